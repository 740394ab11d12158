//! Hydrodynamic mobility of spheres in Stokes flow (e:Mazur): the Rotne-Prager-Yamakawa tensor for
//! unequal radii (Mazur's form; Zuk et al.'s for overlapping spheres) and its Oseen truncation.
//!
//! Self terms are H_αα = I/(6πμa_α). The kernels here compute the *interaction* part
//! u_α = Σ_{β≠α} H_αβ F_β only; callers add the Stokes drag F_α/(6πμa_α) themselves. Keeping the two
//! apart lets the microscopic model drop the self terms from dR_H/dt, where they cancel exactly
//! (the hydrodynamic centre is the centre of friction), instead of cancelling them in floating point.

use super::choice::{self, Choice, Named};
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

impl Named for Mobility {
    const KIND: &'static str = "mobility";
    const CHOICES: &'static [Choice<Self>] = &[
        Choice {
            value: Mobility::Rpy,
            name: "rpy",
            about: "Rotne-Prager-Yamakawa, default",
        },
        Choice {
            value: Mobility::Oseen,
            name: "oseen",
            about: "point forces",
        },
    ];
}

choice::inherent_names!(Mobility);

impl Mobility {
    /// The pair block as H_αβ = c_I I + c_rr r̂r̂ for spheres of radii `ai`, `aj` a distance `d`
    /// apart: (c_I, c_rr).
    ///
    /// RPY: Mazur's form for separated spheres (d > ai + aj), and for overlapping ones the form of
    /// Zuk, Wajnryb, Mizerski & Szymczak (J. Fluid Mech. 741, R5, 2014), which keeps the mobility
    /// positive definite and is continuous with Mazur's at contact and with a single sphere's
    /// drag 1/(6πμ max(ai, aj)) when one sphere lies inside the other:
    /// c_I = [16d³(ai+aj) − ((ai−aj)² + 3d²)²] / (32d³ · 6πμ ai aj),
    /// c_rr = 3((ai−aj)² − d²)² / (32d³ · 6πμ ai aj).
    /// Oseen has no finite size and keeps its point-force form at every distance.
    #[inline]
    pub fn pair_coefficients(self, mu: f64, d: f64, ai: f64, aj: f64) -> (f64, f64) {
        // One division by d; the constants in μ are hoisted out of callers' loops.
        let inv_d = 1.0 / d;
        let oseen = inv_d * (1.0 / (8.0 * PI * mu));
        match self {
            Mobility::Oseen => (oseen, oseen),
            Mobility::Rpy if d > ai + aj => {
                let f = (ai * ai + aj * aj) * (inv_d * inv_d) * oseen * (1.0 / 3.0);
                (oseen + f, oseen - 3.0 * f)
            }
            Mobility::Rpy if d <= (ai - aj).abs() => (self_mobility(mu, ai.max(aj)), 0.0),
            Mobility::Rpy => {
                let (dm, d3) = ((ai - aj) * (ai - aj), d * d * d);
                let scale = 1.0 / (32.0 * d3 * 6.0 * PI * mu * ai * aj);
                let b = dm + 3.0 * d * d;
                (
                    (16.0 * d3 * (ai + aj) - b * b) * scale,
                    3.0 * (dm - d * d) * (dm - d * d) * scale,
                )
            }
        }
    }

    /// The pair block H_αβ = c_I I + c r r for separation `r` = x_α − x_β (α ≠ β) of spheres of
    /// radii `ai`, `aj`: (c_I, c = c_rr/|r|²), the form every product with the block uses.
    #[inline]
    pub fn pair_block(self, mu: f64, r: &Vector3<f64>, ai: f64, aj: f64) -> (f64, f64) {
        let d2 = r.norm_squared();
        let (ci, crr) = self.pair_coefficients(mu, d2.sqrt(), ai, aj);
        // c_rr vanishes where one sphere holds the other, the coincident pair included.
        (ci, if crr == 0.0 { 0.0 } else { crr / d2 })
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
        let (ci, c) = self.pair_block(mu, r, ai, aj);
        ci * f + r * (c * r.dot(f))
    }

    /// The 3×3 block H_αβ (α ≠ β) as a matrix.
    pub fn pair_tensor(self, mu: f64, r: &Vector3<f64>, ai: f64, aj: f64) -> Matrix3<f64> {
        let (ci, c) = self.pair_block(mu, r, ai, aj);
        ci * Matrix3::identity() + c * r * r.transpose()
    }

