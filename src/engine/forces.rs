//! External forces on the spheres: a constant force on every sphere and gravity with buoyancy.
//! Swimmers are force-free by default; these make them sediment (towards −z, onto a wall).

use super::error::{invalid, Result};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Gravity along −z on spheres of density `density` in a fluid of density `fluid_density`: each
/// sphere of radius a feels its buoyant weight (4/3)πa³(ρ_s − ρ_f) g downwards.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Gravity {
    /// g (m/s²), positive: gravity pulls towards −z.
    pub g: f64,
    /// ρ_s, the spheres' density (kg/m³).
    pub density: f64,
    /// ρ_f, the fluid's density (kg/m³).
    pub fluid_density: f64,
}

impl Gravity {
    /// Gravity if every number is usable, else the error naming it.
    pub fn checked(self) -> Result<Self> {
        for (name, v) in [
            ("g", self.g),
            ("density", self.density),
            ("fluid_density", self.fluid_density),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(invalid!(
                    "gravity's {name} must be a finite number ≥ 0, got {v} (g in m/s², the densities in kg/m³: e.g. 9.81, 1050 and 1000)"
                ));
            }
        }
        Ok(self)
    }

    /// The buoyant weight of a sphere of radius `a` (N, along z).
    pub fn force_on(&self, a: f64) -> Vector3<f64> {
        let mass = 4.0 / 3.0 * PI * a * a * a * (self.density - self.fluid_density);
        Vector3::new(0.0, 0.0, -mass * self.g)
    }
}

/// The external forces on every sphere: `force` (N) plus gravity's buoyant weight.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct ExternalForces {
    /// The same force on every sphere (N).
    #[serde(default)]
    pub force: [f64; 3],
    /// Gravity with buoyancy, if on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity: Option<Gravity>,
}

impl ExternalForces {
    /// No external force: force-free swimmers (the default).
    pub fn is_none(&self) -> bool {
        self.force == [0.0; 3] && self.gravity.is_none()
    }

    /// A constant force on every sphere, checked finite.
    pub fn check_force(force: [f64; 3]) -> Result<[f64; 3]> {
        if force.iter().all(|v| v.is_finite()) {
            Ok(force)
        } else {
            Err(invalid!(
                "the external force must be three finite numbers of N, got {force:?} (e.g. 1e-14 N downwards: 0, 0, -1e-14)"
            ))
        }
    }

    /// The force on each sphere of radii `radii` (empty when there is none).
    pub fn per_sphere(&self, radii: impl Iterator<Item = f64>) -> Vec<Vector3<f64>> {
        if self.is_none() {
            return Vec::new();
        }
        let f = Vector3::from(self.force);
        radii
            .map(|a| f + self.gravity.map_or(Vector3::zeros(), |g| g.force_on(a)))
            .collect()
    }
}
