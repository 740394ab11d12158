//! The mobility of spheres above a no-slip wall as a [`MobilityOperator`]: open space's RPY
//! tensor plus the Rotne-Prager-Blake wall correction ([`super::rpb`]), kept symmetric positive
//! definite for every sphere whose centre lies above the wall.
//!
//! The Rotne-Prager-Blake tensor is positive definite while every sphere clears the wall (height
//! h ≥ a). Below that, the treatment of Balboa Usabiaga et al. (J. Chem. Phys. 146, 134104
//! (2017), appendix A) takes over: the mobility is evaluated with those spheres lifted to h = a
//! and damped by B = diag(min(1, h/a)), M̃ = B M(lifted) B, a congruence of a positive definite
//! matrix, so positive definite for any h > 0, continuous at h = a and vanishing at h = 0.

use super::rpb;
use super::Wall;
use crate::engine::mobility::{block_matrix, self_mobility, Blocks, Mobility, MobilityOperator};
use crate::engine::open_space::OpenSpace;
use crate::engine::parallel::PARALLEL_IMAGE_SPHERES;
use nalgebra::{DMatrix, Matrix3, Vector3};
use rayon::prelude::*;

/// The number of row chunks of the parallel pair terms: fixed, so that their sums add up in the
/// same order on any number of threads; enough to keep a few dozen cores busy.
const ROW_CHUNKS: usize = 32;

/// The first rows of `chunks` contiguous chunks of the half-loop over `n` rows (row i holds the
/// n − 1 − i pairs (i, j > i)), each with about the same number of pairs, and `n` at the end.
fn row_chunks(n: usize, chunks: usize) -> Vec<usize> {
    let total = n * n.saturating_sub(1) / 2;
    let mut starts = vec![0];
    let mut pairs = 0;
    for i in 0..n {
        pairs += n - 1 - i;
        if pairs * chunks >= total * starts.len() && starts.len() < chunks && i + 1 < n {
            starts.push(i + 1);
        }
    }
    starts.push(n);
    starts
}

/// Spheres in a fluid of viscosity `mu` above the no-slip plane of `wall`.
#[derive(Debug, Clone)]
pub struct WallMobility {
    mu: f64,
    kind: Mobility,
    wall: Wall,
    open: OpenSpace,
    /// Scratch: positions relative to the wall, lifted to h ≥ a (damped spheres only).
    lifted: Vec<Vector3<f64>>,
    /// Scratch: the damping factor of each sphere.
    damping: Vec<f64>,
    /// Scratch: the damped forces B F.
    damped: Vec<Vector3<f64>>,
}

impl WallMobility {
    /// The mobility above `wall` in a fluid of viscosity `mu`, spheres coupled by `kind`'s pair
    /// tensor in open space and its image: RPY's pairs take the image system through both
    /// spheres' Faxén operators, Oseen's take Blake's point-force image (radius 0). A sphere's
    /// own correction is the Faxén series for either kind.
    pub fn new(mu: f64, kind: Mobility, wall: Wall) -> Self {
        WallMobility {
            mu,
            kind,
            wall,
            open: OpenSpace::new(mu, kind),
            lifted: Vec::new(),
            damping: Vec::new(),
            damped: Vec::new(),
        }
    }

    /// The radius a sphere of radius `a` has in the pair image system of this kind.
    #[inline]
    fn image_radius(&self, a: f64) -> f64 {
        match self.kind {
            Mobility::Rpy => a,
            Mobility::Oseen => 0.0,
        }
    }

    /// Position `x` relative to the wall, lifted to height `a` if below it, and its damping
    /// factor min(1, h/a).
    #[inline]
    fn lift(&self, x: &Vector3<f64>, a: f64) -> (Vector3<f64>, f64) {
        let h = x.z - self.wall.z;
        if h >= a {
            (Vector3::new(x.x, x.y, h), 1.0)
        } else {
            (Vector3::new(x.x, x.y, a), h / a)
        }
    }

    /// Adds sphere i's wall terms to `out` (the damped forces and lifted positions of the
    /// last product): its own correction, and each pair (i, j > i) both ways by reciprocity,
    /// W_ji = W_ijᵀ.
    #[inline]
    fn add_wall_row(&self, i: usize, radii: &[f64], out: &mut [Vector3<f64>]) {
        let (xi, ai) = (self.lifted[i], radii[i]);
        let c = rpb::self_correction(self.mu, xi.z, ai);
        out[i] += c.component_mul(&self.damped[i]);
        for j in (i + 1)..radii.len() {
            let w = rpb::wall_correction(
                self.mu,
                &xi,
                &self.lifted[j],
                self.image_radius(ai),
                self.image_radius(radii[j]),
            );
            out[i] += w * self.damped[j];
            out[j] += w.transpose() * self.damped[i];
        }
    }

    /// M_αβ of spheres at `xa`, `xb` (relative to the wall, lifted), undamped.
    #[inline]
    fn undamped_block(
        &self,
        xa: &Vector3<f64>,
        xb: &Vector3<f64>,
        ai: f64,
        aj: f64,
        same: bool,
    ) -> Matrix3<f64> {
        if same {
            let c = rpb::self_correction(self.mu, xa.z, ai);
            return Matrix3::from_diagonal(&c) + Matrix3::identity() * self_mobility(self.mu, ai);
        }
        self.kind.pair_tensor(self.mu, &(xa - xb), ai, aj)
            + rpb::wall_correction(
                self.mu,
                xa,
                xb,
                self.image_radius(ai),
                self.image_radius(aj),
            )
    }

