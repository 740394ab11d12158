//! The wall as a body: [`Wall`], the plane's height and the steric repulsion that keeps spheres
//! above it (its settings, saved with the scene), the gap of a sphere to it and its forces.

use crate::engine::contacts::StericLaw;
use crate::engine::error::{invalid, Result};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Default gap below which the wall repels a sphere (m): a tenth of the paper's radius.
pub const DEFAULT_WALL_RANGE: f64 = 1e-7;
/// Default stiffness of the wall's repulsion (N/m): with the default range a force of 1e-10 N at
/// contact, far above the paper's spring forces near a wall (~1e-13 N), so a sphere stops well
/// before it touches.
pub const DEFAULT_WALL_STIFFNESS: f64 = 1e-3;

fn default_drift() -> bool {
    true
}

fn is_true(b: &bool) -> bool {
    *b
}

/// A no-slip plane z = `z` with the fluid above it (saved with the scene).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Wall {
    /// Height of the plane (m).
    pub z: f64,
    /// δ: the surface gap below which the wall repels a sphere (m).
    pub range: f64,
    /// k: the repulsion's force per unit of gap below δ (N/m).
    pub stiffness: f64,
    /// How the repulsion grows inside the range (saved only when not harmonic).
    #[serde(default, skip_serializing_if = "StericLaw::is_harmonic")]
    pub law: StericLaw,
    /// Whether thermal runs add the drift kT ∇·M (saved only when off).
    #[serde(default = "default_drift", skip_serializing_if = "is_true")]
    pub drift: bool,
}

impl Wall {
    /// Position `x` relative to the wall, lifted to height `a` if below it, and its damping
    /// factor min(1, h/a): how the mobility treats a sphere of radius `a` that does not clear
    /// the wall ([`super::WallMobility`]).
    #[inline]
    pub fn lift(&self, x: &Vector3<f64>, a: f64) -> (Vector3<f64>, f64) {
        let h = x.z - self.z;
        if h >= a {
            (Vector3::new(x.x, x.y, h), 1.0)
        } else {
            (Vector3::new(x.x, x.y, a), h / a)
        }
    }

    /// A wall at height `z` with the default repulsion and the thermal drift on.
    pub fn at(z: f64) -> Result<Self> {
        Wall {
            z,
            range: DEFAULT_WALL_RANGE,
            stiffness: DEFAULT_WALL_STIFFNESS,
            law: StericLaw::Harmonic,
            drift: true,
        }
        .checked()
    }

    /// The wall if every number is usable, else the error naming it.
    pub fn checked(self) -> Result<Self> {
        if !self.z.is_finite() {
            return Err(invalid!(
                "the wall's height z must be a finite number (m), got {}",
                self.z
            ));
        }
        for (name, v) in [("range", self.range), ("stiffness", self.stiffness)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid!(
                    "the wall's {name} must be a finite number > 0, got {v} (range in m, default {DEFAULT_WALL_RANGE:e}; stiffness in N/m, default {DEFAULT_WALL_STIFFNESS:e})"
                ));
            }
        }
        Ok(self)
    }

    /// The gap between the wall and the surface of a sphere of radius `a` at `x` (m).
    #[inline]
    pub fn gap(&self, x: &Vector3<f64>, a: f64) -> f64 {
        x.z - self.z - a
    }

    /// Adds the wall's repulsion (along +z) to the force on each sphere within range.
    pub fn add_forces(&self, pos: &[Vector3<f64>], radii: &[f64], forces: &mut [Vector3<f64>]) {
        for ((x, &a), f) in pos.iter().zip(radii).zip(forces.iter_mut()) {
            let gap = self.gap(x, a);
            if gap < self.range {
                f.z += self.stiffness * self.law.force(self.range - gap, self.range);
            }
        }
    }

    /// The sphere closest to the wall and its gap; `None` without spheres.
    pub fn closest(&self, pos: &[Vector3<f64>], radii: &[f64]) -> Option<(usize, f64)> {
        pos.iter()
            .zip(radii)
            .map(|(x, &a)| self.gap(x, a))
            .enumerate()
            .min_by(|p, q| p.1.total_cmp(&q.1))
    }
}
