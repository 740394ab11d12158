//! The mobility of spheres above a no-slip wall as a [`MobilityOperator`]: open space's RPY
//! tensor plus the Rotne-Prager-Blake wall correction ([`super::rpb`]), kept symmetric positive
//! definite for every sphere whose centre lies above the wall.
//!
//! The Rotne-Prager-Blake tensor is positive definite while every sphere clears the wall (height
//! h ≥ a). Below that, the treatment of Balboa Usabiaga et al. (J. Chem. Phys. 146, 134104
//! (2017), appendix A) takes over: the mobility is evaluated with those spheres lifted to h = a
//! and damped by B = diag(min(1, h/a)), M̃ = B M(lifted) B, a congruence of a positive definite
//! matrix, so positive definite for any h > 0, continuous at h = a and vanishing at h = 0.

use super::lanes::{wall_rows, WallSpheres, WallVelocities};
use super::rpb;
use super::Wall;
use crate::engine::mobility::{block_matrix, self_mobility, Blocks, Mobility, MobilityOperator};
use crate::engine::open_space::OpenSpace;
use crate::engine::parallel::PARALLEL_IMAGE_SPHERES;
use nalgebra::{DMatrix, Matrix3, Vector3};
use rayon::prelude::*;
use std::f64::consts::PI;

/// The most row chunks of the parallel pair terms: enough to keep a few dozen cores busy.
const ROW_CHUNKS: usize = 32;

/// The fewest pairs in a chunk of the parallel pair terms: enough work that handing a chunk to a
/// thread, and zeroing and adding its buffer (O(n)), are a small share of it.
const MIN_CHUNK_PAIRS: usize = 4096;

/// The number of row chunks of the pair terms of `n` spheres: one where a product is too short
/// to share (then it runs in one piece on one thread), at most [`ROW_CHUNKS`]. It depends on `n`
/// alone, so the chunks' sums add up in the same order on any number of threads.
fn chunk_count(n: usize) -> usize {
    (n * n.saturating_sub(1) / 2 / MIN_CHUNK_PAIRS).clamp(1, ROW_CHUNKS)
}

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

/// The wall's pair terms of the spheres `soa`, in units of 1/(8πμ), into `parts`: one buffer per
/// chunk of rows ([`chunk_count`]; the buffers' storage is kept from call to call), the chunks on
/// rayon's threads where there are several; the caller adds the buffers in chunk order, so the
/// result does not depend on the threads or how the work was stolen.
fn wall_pair_terms(soa: &WallSpheres, parts: &mut Vec<WallVelocities>) {
    let n = soa.len();
    let chunks = chunk_count(n);
    if chunks == 1 {
        parts.resize_with(1, WallVelocities::default);
        parts[0].reset(soa);
        wall_rows(soa, 0, n, &mut parts[0]);
        return;
    }
    // One buffer per chunk the rows were cut into: none left over with an earlier product's sums.
    let starts = row_chunks(n, chunks);
    parts.resize_with(starts.len() - 1, WallVelocities::default);
    starts
        .par_windows(2)
        .zip(parts.par_iter_mut())
        .for_each(|(w, u)| {
            u.reset(soa);
            wall_rows(soa, w[0], w[1], u);
        });
}