    /// The damped block M̃_αβ at lab positions `xa`, `xb`.
    fn damped_block(
        &self,
        xa: &Vector3<f64>,
        xb: &Vector3<f64>,
        ai: f64,
        aj: f64,
        same: bool,
    ) -> Matrix3<f64> {
        let (la, ba) = self.lift(xa, ai);
        if same {
            return self.undamped_block(&la, &la, ai, ai, true) * (ba * ba);
        }
        let (lb, bb) = self.lift(xb, aj);
        self.undamped_block(&la, &lb, ai, aj, false) * (ba * bb)
    }
}

/// Relative step of the central differences behind the divergence, in units of the radius: the
/// blocks vary on the scale of the height (≥ a), so the truncation error is ~(1e-5)² and the
/// round-off ~1e-16/1e-5 of the block, both far below the noise's own statistical error.
const DIVERGENCE_STEP_IN_RADII: f64 = 1e-5;

impl MobilityOperator for WallMobility {
    fn interaction_velocities(
        &mut self,
        pos: &[Vector3<f64>],
        radii: &[f64],
        forces: &[Vector3<f64>],
        out: &mut [Vector3<f64>],
    ) {
        let n = pos.len();
        self.lifted.clear();
        self.damping.clear();
        for (x, &a) in pos.iter().zip(radii) {
            let (l, b) = self.lift(x, a);
            self.lifted.push(l);
            self.damping.push(b);
        }
        let damped_any = self.damping.iter().any(|&b| b < 1.0);
        self.damped.clear();
        self.damped
            .extend(forces.iter().zip(&self.damping).map(|(f, b)| f * *b));
        // Open space's pairs at the lifted positions (equal to the true ones without damping;
        // the open tensor is invariant under the common shift by the wall's height).
        self.open
            .interaction_velocities(&self.lifted, radii, &self.damped, out);
        if n >= PARALLEL_IMAGE_SPHERES {
            // Fixed chunks of rows, each summed into its own buffer, the buffers added in chunk
            // order: the result does not depend on the threads or how the work was stolen.
            let starts = row_chunks(n, ROW_CHUNKS);
            let this = &*self;
            let parts: Vec<Vec<Vector3<f64>>> = starts
                .par_windows(2)
                .map(|w| {
                    let mut acc = vec![Vector3::zeros(); n];
                    for i in w[0]..w[1] {
                        this.add_wall_row(i, radii, &mut acc);
                    }
                    acc
                })
                .collect();
            for part in &parts {
                out.iter_mut().zip(part).for_each(|(o, w)| *o += w);
            }
        } else {
            for i in 0..n {
                self.add_wall_row(i, radii, out);
            }
        }
        if damped_any {
            // M̃F − DF = B(W + D)BF − DF: the damped spheres' own drag moves into W.
            for i in 0..n {
                let d = self_mobility(self.mu, radii[i]);
                out[i] = (out[i] + self.damped[i] * d) * self.damping[i] - forces[i] * d;
            }
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
        self.damped_block(xa, xb, ai, aj, same)
    }

    fn matrix(&self, pos: &[Vector3<f64>], radii: &[f64]) -> DMatrix<f64> {
        block_matrix(pos.len(), Blocks::Upper, |a, b| {
            self.damped_block(&pos[a], &pos[b], radii[a], radii[b], a == b)
        })
    }

    /// (∇·M)_α = Σ_β Σ_b ∂M_αβ[·, b]/∂x_β,b by central differences of the closed-form blocks:
    /// for β ≠ α the block moves with sphere β alone, the self block with sphere α, and only
    /// through its height. Open space's pair tensor is divergence-free and the lifted, damped
    /// blocks are not, so the whole block is differenced.
    fn divergence(&self, pos: &[Vector3<f64>], radii: &[f64], out: &mut [Vector3<f64>]) -> bool {
        if !self.wall.drift {
            return false;
        }
        let n = pos.len();
        for a in 0..n {
            let ai = radii[a];
            let mut div = Vector3::zeros();
            for b in 0..n {
                let aj = radii[b];
                let delta = DIVERGENCE_STEP_IN_RADII * aj;
                let same = a == b;
                let components = if same { 2..3 } else { 0..3 };
                for k in components {
                    let mut e = Vector3::zeros();
                    e[k] = delta;
                    let (plus, minus) = if same {
                        let (xp, xm) = (pos[a] + e, pos[a] - e);
                        (
                            self.damped_block(&xp, &xp, ai, ai, true),
                            self.damped_block(&xm, &xm, ai, ai, true),
                        )
                    } else {
                        (
                            self.damped_block(&pos[a], &(pos[b] + e), ai, aj, false),
                            self.damped_block(&pos[a], &(pos[b] - e), ai, aj, false),
                        )
                    };
                    div += (plus - minus).column(k) / (2.0 * delta);
                }
            }
            out[a] = div;
        }
        true
    }

    fn boxed(&self) -> Box<dyn MobilityOperator> {
        Box::new(self.clone())
    }
}
