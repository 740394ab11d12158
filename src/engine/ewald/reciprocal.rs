//! The reciprocal part of Beenakker's product through structure factors, in vector lanes.
//!
//! Per wave k (half space; its partner −k adds the same real part): the phases e^{ik·x_j} of every
//! sphere from the box's per-axis tables ([`WavePhases`]: two complex products a sphere, no sine
//! or cosine), the structure factors C = Σ_j F_j e^{−ik·x_j} and D = Σ_j a_j² F_j e^{−ik·x_j}, and for every sphere
//! g Re[e^{ik·x_i}(I − k̂k̂)((1 − a_i²k²/6) C − (k²/6) D)]: O(N) per wave, O(N·K) in all. The
//! waves are taken in fixed chunks whose sums are added in order, so the result does not depend
//! on the number of threads.

use crate::engine::periodic::{PeriodicBox, WavePhases};
use crate::engine::simd::{block, lane_sum, vector_dispatch, LANES};
use nalgebra::Vector3;
use rayon::prelude::*;

/// One reciprocal vector of the half space.
#[derive(Debug, Clone, Copy)]
pub(super) struct Wave {
    pub(super) n: [i64; 3],
    pub(super) k: Vector3<f64>,
    pub(super) k2: f64,
    /// 2 (6π/V)(1 + k²/4ξ² + k⁴/8ξ⁴) e^{−k²/4ξ²}/k², in units of 1/(6πμ).
    pub(super) g: f64,
}

/// Waves per chunk: a chunk's sums are one thread's work and are added in chunk order.
const CHUNK: usize = 32;

/// The spheres as the wave pass reads them: per-axis phase tables, forces and a²·forces in
/// lanes.
struct Lanes {
    phases: WavePhases,
    f: [Vec<f64>; 3],
    fa: [Vec<f64>; 3],
    /// a² per sphere (0 for Oseen).
    a2: Vec<f64>,
    count: usize,
}

/// Add the reciprocal part, in units of 1/(6πμ), to `out` for spheres at `pos` (radii `radii`,
/// forces `forces`; `finite`: RPY's a² terms, else Oseen).
#[allow(clippy::too_many_arguments)]
pub(super) fn add_reciprocal(
    periodic: &PeriodicBox,
    waves: &[Wave],
    n_max: [usize; 3],
    finite: bool,
    pos: &[Vector3<f64>],
    radii: &[f64],
    forces: &[Vector3<f64>],
    out: &mut [Vector3<f64>],
    parallel: bool,
) {
    let count = pos.len();
    let a2: Vec<f64> = radii
        .iter()
        .map(|a| if finite { a * a } else { 0.0 })
        .collect();
    let lanes = Lanes {
        phases: WavePhases::new(periodic, pos, n_max),
        f: [0, 1, 2].map(|q| forces.iter().map(|f| f[q]).collect()),
        fa: [0, 1, 2].map(|q| forces.iter().zip(&a2).map(|(f, a)| a * f[q]).collect()),
        a2,
        count,
    };
    let chunk = |ws: &[Wave]| {
        let mut acc = [vec![0.0; count], vec![0.0; count], vec![0.0; count]];
        let (mut re, mut im) = (vec![0.0; count], vec![0.0; count]);
        for w in ws {
            wave_pass(&lanes, w, &mut acc, &mut re, &mut im);
        }
        acc
    };
    let sums: Vec<[Vec<f64>; 3]> = if parallel {
        waves.par_chunks(CHUNK).map(chunk).collect()
    } else {
        waves.chunks(CHUNK).map(chunk).collect()
    };
    for acc in &sums {
        for (i, u) in out.iter_mut().enumerate() {
            *u += Vector3::new(acc[0][i], acc[1][i], acc[2][i]);
        }
    }
}

/// e^{ik·x} = (x)(y)(z) from a sphere's three axis powers (re, im), the y and z powers conjugated
/// by `sy`, `sz` = −1 along an axis of negative index (the half space's x index is not negative).
#[inline(always)]
fn phase(x: (f64, f64), y: (f64, f64), z: (f64, f64), sy: f64, sz: f64) -> (f64, f64) {
    let (br, bi) = (y.0, sy * y.1);
    let (cr, ci) = (x.0 * br - x.1 * bi, x.0 * bi + x.1 * br);
    let (dr, di) = (z.0, sz * z.1);
    (cr * dr - ci * di, cr * di + ci * dr)
}