/// The radius a sphere of radius `a` has in the pair image system of `kind`: RPY's pairs take
/// both spheres' Faxén operators, Oseen's Blake's point-force image (radius 0).
#[inline]
fn image_radius(kind: Mobility, a: f64) -> f64 {
    match kind {
        Mobility::Rpy => a,
        Mobility::Oseen => 0.0,
    }
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
    /// Scratch: the lifted spheres and damped forces as the pair lanes read them.
    soa: WallSpheres,
    /// Scratch: the wall's pair terms, one buffer per chunk of rows.
    parts: Vec<WallVelocities>,
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
            soa: WallSpheres::default(),
            parts: Vec::new(),
        }
    }

    /// The radius a sphere of radius `a` has in the pair image system of this kind.
    #[inline]
    fn image_radius(&self, a: f64) -> f64 {
        image_radius(self.kind, a)
    }

    /// [`Wall::lift`].
    #[inline]
    fn lift(&self, x: &Vector3<f64>, a: f64) -> (Vector3<f64>, f64) {
        self.wall.lift(x, a)
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

impl WallMobility {
    /// Whether sphere `x` (radius `a`) lies clear of the damped layer by more than the
    /// divergence's steps: the pairs it makes with other such spheres add nothing to the
    /// divergence (`divergence`).
    #[inline]
    fn clear(&self, x: &Vector3<f64>, a: f64) -> bool {
        x.z - self.wall.z >= a * (1.0 + 2.0 * DIVERGENCE_STEP_IN_RADII)
    }

    /// Add the pair terms of the divergence of the spheres `rows` into `d`: each lies in the
    /// damped layer (not [`WallMobility::clear`]), and every pair it makes is differenced both
    /// ways, ∂M_αβ/∂x_β into α's and ∂M_βα/∂x_α (the rows of ∂M_αβ/∂x_α, M_βα = M_αβᵀ) into β's;
    /// a pair of two such spheres from its lower index only.
    fn damped_pair_divergence(
        &self,
        pos: &[Vector3<f64>],
        radii: &[f64],
        rows: &[usize],
        d: &mut [Vector3<f64>],
    ) {
        for &a in rows {
            let (xa, ai) = (pos[a], radii[a]);
            let step_a = DIVERGENCE_STEP_IN_RADII * ai;
            for b in 0..pos.len() {
                let (xb, aj) = (pos[b], radii[b]);
                if b == a || (b < a && !self.clear(&xb, aj)) {
                    continue;
                }
                let step_b = DIVERGENCE_STEP_IN_RADII * aj;
                let m =
                    |pa: &Vector3<f64>, pb: &Vector3<f64>| self.damped_block(pa, pb, ai, aj, false);
                for k in 0..3 {
                    let mut e = Vector3::zeros();
                    e[k] = step_b;
                    d[a] +=
                        central_difference(m(&xa, &(xb + e)), m(&xa, &(xb - e)), step_b).column(k);
                    let mut e = Vector3::zeros();
                    e[k] = step_a;
                    d[b] += central_difference(m(&(xa + e), &xb), m(&(xa - e), &xb), step_a)
                        .row(k)
                        .transpose();
                }
            }
        }
    }
}

/// The central difference (plus − minus)/(2 step).
#[inline]
fn central_difference(plus: Matrix3<f64>, minus: Matrix3<f64>, step: f64) -> Matrix3<f64> {
    (plus - minus) / (2.0 * step)
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
        // The wall's pair terms (in units of 1/(8πμ)), then each sphere's own correction, and
        // open space's pairs at the lifted positions (equal to the true ones without damping;
        // the open tensor is invariant under the common shift by the wall's height). The two
        // sums are independent: from PARALLEL_IMAGE_SPHERES spheres on they run side by side
        // on rayon's threads (each as it would alone, so the result does not depend on it).
        let kind = self.kind;
        let image_radii = radii.iter().map(|&a| image_radius(kind, a));
        self.soa
            .fill(self.lifted.iter().zip(image_radii).zip(&self.damped));
        let (open, lifted, damped, soa) = (&mut self.open, &self.lifted, &self.damped, &self.soa);
        let parts = &mut self.parts;
        let mut open_pairs = || open.interaction_velocities(lifted, radii, damped, out);
        if n >= PARALLEL_IMAGE_SPHERES {
            rayon::join(open_pairs, || wall_pair_terms(soa, parts));
        } else {
            open_pairs();
            wall_pair_terms(soa, parts);
        }
        let scale = 1.0 / (8.0 * PI * self.mu);
        for (i, o) in out.iter_mut().enumerate() {
            let mut w = Vector3::zeros();
            for part in &self.parts {
                w += Vector3::new(part.x[i], part.y[i], part.z[i]);
            }
            let c = rpb::self_correction(self.mu, self.lifted[i].z, radii[i]);
            *o += w * scale + c.component_mul(&self.damped[i]);
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
    /// each sphere's own block through its height, and the pairs that a sphere in the damped
    /// layer makes ([`WallMobility::damped_pair_divergence`], in fixed chunks of those spheres on
    /// rayon's threads from [`PARALLEL_IMAGE_SPHERES`] spheres, the chunks' sums added in chunk
    /// order: the result does not depend on the threads). A pair of spheres both clear of the
    /// layer adds nothing: its block is the Rotne-Prager-Blake tensor, Faxén operators on
    /// Blake's Green's function, which as the flow of the force on either sphere is
    /// divergence-free in the other's position (on the differenced blocks: 1e-10 of the self
    /// terms, their round-off). So the divergence costs O(n), and O(n) more for each sphere
    /// in the layer.
    fn divergence(&self, pos: &[Vector3<f64>], radii: &[f64], out: &mut [Vector3<f64>]) -> bool {
        if !self.wall.drift {
            return false;
        }
        let n = pos.len();
        for ((o, x), &a) in out.iter_mut().zip(pos).zip(radii) {
            let step = DIVERGENCE_STEP_IN_RADII * a;
            let (up, down) = (x + Vector3::z() * step, x - Vector3::z() * step);
            *o = central_difference(
                self.damped_block(&up, &up, a, a, true),
                self.damped_block(&down, &down, a, a, true),
                step,
            )
            .column(2)
            .into();
        }
        let damped: Vec<usize> = (0..n).filter(|&a| !self.clear(&pos[a], radii[a])).collect();
        if damped.is_empty() {
            return true;
        }
        let pairs = |rows: &[usize]| {
            let mut d = vec![Vector3::zeros(); n];
            self.damped_pair_divergence(pos, radii, rows, &mut d);
            d
        };
        let parts: Vec<Vec<Vector3<f64>>> = if n >= PARALLEL_IMAGE_SPHERES {
            damped
                .par_chunks(damped.len().div_ceil(ROW_CHUNKS))
                .map(pairs)
                .collect()
        } else {
            vec![pairs(&damped)]
        };
        for part in &parts {
            for (o, d) in out.iter_mut().zip(part) {
                *o += d;
            }
        }
        true
    }

    fn boxed(&self) -> Box<dyn MobilityOperator> {
        Box::new(self.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::open_space::FAST_KERNEL_SPHERES;
    use nalgebra::DVector;

    /// `n` spheres of radii 0.5 to 1.5 µm above a wall at `z0`, drawn by `next` (uniform in
    /// [0, 1)): every third below one radius (0.2 a to a: damped, lifted), the rest from 1.05 a
    /// to `rise` higher, over a square `width` wide.
    fn spheres_above(
        next: &mut impl FnMut() -> f64,
        n: usize,
        z0: f64,
        rise: f64,
        width: f64,
    ) -> (Vec<f64>, Vec<Vector3<f64>>) {
        let radii: Vec<f64> = (0..n).map(|_| (0.5 + next()) * 1e-6).collect();
        let pos = radii
            .iter()
            .enumerate()
            .map(|(k, a)| {
                let h = if k % 3 == 0 {
                    (0.2 + 0.8 * next()) * a
                } else {
                    a * 1.05 + next() * rise
                };
                Vector3::new(next() * width, next() * width, z0 + h)
            })
            .collect();
        (radii, pos)
    }

    /// The product W F against the matrix's (M − D) F, M from the scalar blocks (`wall_correction`
    /// and the self series): RPY and Oseen, unequal radii, a third of the spheres below one
    /// radius (damped, lifted), sizes not a multiple of the lane width on the serial path, the
    /// open and wall sums side by side (from PARALLEL_IMAGE_SPHERES), open space's row kernel
    /// (from FAST_KERNEL_SPHERES) and the wall's terms in several chunks (131 spheres: two).
    /// Tolerance 1e-12 of the largest M F: both sides add the same terms in another order
    /// (lanes, chunks, Horner chains, AVX-512's 1/r within 2 ulp), and the matrix side's drag,
    /// up to the largest M F, is subtracted back out.
    #[test]
    fn product_equals_the_matrix_minus_drag() {
        let mu = 1e-3;
        let z0 = -2e-6;
        let mut rng = crate::engine::rng::Rng::new(0x9e37_79b9_7f4a_7c15);
        let mut next = || rng.uniform();
        let sizes = [
            5,
            13,
            PARALLEL_IMAGE_SPHERES + 7,
            FAST_KERNEL_SPHERES + 13,
            131,
        ];
        assert!(chunk_count(131) == 2 && chunk_count(FAST_KERNEL_SPHERES + 13) == 1);
        for kind in [Mobility::Rpy, Mobility::Oseen] {
            for n in sizes {
                let mut op = WallMobility::new(mu, kind, Wall::at(z0).expect("a finite wall"));
                let (radii, pos) = spheres_above(&mut next, n, z0, 15e-6, 30e-6);
                let forces: Vec<Vector3<f64>> = (0..n)
                    .map(|_| Vector3::new(next() - 0.5, next() - 0.5, next() - 0.5) * 1e-12)
                    .collect();
                let mut w = vec![Vector3::zeros(); n];
                op.interaction_velocities(&pos, &radii, &forces, &mut w);
                let f =
                    DVector::from_iterator(3 * n, forces.iter().flat_map(|f| f.iter().copied()));
                let mf = op.matrix(&pos, &radii) * f;
                let scale = mf.amax();
                for a in 0..n {
                    let drag = forces[a] * self_mobility(mu, radii[a]);
                    for k in 0..3 {
                        let expected = mf[3 * a + k] - drag[k];
                        assert!(
                            (w[a][k] - expected).abs() <= 1e-12 * scale,
                            "{kind:?}, n {n}, sphere {a}, component {k}: {} vs {expected}",
                            w[a][k]
                        );
                    }
                }
            }
        }
    }

    /// Every ordered pair's whole damped block differenced in all three coordinates of the
    /// partner, serially: the divergence by its definition, the yardstick of the fast one.
    fn divergence_by_definition(
        op: &WallMobility,
        pos: &[Vector3<f64>],
        radii: &[f64],
    ) -> Vec<Vector3<f64>> {
        let n = pos.len();
        (0..n)
            .map(|a| {
                let mut div = Vector3::zeros();
                for b in 0..n {
                    let delta = DIVERGENCE_STEP_IN_RADII * radii[b];
                    let components = if a == b { 2..3 } else { 0..3 };
                    for k in components {
                        let mut e = Vector3::zeros();
                        e[k] = delta;
                        let (plus, minus) = if a == b {
                            let (xp, xm) = (pos[a] + e, pos[a] - e);
                            (
                                op.damped_block(&xp, &xp, radii[a], radii[a], true),
                                op.damped_block(&xm, &xm, radii[a], radii[a], true),
                            )
                        } else {
                            (
                                op.damped_block(&pos[a], &(pos[b] + e), radii[a], radii[b], false),
                                op.damped_block(&pos[a], &(pos[b] - e), radii[a], radii[b], false),
                            )
                        };
                        div += (plus - minus).column(k) / (2.0 * delta);
                    }
                }
                div
            })
            .collect()
    }

    /// The divergence (self terms, and pairs with a sphere in the damped layer once both ways;
    /// pairs clear of it add nothing; rows in parallel chunks) against its definition: RPY and
    /// Oseen, unequal radii, a third of the spheres below one radius, one overlapping pair, the serial and the
    /// parallel path. Tolerance 1e-8 of the largest component: both sides are central differences
    /// at the same step (truncation ~(1e-5)² relative), but the definition also differences open
    /// space's tensor, whose exact divergence is zero and whose differenced one is round-off,
    /// ~1e-16 of a block over a step of 1e-5 radii, ~1e-11 of a divergence term, summed over up
    /// to ~70 pairs (measured: 2.7e-11 to 6.1e-10); leaving out the pairs of the spheres in the
    /// layer is off by 1.1e-4.
    #[test]
    fn the_divergence_is_its_definition() {
        let mu = 1e-3;
        let z0 = 1e-6;
        let mut rng = crate::engine::rng::Rng::new(0x2545_f491_4f6c_dd1d);
        let mut next = || rng.uniform();
        for kind in [Mobility::Rpy, Mobility::Oseen] {
            for n in [6, PARALLEL_IMAGE_SPHERES + 7] {
                let op = WallMobility::new(mu, kind, Wall::at(z0).expect("a finite wall"));
                let (radii, mut pos) = spheres_above(&mut next, n, z0, 8e-6, 12e-6);
                // Spheres 1 and 2 (both clear) overlapping.
                pos[2] = pos[1] + Vector3::new(0.5 * (radii[1] + radii[2]), 0.0, 0.0);
                pos[2].z = pos[1].z.max(z0 + 1.1 * radii[2]);
                let mut fast = vec![Vector3::zeros(); n];
                assert!(op.divergence(&pos, &radii, &mut fast));
                let slow = divergence_by_definition(&op, &pos, &radii);
                let scale = slow.iter().map(|d| d.amax()).fold(0.0, f64::max);
                for (a, (f, s)) in fast.iter().zip(&slow).enumerate() {
                    assert!(
                        (f - s).amax() <= 1e-8 * scale,
                        "{kind:?}, n {n}, sphere {a}: {f:?} against {s:?} (scale {scale:e})"
                    );
                }
            }
        }
    }
}
