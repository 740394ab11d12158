//! The wall's pair terms in vector lanes: u_i += Σ_{j≠i} W_ij F_j with W the Rotne-Prager-Blake
//! correction of [`super::rpb::wall_correction`], each pair (i, j > i) evaluated once and applied
//! both ways by reciprocity (W_ji = W_ijᵀ).
//!
//! A row i runs over its partners j > i in blocks of [`LANES`]: row i's own sum in lane
//! accumulators, the partners' terms added straight into their contiguous slots of the output
//! (each lane a different partner), so the compiler maps the block onto vector registers
//! (AVX-512 or AVX2 with FMA, chosen at run time). The coefficients A … E are those of
//! `wall_correction`, rearranged as Horner chains in 1/r² of fused multiply-adds; 1/r is the
//! vector build's ([`InvSqrt`]). The sums of a range of rows depend only on the sphere data and
//! the range (not on the thread that runs it); the caller fixes the ranges.
//!
//! No pair needs a mask: the image lies below the wall, so r ≥ z_i + z_j > 0 for spheres lifted
//! to h ≥ a. A sphere's own correction (diagonal, from its true radius for either pair kind) is
//! not here; the operator adds it.

use crate::engine::simd::{block, lane_sum, vector_dispatch, InvSqrt, LANES};
use nalgebra::Vector3;

/// The spheres as structure of arrays: positions relative to the wall (lifted), the radius each
/// has in the pair image system (squared), and the (damped) forces, followed by `LANES − 1`
/// forceless copies of the last sphere ([`WallSpheres::fill`] lays them), so that every row's
/// last block of partners is a full vector block (no scalar tail).
#[derive(Debug, Clone, Default)]
pub(super) struct WallSpheres {
    /// Number of spheres (the padding excluded).
    n: usize,
    x: Vec<f64>,
    y: Vec<f64>,
    /// Heights above the wall.
    z: Vec<f64>,
    /// Image radii squared (RPY: a², Oseen: 0).
    a2: Vec<f64>,
    fx: Vec<f64>,
    fy: Vec<f64>,
    fz: Vec<f64>,
}

impl WallSpheres {
    /// Hold these spheres: each at `x` (relative to the wall), of image radius `a`, under force
    /// `f`; then the padding. The storage is kept from one filling to the next.
    pub(super) fn fill<'a>(
        &mut self,
        spheres: impl IntoIterator<Item = ((&'a Vector3<f64>, f64), &'a Vector3<f64>)>,
    ) {
        self.n = 0;
        for v in [
            &mut self.x,
            &mut self.y,
            &mut self.z,
            &mut self.a2,
            &mut self.fx,
            &mut self.fy,
            &mut self.fz,
        ] {
            v.clear();
        }
        for ((x, a), f) in spheres {
            self.n += 1;
            self.x.push(x.x);
            self.y.push(x.y);
            self.z.push(x.z);
            self.a2.push(a * a);
            self.fx.push(f.x);
            self.fy.push(f.y);
            self.fz.push(f.z);
        }
        self.pad();
    }

    /// Number of spheres.
    pub(super) fn len(&self) -> usize {
        self.n
    }

    /// Append `LANES − 1` copies of the last sphere with no force and image radius 0: every
    /// coefficient of a pair with such a copy is finite (its image lies below the wall, at a
    /// distance of a real pair's), so its term on a row is exactly zero, and the terms it
    /// receives land in slots past the spheres, which no caller reads.
    fn pad(&mut self) {
        let Some(last) = self.n.checked_sub(1) else {
            return;
        };
        for _ in 1..LANES {
            self.x.push(self.x[last]);
            self.y.push(self.y[last]);
            self.z.push(self.z[last]);
            self.a2.push(0.0);
            self.fx.push(0.0);
            self.fy.push(0.0);
            self.fz.push(0.0);
        }
    }
}

/// Velocities as structure of arrays, in units of 1/(8πμ) (the caller scales them).
#[derive(Debug, Clone, Default)]
pub(super) struct WallVelocities {
    pub(super) x: Vec<f64>,
    pub(super) y: Vec<f64>,
    pub(super) z: Vec<f64>,
}

