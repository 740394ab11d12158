//! What Beenakker's sums and spectral Ewald share: the splitting ξ and its truncation, and the
//! real-space, self and overlap terms of the split RPY (or Oseen) tensor.

use crate::engine::mobility::Mobility;
use nalgebra::Vector3;
use std::f64::consts::PI;

/// What both methods share: the viscosity, RPY or Oseen, and the splitting ξ; the real-space,
/// self and overlap terms.
#[derive(Debug, Clone, Copy)]
pub(super) struct Split {
    pub(super) mu: f64,
    /// RPY (finite size) or Oseen (s = 0).
    pub(super) finite_size: bool,
    pub(super) xi: f64,
}

/// Truncation parameter p for tolerance `tol`: e^{−p²}(1 + p⁴) = tol.
pub(super) fn truncation(tol: f64) -> f64 {
    let target = -tol.ln();
    let mut p = target.sqrt();
    for _ in 0..8 {
        p = (target + (1.0 + p.powi(4)).ln()).sqrt();
    }
    p
}

impl Split {
    /// s for a pair of radii: (a_i² + a_j²)/2 for RPY, 0 for Oseen.
    #[inline]
    pub(super) fn s(&self, ai: f64, aj: f64) -> f64 {
        if self.finite_size {
            0.5 * (ai * ai + aj * aj)
        } else {
            0.0
        }
    }

    /// Real-space coefficients (c_I, c_rr) at distance `r` > 0, units 1/(6πμ).
    #[inline]
    pub(super) fn real(&self, r: f64, s: f64) -> (f64, f64) {
        let xr = self.xi * r;
        let e = (-xr * xr).exp() / PI.sqrt();
        self.real_with(r, 1.0 / r, s, libm::erfc(xr), e)
    }

    /// [`Split::real`] from r, 1/r, and erfc(ξr) and e^{−ξ²r²}/√π however they were computed (libm
    /// here, a table in the vector lanes of `real.rs`).
    #[inline(always)]
    pub(super) fn real_with(&self, r: f64, inv_r: f64, s: f64, erfc: f64, e: f64) -> (f64, f64) {
        let xi = self.xi;
        let x2 = xi * xi;
        let (r2, inv_r2) = (r * r, inv_r * inv_r);
        let (x3, x5, x7) = (x2 * xi, x2 * x2 * xi, x2 * x2 * x2 * xi);
        let ci = erfc * (0.75 * inv_r + 0.5 * s * inv_r2 * inv_r)
            + e * (3.0 * x3 * r2 - 4.5 * xi
                + s * (4.0 * x7 * r2 * r2 - 20.0 * x5 * r2 + 14.0 * x3 + xi * inv_r2));
        let crr = erfc * (0.75 * inv_r - 1.5 * s * inv_r2 * inv_r)
            + e * (-3.0 * x3 * r2
                + 1.5 * xi
                + s * (-4.0 * x7 * r2 * r2 + 16.0 * x5 * r2 - 2.0 * x3 - 3.0 * xi * inv_r2));
        (ci, crr)
    }

    /// The self term less the Stokes drag, units 1/(6πμ): −6ξ/√π + (40/3)ξ³a²/√π.
    pub(super) fn self_excess(&self, a: f64) -> f64 {
        let s = self.s(a, a);
        (-6.0 * self.xi + 40.0 / 3.0 * self.xi.powi(3) * s) / PI.sqrt()
    }

    /// The overlapping-sphere correction (c_I, c_rr) at the nearest image `r0`, absolute units
    /// (RPY only; `None` when apart).
    #[inline]
    pub(super) fn overlap(&self, r0: &Vector3<f64>, ai: f64, aj: f64) -> Option<(f64, f64)> {
        let d = r0.norm();
        if !self.finite_size || d >= ai + aj || d == 0.0 {
            return None;
        }
        let (zi, zrr) = Mobility::Rpy.pair_coefficients(self.mu, d, ai, aj);
        let oseen = 1.0 / (8.0 * PI * self.mu * d);
        let fs = (ai * ai + aj * aj) / (24.0 * PI * self.mu * d * d * d);
        Some((zi - oseen - fs, zrr - oseen + 3.0 * fs))
    }

    /// The overlapping-sphere correction applied to `f` (zero when apart).
    #[inline]
    pub(super) fn overlap_apply(
        &self,
        r0: &Vector3<f64>,
        ai: f64,
        aj: f64,
        f: &Vector3<f64>,
    ) -> Vector3<f64> {
        match self.overlap(r0, ai, aj) {
            Some((ci, crr)) => ci * f + r0 * (crr * r0.dot(f) / r0.norm_squared()),
            None => Vector3::zeros(),
        }
    }
}
