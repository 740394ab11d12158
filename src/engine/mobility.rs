//! Hydrodynamic mobility of spheres in Stokes flow (e:Mazur): the Rotne-Prager-Yamakawa tensor for
//! unequal radii (Mazur's form) and its Oseen truncation.
//!
//! Self terms are H_αα = I/(6πμa_α). The kernels here compute the *interaction* part
//! u_α = Σ_{β≠α} H_αβ F_β only; callers add the Stokes drag F_α/(6πμa_α) themselves. Keeping the two
//! apart lets the microscopic model drop the self terms from dR_H/dt, where they cancel exactly
//! (the hydrodynamic centre is the centre of friction), instead of cancelling them in floating point.

use super::error::{invalid, Result};
use nalgebra::{DMatrix, Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Which pair tensor couples different spheres.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Mobility {
    /// Rotne-Prager-Yamakawa-Mazur: Oseen plus the (a_α²+a_β²)/r³ finite-size term.
    #[default]
    Rpy,
    /// Oseen: point forces, the r⁻¹ term only.
    Oseen,
}

impl Mobility {
    /// Parse a user-facing name.
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "rpy" => Ok(Mobility::Rpy),
            "oseen" => Ok(Mobility::Oseen),
            other => Err(invalid!(
                "unknown mobility \"{other}\"; use \"rpy\" (Rotne-Prager-Yamakawa, default) or \"oseen\""
            )),
        }
    }

    /// The user-facing name.
    pub fn name(self) -> &'static str {
        match self {
            Mobility::Rpy => "rpy",
            Mobility::Oseen => "oseen",
        }
    }

    /// H_αβ F for spheres of radii `ai`, `aj` at separation `r` = x_α − x_β (α ≠ β).
    #[inline]
    pub fn pair_apply(
        self,
        mu: f64,
        r: &Vector3<f64>,
        ai: f64,
        aj: f64,
        f: &Vector3<f64>,
    ) -> Vector3<f64> {
        let r2 = r.norm_squared();
        let inv_r = 1.0 / r2.sqrt();
        let rhat_dot_f = r.dot(f) * inv_r * inv_r; // (r·F)/r², multiplies r (not r̂)
        let c1 = inv_r / (8.0 * PI * mu);
        let mut out = c1 * (f + r * rhat_dot_f);
        if self == Mobility::Rpy {
            let c3 = (ai * ai + aj * aj) * inv_r * inv_r * inv_r / (24.0 * PI * mu);
            out += c3 * (f - r * (3.0 * rhat_dot_f));
        }
        out
    }

    /// The 3×3 block H_αβ (α ≠ β) as a matrix.
    pub fn pair_tensor(self, mu: f64, r: &Vector3<f64>, ai: f64, aj: f64) -> Matrix3<f64> {
        let d = r.norm();
        let rr = r * r.transpose() / (d * d);
        let id = Matrix3::identity();
        let mut h = (id + rr) / (8.0 * PI * mu * d);
        if self == Mobility::Rpy {
            h += (ai * ai + aj * aj) / (24.0 * PI * mu * d * d * d) * (id - 3.0 * rr);
        }
        h
    }

    /// The full 3N×3N mobility matrix including self terms (for tests and small systems).
    pub fn matrix(self, mu: f64, pos: &[Vector3<f64>], radii: &[f64]) -> DMatrix<f64> {
        let n = pos.len();
        let mut m = DMatrix::zeros(3 * n, 3 * n);
        for a in 0..n {
            for i in 0..3 {
                m[(3 * a + i, 3 * a + i)] = 1.0 / (6.0 * PI * mu * radii[a]);
            }
            for b in 0..n {
                if a != b {
                    let h = self.pair_tensor(mu, &(pos[a] - pos[b]), radii[a], radii[b]);
                    m.fixed_view_mut::<3, 3>(3 * a, 3 * b).copy_from(&h);
                }
            }
        }
        m
    }

    /// Interaction velocities u_α = Σ_{β≠α} H_αβ F_β (self drag excluded), all pairs, O(N²).
    pub fn interaction_velocities(
        self,
        mu: f64,
        pos: &[Vector3<f64>],
        radii: &[f64],
        forces: &[Vector3<f64>],
        out: &mut [Vector3<f64>],
    ) {
        out.iter_mut().for_each(|u| *u = Vector3::zeros());
        let n = pos.len();
        for a in 0..n {
            for b in (a + 1)..n {
                let r = pos[a] - pos[b];
                // H is even in r, so one evaluation serves both directions of the pair.
                let ua = self.pair_apply(mu, &r, radii[a], radii[b], &forces[b]);
                let ub = self.pair_apply(mu, &r, radii[a], radii[b], &forces[a]);
                out[a] += ua;
                out[b] += ub;
            }
        }
    }
}

/// Stokes drag mobility of one sphere, 1/(6πμa).
#[inline]
pub fn self_mobility(mu: f64, a: f64) -> f64 {
    1.0 / (6.0 * PI * mu * a)
}