impl WallVelocities {
    /// Zero these velocities, sized for the spheres `s` and their padding (the spheres' slots
    /// are the first `s.len()`), keeping the storage.
    pub(super) fn reset(&mut self, s: &WallSpheres) {
        let n = s.x.len();
        for v in [&mut self.x, &mut self.y, &mut self.z] {
            v.clear();
            v.resize(n, 0.0);
        }
    }
}

/// 1/3, rounded once.
const THIRD: f64 = 1.0 / 3.0;

/// Row i's data for [`pair_terms`].
#[derive(Clone, Copy)]
struct Row {
    x: f64,
    y: f64,
    z: f64,
    a2: f64,
    f: [f64; 3],
}

/// The coefficients (A, B, C, D, E) of 8πμ W_ij for spheres i, j of image radii² `ai2`, `aj2`
/// with R = x_i − x_j*, r3 = z_i + z_j (heights above the wall), h = z_j and `q` = 1/|R| (see
/// [`super::rpb`]): 8πμ W_ij = [[A + B Rx², B Rx Ry, C Rx], [B Ry Rx, A + B Ry², C Ry],
/// [D Rx, D Ry, E]].
#[inline(always)]
pub(crate) fn image_coefficients(
    r3: f64,
    h: f64,
    ai2: f64,
    aj2: f64,
    q: f64,
) -> (f64, f64, f64, f64, f64) {
    let q2 = q * q;
    let aa = ai2 * aj2;
    let dh = ai2 - aj2;
    let sum2 = ai2 + aj2;
    let r3r3 = r3 * r3;
    let r3h = 6.0 * r3 * h;
    let hh6 = 6.0 * h * h;
    // t = r3² a_j² + r3 h (a_i² − a_j²), s = 3t + a_i² a_j².
    let t = r3.mul_add(h * dh, r3r3 * aj2);
    let s = 3.0f64.mul_add(t, aa);
    // The coefficients of each polynomial in q² (A = q (a0 + q² (a1 + q² (a2 + q² a3))), and so
    // on), term by term those of `wall_correction`; its divisions by 3 are products with
    // constants here (a division costs the vector unit several times a product).
    let raa = r3r3 * aa;
    let a1 = (hh6 - r3h - sum2) * THIRD;
    let a2c = s * (2.0 * THIRD);
    let a3 = raa * (-10.0 * THIRD);
    let b1 = r3h - hh6 + sum2;
    let b2 = s * (-10.0 * THIRD);
    let b3 = raa * (70.0 * THIRD);
    let c0 = 2.0 * h - r3;
    let c1 = r3h.mul_add(h - r3, r3 * (ai2 - 3.0 * aj2)) - 2.0 * h * dh;
    let c2 = 10.0 * r3 * (t + aa);
    let c3 = -b3 * r3;
    let d1 = r3h.mul_add(r3 - h, r3 * sum2) + 2.0 * h * dh;
    let e1 = -(3.0 * r3r3 - r3h + sum2 + hh6) * THIRD;
    let e2 = (r3h * r3).mul_add(h - r3, r3r3 * (ai2 - 5.0 * aj2)) - r3h * dh - 2.0 * aa;
    let e3 = 10.0 * r3r3 * (t + 2.0 * aa);
    let e4 = c3 * r3;
    let q3 = q * q2;
    let a_ = q * q2.mul_add(q2.mul_add(q2.mul_add(a3, a2c), a1), -1.0);
    let b_ = q3 * q2.mul_add(q2.mul_add(q2.mul_add(b3, b2), b1), -1.0);
    let c_ = q3 * q2.mul_add(q2.mul_add(q2.mul_add(c3, c2), c1), c0);
    let d_ = q3 * q2.mul_add(q2.mul_add(q2.mul_add(-c3, -c2), d1), c0);
    let e_ = q * q2.mul_add(q2.mul_add(q2.mul_add(q2.mul_add(e4, e3), e2), e1), -1.0);
    (a_, b_, c_, d_, e_)
}

