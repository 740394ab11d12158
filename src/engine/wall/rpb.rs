//! The Rotne-Prager-Blake wall correction: what a no-slip plane at z = 0 adds to open space's
//! RPY mobility, for spheres of unequal radii.
//!
//! Blake's Green's function (1971) of a point force above a no-slip plane is open space's Oseen
//! tensor plus an image system (a Stokeslet, a Stokes doublet and a source doublet at the mirror
//! point). As Swan & Brady (Phys. Fluids 19, 113306 (2007)) do for equal spheres, the image part
//! is taken through the Faxén operators of both spheres, (1 + a_i²/6 ∇_i²)(1 + a_j²/6 ∇_j²): the
//! velocity of sphere i (at x, radius a_i) under a force on sphere j (at y, radius a_j). With
//! R = x − y* (y* the mirror image of y), r = |R|, R_3 = x_z + y_z and h = y_z, the correction is
//!
//! 8πμ W_αβ = A δ_αβ + B R_α R_β,  8πμ W_α3 = C R_α,  8πμ W_3α = D R_α,  8πμ W_33 = E
//!
//! (α, β in the plane), where A … E are polynomials in R_3, h, a_i², a_j² over odd powers of r,
//! derived symbolically (the derivation keeps the source height h inside the derivatives with
//! respect to y). W_ij = W_ji^T with the radii swapped (reciprocity). The image lies below the
//! wall, so r ≥ x_z + y_z and W has no singularity while both spheres are above it; overlapping
//! spheres change open space's part alone.
//!
//! A sphere's own correction is the same construction at x = y with a_i = a_j = a; it is diagonal,
//! Swan & Brady's series in a/h.

use nalgebra::{Matrix3, Vector3};
use std::f64::consts::PI;

/// W_ij, the wall's correction to the mobility of sphere i (at `xi`, radius `ai`) under a force
/// on sphere j (at `xj`, radius `aj`) above the no-slip plane z = 0, in a fluid of viscosity `mu`:
/// row index the velocity's component, column the force's.
#[inline]
pub fn wall_correction(
    mu: f64,
    xi: &Vector3<f64>,
    xj: &Vector3<f64>,
    ai: f64,
    aj: f64,
) -> Matrix3<f64> {
    let (rx, ry) = (xi.x - xj.x, xi.y - xj.y);
    let r3 = xi.z + xj.z;
    let h = xj.z;
    let (ai2, aj2) = (ai * ai, aj * aj);
    let q = 1.0 / (rx * rx + ry * ry + r3 * r3).sqrt();
    let q2 = q * q;
    let q3 = q * q2;
    let q5 = q3 * q2;
    let q7 = q5 * q2;
    let q9 = q7 * q2;
    let aa = ai2 * aj2;
    let dh = ai2 - aj2;
    // Recurring combinations of the coefficients.
    let s = 3.0 * r3 * r3 * aj2 + 3.0 * r3 * h * dh + aa;
    let t = r3 * r3 * aj2 + r3 * h * dh;
    let r3h = 6.0 * r3 * h;
    let a_ = -q + q3 * (6.0 * h * h - r3h - ai2 - aj2) / 3.0 + q5 * 2.0 * s / 3.0
        - q7 * 10.0 * r3 * r3 * aa / 3.0;
    let b_ = -q3 + q5 * (r3h - 6.0 * h * h + ai2 + aj2) - q7 * 10.0 * s / 3.0
        + q9 * 70.0 * r3 * r3 * aa / 3.0;
    let c_ = q3 * (2.0 * h - r3)
        + q5 * (r3h * (h - r3) + r3 * (ai2 - 3.0 * aj2) - 2.0 * h * dh)
        + q7 * 10.0 * r3 * (t + aa)
        - q9 * 70.0 * r3 * r3 * r3 * aa / 3.0;
    let d_ = q3 * (2.0 * h - r3) + q5 * (r3h * (r3 - h) + r3 * (ai2 + aj2) + 2.0 * h * dh)
        - q7 * 10.0 * r3 * (t + aa)
        + q9 * 70.0 * r3 * r3 * r3 * aa / 3.0;
    let e_ = -q - q3 * (3.0 * r3 * r3 - r3h + ai2 + aj2 + 6.0 * h * h) / 3.0
        + q5 * (r3h * r3 * (h - r3) + r3 * r3 * (ai2 - 5.0 * aj2) - r3h * dh - 2.0 * aa)
        + q7 * 10.0 * r3 * r3 * (t + 2.0 * aa)
        - q9 * 70.0 * r3 * r3 * r3 * r3 * aa / 3.0;
    let f = 1.0 / (8.0 * PI * mu);
    Matrix3::new(
        a_ + b_ * rx * rx,
        b_ * rx * ry,
        c_ * rx,
        b_ * ry * rx,
        a_ + b_ * ry * ry,
        c_ * ry,
        d_ * rx,
        d_ * ry,
        e_,
    ) * f
}

/// A sphere's own wall correction at height `h` above the plane, radius `a`: the diagonal
/// (parallel, parallel, perpendicular) of Swan & Brady's series, μ0 (−9/16 x + 1/8 x³ − 1/16 x⁵)
/// and μ0 (−9/8 x + 1/2 x³ − 1/8 x⁵) with x = a/h and μ0 = 1/(6πμa).
#[inline]
pub fn self_correction(mu: f64, h: f64, a: f64) -> Vector3<f64> {
    let mu0 = 1.0 / (6.0 * PI * mu * a);
    let x = a / h;
    let x2 = x * x;
    let par = mu0 * x * (-9.0 / 16.0 + x2 * (1.0 / 8.0 - x2 / 16.0));
    let perp = mu0 * x * (-9.0 / 8.0 + x2 * (1.0 / 2.0 - x2 / 8.0));
    Vector3::new(par, par, perp)
}

#[cfg(test)]
mod tests {
    use super::*;

    const MU: f64 = 1e-3;

    /// The pair formula at coincident equal spheres is the independent self series: both come
    /// from the same construction, one by the symbolic derivation, one from Swan & Brady.
    #[test]
    fn pair_formula_at_coincidence_is_the_self_series() {
        for (h, a) in [(1.2e-6, 1e-6), (3e-6, 1e-6), (10e-6, 2e-6)] {
            let x = Vector3::new(0.3e-6, -0.2e-6, h);
            let w = wall_correction(MU, &x, &x, a, a);
            let s = self_correction(MU, h, a);
            let scale = 1.0 / (6.0 * PI * MU * a);
            // Round-off of the ~10-term sums, relative to μ0.
            assert!((w - Matrix3::from_diagonal(&s)).abs().max() < 1e-13 * scale);
        }
    }

    /// Reciprocity W_ij = W_ji^T holds with the radii swapped, for unequal spheres.
    #[test]
    fn reciprocity_with_unequal_radii() {
        let xi = Vector3::new(1e-6, 2e-6, 1.5e-6);
        let xj = Vector3::new(-0.5e-6, 0.7e-6, 4e-6);
        let (ai, aj) = (1e-6, 0.4e-6);
        let wij = wall_correction(MU, &xi, &xj, ai, aj);
        let wji = wall_correction(MU, &xj, &xi, aj, ai);
        assert!((wij - wji.transpose()).abs().max() < 1e-13 * wij.abs().max());
    }
}