    /// The full 3N×3N mobility matrix including self terms (for tests and small systems).
    pub fn matrix(self, mu: f64, pos: &[Vector3<f64>], radii: &[f64]) -> DMatrix<f64> {
        block_matrix(pos.len(), Blocks::Each, |a, b| {
            if a == b {
                Matrix3::identity() * (1.0 / (6.0 * PI * mu * radii[a]))
            } else {
                self.pair_tensor(mu, &(pos[a] - pos[b]), radii[a], radii[b])
            }
        })
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
                // H is even in r and symmetric in the two radii: one block serves both
                // directions of the pair.
                let r = pos[a] - pos[b];
                let (ci, c) = self.pair_block(mu, &r, radii[a], radii[b]);
                out[a] += ci * forces[b] + r * (c * r.dot(&forces[b]));
                out[b] += ci * forces[a] + r * (c * r.dot(&forces[a]));
            }
        }
    }
}

/// Which blocks of a symmetric block matrix [`block_matrix`] computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Blocks {
    /// Every block M_ab on its own.
    Each,
    /// The blocks on and above the diagonal; those below are their transposes, M_ba = M_abᵀ.
    Upper,
}

/// The 3N×3N matrix of the N×N blocks `block(a, b)` (3×3 each), computed as `blocks` says.
pub fn block_matrix(
    n: usize,
    blocks: Blocks,
    block: impl Fn(usize, usize) -> Matrix3<f64>,
) -> DMatrix<f64> {
    let mut m = DMatrix::zeros(3 * n, 3 * n);
    for a in 0..n {
        let first = match blocks {
            Blocks::Each => 0,
            Blocks::Upper => a,
        };
        for b in first..n {
            let h = block(a, b);
            m.fixed_view_mut::<3, 3>(3 * a, 3 * b).copy_from(&h);
            if blocks == Blocks::Upper && a != b {
                m.fixed_view_mut::<3, 3>(3 * b, 3 * a)
                    .copy_from(&h.transpose());
            }
        }
    }
    m
}

/// Stokes drag mobility of one sphere, 1/(6πμa).
#[inline]
pub fn self_mobility(mu: f64, a: f64) -> f64 {
    1.0 / (6.0 * PI * mu * a)
}

/// The mobility of a set of spheres in one boundary (open space, a periodic box, a wall): how the
/// forces on the spheres become their velocities. Built once where the scene's settings change
/// and owned by the sphere models; each boundary is one implementation (what is solid and how
/// separations are measured is the boundary's geometry, not the mobility's).
///
/// Every boundary splits its mobility as M = D + W: D the free Stokes drag 1/(6πμa) of each
/// sphere, which the models apply themselves (it cancels from dR_H/dt exactly), and W all the
/// rest (the pairs, and whatever the boundary adds to a sphere's own flow, as a box's images
/// do), which [`MobilityOperator::interaction_velocities`] applies.
pub trait MobilityOperator: std::fmt::Debug + Send + Sync {
    /// u_α = (W F)_α at positions `pos` of spheres of radii `radii`: every velocity the forces
    /// give beyond each sphere's own Stokes drag.
    fn interaction_velocities(
        &mut self,
        pos: &[Vector3<f64>],
        radii: &[f64],
        forces: &[Vector3<f64>],
        out: &mut [Vector3<f64>],
    );

    /// The 3×3 block M_αβ between spheres at `xa` and `xb` of radii `ai`, `aj`; `same`: α = β,
    /// the self block, Stokes drag included.
    fn block(
        &self,
        xa: &Vector3<f64>,
        xb: &Vector3<f64>,
        ai: f64,
        aj: f64,
        same: bool,
    ) -> Matrix3<f64>;

    /// The full 3N×3N matrix M, self blocks included (dense noise roots, tests).
    fn matrix(&self, pos: &[Vector3<f64>], radii: &[f64]) -> DMatrix<f64>;

    /// (∇·M)_α, the divergence of the mobility with respect to the positions, into `out`: the
    /// drift kT ∇·M that Itô's thermal noise needs where M varies with the positions. `false`
    /// (nothing written) where it vanishes, as in open space and a periodic box, or where the
    /// boundary's settings leave the drift out.
    fn divergence(&self, _pos: &[Vector3<f64>], _radii: &[f64], _out: &mut [Vector3<f64>]) -> bool {
        false
    }

    /// A copy behind a box (the models are cloned with their scenes).
    fn boxed(&self) -> Box<dyn MobilityOperator>;
}

impl Clone for Box<dyn MobilityOperator> {
    fn clone(&self) -> Self {
        self.boxed()
    }
}