/// 8πμ (W_ij F_j, W_ji F_i) for row `p` = i and partner j at (`x`, `y`, `z`), image radius² `a2`,
/// force `f`, with `q` = 1/r, r = |x_i − x_j*|: W_ij F_j = (A f_∥ + R_∥ (B R_∥·f_∥ + C f_z),
/// D R_∥·f_∥ + E f_z) and W_ijᵀ F_i = (A f_∥ + R_∥ (B R_∥·f_∥ + D f_z), C R_∥·f_∥ + E f_z)
/// ([`image_coefficients`]).
#[inline(always)]
fn pair_terms(
    p: &Row,
    x: f64,
    y: f64,
    z: f64,
    a2: f64,
    f: [f64; 3],
    q: f64,
) -> ([f64; 3], [f64; 3]) {
    let (rx, ry) = (p.x - x, p.y - y);
    let (a_, b_, c_, d_, e_) = image_coefficients(p.z + z, z, p.a2, a2, q);
    // W_ij F_j.
    let rfj = rx.mul_add(f[0], ry * f[1]);
    let gj = b_.mul_add(rfj, c_ * f[2]);
    let to_i = [
        rx.mul_add(gj, a_ * f[0]),
        ry.mul_add(gj, a_ * f[1]),
        d_.mul_add(rfj, e_ * f[2]),
    ];
    // W_ijᵀ F_i = W_ji F_i.
    let fi = p.f;
    let rfi = rx.mul_add(fi[0], ry * fi[1]);
    let gi = b_.mul_add(rfi, d_ * fi[2]);
    let to_j = [
        rx.mul_add(gi, a_ * fi[0]),
        ry.mul_add(gi, a_ * fi[1]),
        c_.mul_add(rfi, e_ * fi[2]),
    ];
    (to_i, to_j)
}

/// The pair terms of rows `first..last` against their partners j > i, added to `u` (all spheres'
/// slots and the padding's, [`WallVelocities::reset`]) in units of 1/(8πμ); 1/r is `U`'s. The
/// partners run in whole vector blocks, the last one into the padding.
#[inline(always)]
fn rows_impl<U: InvSqrt>(s: &WallSpheres, first: usize, last: usize, u: &mut WallVelocities) {
    assert!(
        u.x.len() == s.x.len(),
        "the wall's pair lanes need velocities sized by WallVelocities::reset"
    );
    let n = s.len();
    for i in first..last {
        let p = Row {
            x: s.x[i],
            y: s.y[i],
            z: s.z[i],
            a2: s.a2[i],
            f: [s.fx[i], s.fy[i], s.fz[i]],
        };
        let r2 = |x: f64, y: f64, z: f64| {
            let (rx, ry, r3) = (p.x - x, p.y - y, p.z + z);
            rx.mul_add(rx, ry.mul_add(ry, r3 * r3))
        };
        let mut ax = [0.0; LANES];
        let mut ay = [0.0; LANES];
        let mut az = [0.0; LANES];
        let start = i + 1;
        let blocks = (n - start).div_ceil(LANES);
        for b in 0..blocks {
            let o = start + b * LANES;
            let l8 = o..o + LANES;
            let lanes = |v: &[f64]| block(v, o);
            let (x, y, z, a2) = (lanes(&s.x), lanes(&s.y), lanes(&s.z), lanes(&s.a2));
            let (fx, fy, fz) = (lanes(&s.fx), lanes(&s.fy), lanes(&s.fz));
            let whole = "a block of LANES slots: the velocities are padded";
            let ux: &mut [f64; LANES] = (&mut u.x[l8.clone()]).try_into().expect(whole);
            let uy: &mut [f64; LANES] = (&mut u.y[l8.clone()]).try_into().expect(whole);
            let uz: &mut [f64; LANES] = (&mut u.z[l8]).try_into().expect(whole);
            let d2: [f64; LANES] = std::array::from_fn(|l| r2(x[l], y[l], z[l]));
            // SAFETY: `U` is the one vector_dispatch! chose for the unit this build runs on.
            let q = unsafe { U::inv_sqrt(d2) };
            let (mut vx, mut vy, mut vz) = (*ux, *uy, *uz);
            for l in 0..LANES {
                let (ti, tj) = pair_terms(&p, x[l], y[l], z[l], a2[l], [fx[l], fy[l], fz[l]], q[l]);
                ax[l] += ti[0];
                ay[l] += ti[1];
                az[l] += ti[2];
                vx[l] += tj[0];
                vy[l] += tj[1];
                vz[l] += tj[2];
            }
            (*ux, *uy, *uz) = (vx, vy, vz);
        }
        u.x[i] += lane_sum(&ax);
        u.y[i] += lane_sum(&ay);
        u.z[i] += lane_sum(&az);
    }
}