/// One wave: the phases into `re`, `im`, the structure factors, and every sphere's velocity
/// added to `acc`.
#[inline(always)]
fn wave_pass_body(l: &Lanes, w: &Wave, acc: &mut [Vec<f64>; 3], re: &mut [f64], im: &mut [f64]) {
    let count = l.count;
    let row = |d: usize| {
        let (re, im) = l.phases.row(d, w.n[d].unsigned_abs() as usize);
        (re, im, if w.n[d] < 0 { -1.0 } else { 1.0 })
    };
    let ((xr, xi, _), (yr, yi, sy), (zr, zi, sz)) = (row(0), row(1), row(2));
    // The phases, and C and D (with e^{−ik·x} = re − i im) as 12 sums in lanes, block by block
    // (exact blocks as arrays), then the spheres past the last block.
    let blocks = count / LANES;
    let arr = |v: &[f64], b: usize| block(v, b * LANES);
    let mut s = [[0.0; LANES]; 12];
    for b in 0..blocks {
        let (ar, ai, br, bi, cr, ci) = (
            arr(xr, b),
            arr(xi, b),
            arr(yr, b),
            arr(yi, b),
            arr(zr, b),
            arr(zi, b),
        );
        let f = [arr(&l.f[0], b), arr(&l.f[1], b), arr(&l.f[2], b)];
        let fa = [arr(&l.fa[0], b), arr(&l.fa[1], b), arr(&l.fa[2], b)];
        let mut pr = [0.0; LANES];
        let mut pi = [0.0; LANES];
        for k in 0..LANES {
            let (r, m) = phase((ar[k], ai[k]), (br[k], bi[k]), (cr[k], ci[k]), sy, sz);
            pr[k] = r;
            pi[k] = m;
            for q in 0..3 {
                s[4 * q][k] += f[q][k] * r;
                s[4 * q + 1][k] -= f[q][k] * m;
                s[4 * q + 2][k] += fa[q][k] * r;
                s[4 * q + 3][k] -= fa[q][k] * m;
            }
        }
        re[b * LANES..(b + 1) * LANES].copy_from_slice(&pr);
        im[b * LANES..(b + 1) * LANES].copy_from_slice(&pi);
    }
    let mut c = [[0.0; 4]; 3];
    for q in 0..3 {
        for m in 0..4 {
            c[q][m] = lane_sum(&s[4 * q + m]);
        }
    }
    for j in blocks * LANES..count {
        let (r, m) = phase((xr[j], xi[j]), (yr[j], yi[j]), (zr[j], zi[j]), sy, sz);
        re[j] = r;
        im[j] = m;
        for q in 0..3 {
            c[q][0] += l.f[q][j] * r;
            c[q][1] -= l.f[q][j] * m;
            c[q][2] += l.fa[q][j] * r;
            c[q][3] -= l.fa[q][j] * m;
        }
    }
    // (I − k̂k̂) applied to each of Re C, Im C, Re D, Im D.
    let k = [w.k[0], w.k[1], w.k[2]];
    let mut pc = [[0.0; 4]; 3];
    for m in 0..4 {
        let kv = (k[0] * c[0][m] + k[1] * c[1][m] + k[2] * c[2][m]) / w.k2;
        for q in 0..3 {
            pc[q][m] = w.g * (c[q][m] - k[q] * kv);
        }
    }
    let q6 = w.k2 / 6.0;
    // Re[e^{ik·x_i}(p C − (k²/6) D)] after the projection = r α − m β with α = p Re C' − (k²/6)
    // Re D' and β = p Im C' − (k²/6) Im D' (p = 1 − a_i²k²/6): four fused operations a component.
    let d6 = [0, 1, 2].map(|q| [q6 * pc[q][2], q6 * pc[q][3]]);
    for i in 0..count {
        let p = 1.0 - l.a2[i] * q6;
        let (r, m) = (re[i], im[i]);
        for q in 0..3 {
            let alpha = p.mul_add(pc[q][0], -d6[q][0]);
            let beta = p.mul_add(pc[q][1], -d6[q][1]);
            acc[q][i] = (-m).mul_add(beta, r.mul_add(alpha, acc[q][i]));
        }
    }
}

vector_dispatch! {
    /// [`wave_pass_body`] in the widest vector unit present.
    fn wave_pass(l: &Lanes, w: &Wave, acc: &mut [Vec<f64>; 3], re: &mut [f64], im: &mut [f64]) = wave_pass_body;
}
