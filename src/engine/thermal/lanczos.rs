//! √M·z for a symmetric positive definite M given only as a product v ↦ Mv: the Lanczos
//! iteration (Ando, Chow, Saad & Skolnick, J. Chem. Phys. 137, 064106 (2012); Chow & Saad, SIAM
//! J. Sci. Comput. 36, A1 (2014)). After k steps M ≈ V T Vᵀ on the Krylov space of z, with T
//! tridiagonal, and √M·z ≈ |z| V √T e₁. The iteration stops when that estimate changes by less
//! than `tol` of its size from one step to the next. Vectors are re-orthogonalised against the
//! whole basis (k is small: tens of steps), so round-off does not spoil T.

use nalgebra::{DMatrix, SymmetricEigen};

/// Why the iteration gave no answer.
#[derive(Debug, Clone, PartialEq)]
pub enum LanczosFailure {
    /// T has a non-positive eigenvalue: M is not positive definite.
    NotPositive(f64),
    /// No convergence within the allowed steps.
    NoConvergence {
        /// Steps taken.
        steps: usize,
        /// The last relative change.
        change: f64,
    },
}

/// The most Lanczos steps (each one product with M).
pub const MAX_STEPS: usize = 400;

/// Write √M·z to `out` and return the number of products with M taken.
pub fn sqrt_times(
    apply: &mut dyn FnMut(&[f64], &mut [f64]),
    z: &[f64],
    tol: f64,
    out: &mut [f64],
) -> Result<usize, LanczosFailure> {
    let n = z.len();
    let norm = z.iter().map(|v| v * v).sum::<f64>().sqrt();
    out.fill(0.0);
    if norm == 0.0 {
        return Ok(0);
    }
    let max = MAX_STEPS.min(n);
    let mut basis: Vec<Vec<f64>> = vec![z.iter().map(|v| v / norm).collect()];
    let (mut alpha, mut beta): (Vec<f64>, Vec<f64>) = (Vec::new(), Vec::new());
    let mut w = vec![0.0; n];
    let mut last: Vec<f64> = Vec::new();
    let mut change = f64::INFINITY;
    for k in 0..max {
        apply(&basis[k], &mut w);
        let a = dot(&basis[k], &w);
        alpha.push(a);
        // Full re-orthogonalisation, twice ("twice is enough").
        for _ in 0..2 {
            for v in &basis {
                let c = dot(v, &w);
                w.iter_mut().zip(v).for_each(|(x, y)| *x -= c * y);
            }
        }
        let b = dot(&w, &w).sqrt();
        let coef = sqrt_t_e1(&alpha, &beta)?;
        change = if last.is_empty() {
            f64::INFINITY
        } else {
            let diff: f64 = coef
                .iter()
                .enumerate()
                .map(|(i, c)| (c - last.get(i).copied().unwrap_or(0.0)).powi(2))
                .sum();
            (diff / coef.iter().map(|c| c * c).sum::<f64>()).sqrt()
        };
        let invariant = b <= 1e-14 * a.abs().max(f64::MIN_POSITIVE);
        if change <= tol || invariant || k + 1 == n {
            for (c, v) in coef.iter().zip(&basis) {
                out.iter_mut().zip(v).for_each(|(o, x)| *o += norm * c * x);
            }
            return Ok(k + 1);
        }
        last = coef;
        beta.push(b);
        basis.push(w.iter().map(|x| x / b).collect());
    }
    Err(LanczosFailure::NoConvergence { steps: max, change })
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// √T e₁ for the tridiagonal T with diagonal `alpha` and off-diagonal `beta`.
fn sqrt_t_e1(alpha: &[f64], beta: &[f64]) -> Result<Vec<f64>, LanczosFailure> {
    let k = alpha.len();
    let mut t = DMatrix::zeros(k, k);
    for i in 0..k {
        t[(i, i)] = alpha[i];
        if i + 1 < k {
            t[(i, i + 1)] = beta[i];
            t[(i + 1, i)] = beta[i];
        }
    }
    let eig = SymmetricEigen::new(t);
    let smallest = eig
        .eigenvalues
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    if smallest <= 0.0 {
        return Err(LanczosFailure::NotPositive(smallest));
    }
    let q = &eig.eigenvectors;
    Ok((0..k)
        .map(|i| {
            (0..k)
                .map(|j| q[(i, j)] * eig.eigenvalues[j].sqrt() * q[(0, j)])
                .sum()
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a random SPD matrix the iteration's √M·z equals the eigendecomposition's to its
    /// tolerance (1e-10 asked; 1e-8 allowed: the stopping test measures the last change, and the
    /// error left is a small multiple of it).
    #[test]
    fn lanczos_square_root_matches_the_eigendecomposition() {
        let n = 60;
        let mut a = DMatrix::<f64>::zeros(n, n);
        let mut x = 0.3_f64;
        for v in a.iter_mut() {
            x = (x * 3.7 + 0.1).fract();
            *v = x - 0.5;
        }
        let m = &a * a.transpose() + DMatrix::identity(n, n) * 2.0;
        let z: Vec<f64> = (0..n).map(|i| ((i * 7) % 11) as f64 - 5.0).collect();
        let eig = SymmetricEigen::new(m.clone());
        let root = &eig.eigenvectors
            * DMatrix::from_diagonal(&eig.eigenvalues.map(f64::sqrt))
            * eig.eigenvectors.transpose();
        let exact = &root * nalgebra::DVector::from_column_slice(&z);
        let mut out = vec![0.0; n];
        let mut apply = |v: &[f64], w: &mut [f64]| {
            let r = &m * nalgebra::DVector::from_column_slice(v);
            w.copy_from_slice(r.as_slice());
        };
        let steps = sqrt_times(&mut apply, &z, 1e-10, &mut out).unwrap();
        let err = (nalgebra::DVector::from_column_slice(&out) - &exact).norm() / exact.norm();
        assert!(err < 1e-8, "relative error {err:e} after {steps} steps");
        assert!(steps < n, "{steps} steps: no faster than the dimension");
    }
}
