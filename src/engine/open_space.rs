//! Open space, the unbounded fluid: the RPY (or Oseen) pair tensor summed over all pairs, as a
//! [`MobilityOperator`]. Small sets take the symmetric half-loop of [`Mobility`], large ones the
//! vectorised row kernel of [`super::pairs`], on rayon's threads from `PARALLEL_SPHERES` on.

use super::mobility::{self_mobility, Mobility, MobilityOperator};
use super::pairs::{self, SoaSpheres};
use super::parallel::PARALLEL_SPHERES;
use nalgebra::{DMatrix, Matrix3, Vector3};

/// From this many spheres on, the vectorised row kernel ([`pairs`]) replaces the symmetric
/// half-loop (below this size the half-loop's halved arithmetic wins; the measurement is in the
/// book's design notes).
pub const FAST_KERNEL_SPHERES: usize = 64;

/// The mobility of spheres in an unbounded fluid of viscosity `mu`.
#[derive(Debug, Clone)]
pub struct OpenSpace {
    mu: f64,
    kind: Mobility,
    /// Scratch of the row kernel.
    soa: SoaSpheres,
    soa_u: Vec<[f64; 3]>,
}

impl OpenSpace {
    /// Spheres in a fluid of viscosity `mu` (Pa s), coupled by `kind`'s pair tensor.
    pub fn new(mu: f64, kind: Mobility) -> Self {
        OpenSpace {
            mu,
            kind,
            soa: SoaSpheres::default(),
            soa_u: Vec::new(),
        }
    }
}

impl MobilityOperator for OpenSpace {
    fn interaction_velocities(
        &mut self,
        pos: &[Vector3<f64>],
        radii: &[f64],
        forces: &[Vector3<f64>],
        out: &mut [Vector3<f64>],
    ) {
        let n = pos.len();
        if n < FAST_KERNEL_SPHERES {
            self.kind
                .interaction_velocities(self.mu, pos, radii, forces, out);
            return;
        }
        self.soa.fill(pos, radii, Some(forces));
        self.soa_u.resize(n, [0.0; 3]);
        pairs::interaction_velocities(
            self.kind,
            self.mu,
            &self.soa,
            &mut self.soa_u,
            n >= PARALLEL_SPHERES,
        );
        for (u, v) in out.iter_mut().zip(&self.soa_u) {
            *u = Vector3::new(v[0], v[1], v[2]);
        }
    }

    fn block(
        &self,
        xa: &Vector3<f64>,
        xb: &Vector3<f64>,
        ai: f64,
        aj: f64,
        same: bool,
    ) -> Matrix3<f64> {
        if same {
            return Matrix3::identity() * self_mobility(self.mu, ai);
        }
        self.kind.pair_tensor(self.mu, &(xa - xb), ai, aj)
    }

    fn matrix(&self, pos: &[Vector3<f64>], radii: &[f64]) -> DMatrix<f64> {
        self.kind.matrix(self.mu, pos, radii)
    }

    fn boxed(&self) -> Box<dyn MobilityOperator> {
        Box::new(self.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The operator's product, its blocks and its matrix are one mobility: M F = D F + W F with
    /// D the Stokes drag, on both kernels (the half-loop below FAST_KERNEL_SPHERES, the row
    /// kernel above). The row kernel sums in another order: 1e-12 of the largest velocity.
    #[test]
    fn product_blocks_and_matrix_agree_on_both_kernels() {
        let mu = 1e-3;
        for n in [6, FAST_KERNEL_SPHERES + 10] {
            let mut op = OpenSpace::new(mu, Mobility::Rpy);
            let mut rng = crate::engine::rng::Rng::new(0x9e3779b97f4a7c15);
            let mut next = || rng.uniform();
            let pos: Vec<Vector3<f64>> = (0..n)
                .map(|_| Vector3::new(next(), next(), next()) * 40e-6)
                .collect();
            let radii: Vec<f64> = (0..n).map(|_| (0.5 + next()) * 1e-6).collect();
            let forces: Vec<Vector3<f64>> = (0..n)
                .map(|_| Vector3::new(next() - 0.5, next() - 0.5, next() - 0.5) * 1e-12)
                .collect();
            let mut w = vec![Vector3::zeros(); n];
            op.interaction_velocities(&pos, &radii, &forces, &mut w);
            let m = op.matrix(&pos, &radii);
            let f = nalgebra::DVector::from_iterator(
                3 * n,
                forces.iter().flat_map(|f| f.iter().copied()),
            );
            let mf = &m * &f;
            let scale = mf.amax();
            for a in 0..n {
                let drag = forces[a] * self_mobility(mu, radii[a]);
                let by_blocks: Vector3<f64> = (0..n)
                    .map(|b| op.block(&pos[a], &pos[b], radii[a], radii[b], a == b) * forces[b])
                    .sum();
                for k in 0..3 {
                    let product = w[a][k] + drag[k];
                    assert!(
                        (product - mf[3 * a + k]).abs() <= 1e-12 * scale,
                        "n {n}, sphere {a}"
                    );
                    assert!(
                        (by_blocks[k] - mf[3 * a + k]).abs() <= 1e-12 * scale,
                        "n {n}, sphere {a}"
                    );
                }
            }
        }
    }
}