vector_dispatch! {
    /// The pair terms of rows `first..last` (each with its partners j > i, both ways), added to
    /// `u` in units of 1/(8πμ), in the widest vector unit present.
    pub(super) fn wall_rows(s: &WallSpheres, first: usize, last: usize, u: &mut WallVelocities) = rows_impl::<InvSqrt>;
}

#[cfg(test)]
mod tests {
    use super::super::rpb::wall_correction;
    use super::*;
    use std::f64::consts::PI;

    const MU: f64 = 1e-3;

    fn random(rng: &mut crate::engine::rng::Rng) -> f64 {
        rng.uniform()
    }

    /// The lanes against the scalar blocks summed pair by pair, Σ_{j≠i} W_ij F_j, for sizes below,
    /// at and above multiples of the lane width (a last block reaching into the padding, full
    /// blocks, both), spheres filled over an earlier filling, unequal
    /// image radii (zero ones too, as Oseen's), heights from one radius to far above, and rows
    /// split into ranges (as the parallel chunks split them). Tolerance 1e-12 of the largest
    /// velocity: the two differ by summation order, Horner chains against expanded powers and
    /// AVX-512's 1/r (within 2 ulp), each a few ulp of terms no larger than that velocity.
    #[test]
    fn lanes_equal_the_scalar_blocks() {
        let mut seed = crate::engine::rng::Rng::new(0x2545_f491_4f6c_dd1d);
        for n in [1, 2, 7, 8, 9, 17, 24, 37] {
            for oseen in [false, true] {
                let mut s = WallSpheres::default();
                let mut pos = Vec::new();
                let mut radii = Vec::new();
                let mut forces = Vec::new();
                for _ in 0..n {
                    let a = (0.4 + random(&mut seed)) * 1e-6;
                    let a = if oseen { 0.0 } else { a };
                    let x = Vector3::new(
                        random(&mut seed) * 20e-6,
                        random(&mut seed) * 20e-6,
                        1e-6 + random(&mut seed) * 10e-6,
                    );
                    let f = Vector3::new(
                        random(&mut seed) - 0.5,
                        random(&mut seed) - 0.5,
                        random(&mut seed) - 0.5,
                    ) * 1e-12;
                    pos.push(x);
                    radii.push(a);
                    forces.push(f);
                }
                // Filled twice: the second filling replaces the first, padding and all.
                s.fill(pos.iter().rev().zip([2e-6; 40]).zip(&forces));
                s.fill(pos.iter().zip(radii.iter().copied()).zip(&forces));
                let scale = 8.0 * PI * MU;
                let expected: Vec<Vector3<f64>> = (0..n)
                    .map(|i| {
                        (0..n)
                            .filter(|&j| j != i)
                            .map(|j| {
                                wall_correction(MU, &pos[i], &pos[j], radii[i], radii[j])
                                    * forces[j]
                                    * scale
                            })
                            .sum()
                    })
                    .collect();
                let largest = expected.iter().map(|v| v.amax()).fold(0.0, f64::max);
                for split in [n, n / 2, 1] {
                    let mut u = WallVelocities::default();
                    u.reset(&s);
                    let mut first = 0;
                    while first < n {
                        let last = (first + split.max(1)).min(n);
                        wall_rows(&s, first, last, &mut u);
                        first = last;
                    }
                    for (i, e) in expected.iter().enumerate() {
                        let got = Vector3::new(u.x[i], u.y[i], u.z[i]);
                        assert!(
                            (got - e).amax() <= 1e-12 * largest,
                            "n {n}, oseen {oseen}, split {split}, sphere {i}: {got} vs {e}"
                        );
                    }
                }
            }
        }
    }
}
