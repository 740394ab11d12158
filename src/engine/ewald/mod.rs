//! The periodic Rotne-Prager-Yamakawa mobility by Ewald summation (Beenakker, J. Chem. Phys. 85,
//! 1581 (1986)), for unequal radii.
//!
//! The RPY pair tensor is (1 + (a_i² + a_j²)/6 ∇²)G, G the Oseen tensor: every term of Beenakker's
//! equal-radius sum is linear in a², so unequal radii take s = (a_i² + a_j²)/2 where his form has
//! a² (the Oseen part carries a⁰, the finite-size part a²). With ξ the splitting
//! parameter (1/m), E = e^{−ξ²r²}/√π and everything in units of 1/(6πμ):
//! - real space, over every image r = x_i − x_j + nL (the particle's own r = 0 left out):
//!   c_I = erfc(ξr)(3/(4r) + s/(2r³)) + E(3ξ³r² − 9ξ/2 + s(4ξ⁷r⁴ − 20ξ⁵r² + 14ξ³ + ξ/r²)),
//!   c_rr = erfc(ξr)(3/(4r) − 3s/(2r³)) + E(−3ξ³r² + 3ξ/2 + s(−4ξ⁷r⁴ + 16ξ⁵r² − 2ξ³ − 3ξ/r²));
//! - reciprocal space, over k = 2π(n_x/L_x, n_y/L_y, n_z/L_z) ≠ 0 (the k = 0 mode left out: no net
//!   flow through the box): (6π/V)(1 − s k²/3)(1 + k²/4ξ² + k⁴/8ξ⁴) e^{−k²/4ξ²} cos(k·r)(I − k̂k̂)/k²;
//! - self: 1/a_i − 6ξ/√π + (40/3) ξ³ a_i²/√π.
//!
//! Overlapping spheres (r < a_i + a_j, nearest image) get the difference between the overlapping
//! form of Zuk et al. and Mazur's at that image (both are exact pair terms; only the nearest image
//! can overlap in a box longer than twice the largest sphere). The Oseen mobility is the same sum
//! with s = 0.
//!
//! Truncation: both sums fall as e^{−p²} times a polynomial in p, with p = ξ r_c = k_c/(2ξ); p is
//! chosen so that e^{−p²}(1 + p⁴) is the tolerance, and ξ to minimise the work for the number of
//! spheres (the pairs within r_c, found by cell lists where r_c ≤ L/2 and among all pairs and their
//! images otherwise, against the spheres times the waves within k_c: O(N^1.5) at the optimum).
//! The result does not depend on ξ beyond that tolerance (tests/periodic.rs).
//!
//! - `method.rs`: [`EwaldMethod`] (auto, Beenakker, spectral) and the tolerance's check;
//! - `split.rs`: the splitting and the terms both methods share;
//! - `beenakker.rs`: Beenakker's sums, [`Ewald`] (products, blocks, the matrix) and Hasimoto's
//!   self-mobility;
//! - `reciprocal.rs`: the products' reciprocal part through structure factors, in vector lanes;
//! - `real.rs`: the products' real-space part over cell lists (r_c ≤ L/2), in vector lanes;
//! - `erfc.rs`: erfc and e^{−x²} from a table and a Taylor series, for the lanes;
//! - `spectral.rs`: spectral Ewald (Lindbo & Tornberg 2010), the products on an FFT grid.

mod beenakker;
mod erfc;
mod method;
mod real;
mod reciprocal;
pub mod spectral;
mod split;

pub use beenakker::{hasimoto, Ewald};
pub use method::{
    check_tol, ewald_tol_for, EwaldMethod, DEFAULT_EWALD_TOL, EWALD_TOL_PER_DRIFT_TOL,
    SPECTRAL_COSTLY_BELOW, SPECTRAL_FROM_SPHERES,
};
pub use spectral::SpectralEwald;
