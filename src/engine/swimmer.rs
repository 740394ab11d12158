//! One dumbbell swimmer: two spheres joined by a spring whose rest length oscillates,
//! L(t) = ℓ + λ sin(ωt + φ): the stroke of the microscopic model.

use super::error::{invalid, require_finite, require_positive, Result};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// The parameters of one dumbbell (SI units). Its pose lives in the scene state.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Dumbbell {
    /// Radius of sphere 1 (m); the orientation points from this sphere to sphere 2.
    pub a1: f64,
    /// Radius of sphere 2 (m).
    pub a2: f64,
    /// Mean length ℓ (m).
    pub ell: f64,
    /// Stroke amplitude λ (m).
    pub lambda: f64,
    /// Angular frequency ω (1/s).
    pub omega: f64,
    /// Spring constant k0 (kg/s²).
    pub k0: f64,
    /// Stroke phase φ (rad).
    pub phase: f64,
}

impl Default for Dumbbell {
    /// The paper's symmetric Fig-1 swimmer: a1 = a2 = 0.15 ℓ, ℓ = 5 µm, λ = 0.1 ℓ, ω = 500/s, k0 = 1e-3.
    fn default() -> Self {
        let ell = 5e-6;
        Dumbbell {
            a1: 0.15 * ell,
            a2: 0.15 * ell,
            ell,
            lambda: 0.1 * ell,
            omega: 500.0,
            k0: 1e-3,
            phase: 0.0,
        }
    }
}

impl Dumbbell {
    /// Check the parameters: positive finite radii, ℓ, ω, k0; finite λ ≥ 0 and φ; ℓ > a1 + a2 + λ.
    pub fn validate(&self) -> Result<()> {
        require_positive("a1", self.a1, "m")?;
        require_positive("a2", self.a2, "m")?;
        require_positive("ell", self.ell, "m")?;
        require_positive("omega", self.omega, "1/s")?;
        require_positive("k0", self.k0, "kg/s^2")?;
        require_finite("lambda", self.lambda)?;
        require_finite("phase", self.phase)?;
        if self.lambda < 0.0 {
            return Err(invalid!(
                "lambda must be >= 0 (m), got {}; shift the phase by pi instead of flipping the sign",
                self.lambda
            ));
        }
        if self.ell <= self.a1 + self.a2 + self.lambda {
            return Err(invalid!(
                "the spheres would touch during the stroke: ell = {:e} m must exceed a1 + a2 + lambda = {:e} m; \
                 lengthen ell or shrink the radii or the amplitude",
                self.ell,
                self.a1 + self.a2 + self.lambda
            ));
        }
        Ok(())
    }

    /// Rest length L(t) = ℓ + λ sin(ωt + φ).
    pub fn rest_length(&self, t: f64) -> f64 {
        self.ell + self.lambda * (self.omega * t + self.phase).sin()
    }

    /// Stroke period T = 2π/ω.
    pub fn period(&self) -> f64 {
        2.0 * PI / self.omega
    }

    /// Weight of sphere 1 in the hydrodynamic centre, a1/(a1+a2).
    pub fn w1(&self) -> f64 {
        self.a1 / (self.a1 + self.a2)
    }

    /// Weight of sphere 2 in the hydrodynamic centre, a2/(a1+a2).
    pub fn w2(&self) -> f64 {
        self.a2 / (self.a1 + self.a2)
    }

    /// Harmonic mean of the radii Λ = 2 a1 a2 / (a1 + a2).
    pub fn big_lambda(&self) -> f64 {
        2.0 * self.a1 * self.a2 / (self.a1 + self.a2)
    }

    /// Whether both spheres have the same radius (the asymmetric terms vanish).
    pub fn is_symmetric(&self) -> bool {
        self.a1 == self.a2
    }

    /// Size of the stroke that error control compares the dumbbell vector with: λ, but at least
    /// 1% of ℓ so a passive dumbbell (λ = 0) still has a scale (m).
    pub fn stroke_scale(&self) -> f64 {
        self.lambda.max(0.01 * self.ell)
    }

    /// Size of the net displacement per period of the closest possible pair, λ(λ/ℓ)²(Λ/ℓ) (m): the
    /// drift is second order in λ/ℓ and first in Λ/ℓ, so this is what error control on R_H is
    /// measured against, never the absolute position.
    pub fn drift_scale(&self) -> f64 {
        let stroke = self.stroke_scale();
        stroke * (stroke / self.ell).powi(2) * (self.big_lambda() / self.ell)
    }

    /// Relaxation rate of the spring, k0 (1/γ1 + 1/γ2) with γ = 6πμa (1/s): the stiff rate.
    pub fn relaxation_rate(&self, mu: f64) -> f64 {
        self.k0 / (6.0 * PI * mu) * (1.0 / self.a1 + 1.0 / self.a2)
    }

    /// Sphere positions of a dumbbell with hydrodynamic centre `rh`, unit orientation `n` and length `len`.
    pub fn sphere_positions(
        &self,
        rh: Vector3<f64>,
        n: Vector3<f64>,
        len: f64,
    ) -> (Vector3<f64>, Vector3<f64>) {
        (rh - self.w2() * len * n, rh + self.w1() * len * n)
    }
}

/// Normalise a direction, rejecting zero and non-finite vectors.
pub fn unit_direction(dir: Vector3<f64>) -> Result<Vector3<f64>> {
    let norm = dir.norm();
    if !norm.is_finite() || dir.iter().any(|c| !c.is_finite()) {
        return Err(invalid!(
            "dir must have finite components, got [{}, {}, {}]",
            dir.x,
            dir.y,
            dir.z
        ));
    }
    if norm == 0.0 {
        return Err(invalid!(
            "dir must be a non-zero vector such as [1.0, 0.0, 0.0], got [0, 0, 0]"
        ));
    }
    Ok(dir / norm)
}

/// The shortest stroke period of `swimmers` (s); infinite without swimmers.
pub fn shortest_period(swimmers: &[Dumbbell]) -> f64 {
    swimmers
        .iter()
        .map(Dumbbell::period)
        .fold(f64::INFINITY, f64::min)
}
