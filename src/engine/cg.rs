//! Preconditioned conjugate gradients with the flexible β, for symmetric positive definite
//! systems given as a product and a preconditioner (the rigid model's tensions and the
//! preconditioner's own inner solve).

use nalgebra::DVector;

/// The vectors of one conjugate-gradient solve.
#[derive(Debug, Clone)]
pub(crate) struct CgVectors {
    /// The residual b − A x (given on entry).
    pub(crate) r: DVector<f64>,
    z: DVector<f64>,
    /// The last preconditioned residual (the flexible β).
    z_prev: DVector<f64>,
    p: DVector<f64>,
    /// A p during the solve; free before it (a caller may form the first residual in it).
    pub(crate) q: DVector<f64>,
}

impl CgVectors {
    /// Zero vectors of length `n`.
    pub(crate) fn zeros(n: usize) -> Self {
        let z = || DVector::zeros(n);
        CgVectors {
            r: z(),
            z: z(),
            z_prev: z(),
            p: z(),
            q: z(),
        }
    }
}

/// Preconditioned conjugate gradients for A x = b from `x`, with `v.r` = b − A x on entry, until
/// |r| ≤ `goal` (true) or `max` steps or a breakdown (false); `apply(p, q)` sets q = A p and
/// `precondition(r, z)` sets z ≈ A⁻¹ r. β is the flexible (Polak-Ribière) one, which equals the
/// classical β for a fixed preconditioner and keeps the iteration converging where the
/// preconditioner is itself an iteration (not exactly one linear map at every step).
pub(crate) fn cg(
    x: &mut DVector<f64>,
    v: &mut CgVectors,
    goal: f64,
    max: usize,
    mut apply: impl FnMut(&DVector<f64>, &mut DVector<f64>),
    mut precondition: impl FnMut(&DVector<f64>, &mut DVector<f64>),
) -> bool {
    precondition(&v.r, &mut v.z);
    v.p.copy_from(&v.z);
    let mut rz = v.r.dot(&v.z);
    for _ in 0..max {
        if v.r.norm() <= goal {
            return true;
        }
        apply(&v.p, &mut v.q);
        let pq = v.p.dot(&v.q);
        if !(pq > 0.0 && rz.is_finite()) {
            return false;
        }
        let alpha = rz / pq;
        x.axpy(alpha, &v.p, 1.0);
        v.r.axpy(-alpha, &v.q, 1.0);
        std::mem::swap(&mut v.z, &mut v.z_prev);
        precondition(&v.r, &mut v.z);
        let rz_next = v.r.dot(&v.z);
        let beta = (rz_next - v.r.dot(&v.z_prev)) / rz;
        rz = rz_next;
        v.p.axpy(1.0, &v.z, beta);
    }
    v.r.norm() <= goal
}
