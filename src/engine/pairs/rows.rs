//! The row kernel: each sphere's row sums over all partners, every pair evaluated from both
//! ends, in blocks of [`LANES`] lanes; rows are independent and run in parallel.

use super::soa::SoaSpheres;
use super::tensor::{add_overlapping, prefactors, Kernel};
use crate::engine::mobility::Mobility;
use crate::engine::simd::{lane_sum, vector_dispatch, LANES};
use rayon::prelude::*;

/// Rows per parallel task.
const ROWS_PER_TASK: usize = 32;

/// u_i for the rows `first..first + u.len()`, written to `u` as (ux, uy, uz).
///
/// Overlapping pairs (r ≤ a_i + a_j, RPY only; coincident spheres included) are masked out of
/// the vector loop, counted per lane, and added afterwards in a scalar pass with the overlapping-sphere form
/// ([`Mobility::pair_apply`]); rows without overlaps (all of them in a scene that stops at
/// contact) never take that pass.
#[inline(always)]
fn rows_impl(s: &SoaSpheres, k: Kernel, first: usize, u: &mut [[f64; 3]]) {
    let (c1, c3) = (k.c1, k.c3);
    // Oseen has no finite size: nothing is masked.
    let reach = if c3 != 0.0 { 1.0 } else { 0.0 };
    let n = s.len();
    let blocks = n / LANES;
    for (row, out) in u.iter_mut().enumerate() {
        let i = first + row;
        let (xi, yi, zi, ai, ai2) = (s.x[i], s.y[i], s.z[i], s.a[i] * reach, s.a2[i]);
        let mut ax = [0.0; LANES];
        let mut ay = [0.0; LANES];
        let mut az = [0.0; LANES];
        let mut overlaps = [0.0; LANES];
        let term = |x: f64, y: f64, z: f64, a: f64, a2: f64, fx: f64, fy: f64, fz: f64| {
            let (rx, ry, rz) = (xi - x, yi - y, zi - z);
            let r2 = rx * rx + ry * ry + rz * rz;
            let inv = 1.0 / r2.sqrt();
            let contact = ai + a * reach;
            let separated = r2 > contact * contact;
            let inv_r = if separated { inv } else { 0.0 };
            // Counts the row's own sphere too (r² = 0), so a row overlaps from a count of 2.
            let overlap = if separated { 0.0 } else { 1.0 };
            let inv_r2 = inv_r * inv_r;
            let rdf = (rx * fx + ry * fy + rz * fz) * inv_r2;
            let o = c1 * inv_r;
            let f3 = c3 * (ai2 + a2) * inv_r * inv_r2;
            let cf = o + f3;
            let cr = (o - 3.0 * f3) * rdf;
            (
                cf * fx + cr * rx,
                cf * fy + cr * ry,
                cf * fz + cr * rz,
                overlap,
            )
        };
        for b in 0..blocks {
            let o = b * LANES;
            let x: &[f64; LANES] = s.x[o..o + LANES].try_into().unwrap_or(&[0.0; LANES]);
            let y: &[f64; LANES] = s.y[o..o + LANES].try_into().unwrap_or(&[0.0; LANES]);
            let z: &[f64; LANES] = s.z[o..o + LANES].try_into().unwrap_or(&[0.0; LANES]);
            let a: &[f64; LANES] = s.a[o..o + LANES].try_into().unwrap_or(&[0.0; LANES]);
            let a2: &[f64; LANES] = s.a2[o..o + LANES].try_into().unwrap_or(&[0.0; LANES]);
            let fx: &[f64; LANES] = s.fx[o..o + LANES].try_into().unwrap_or(&[0.0; LANES]);
            let fy: &[f64; LANES] = s.fy[o..o + LANES].try_into().unwrap_or(&[0.0; LANES]);
            let fz: &[f64; LANES] = s.fz[o..o + LANES].try_into().unwrap_or(&[0.0; LANES]);
            for l in 0..LANES {
                let (tx, ty, tz, ov) = term(x[l], y[l], z[l], a[l], a2[l], fx[l], fy[l], fz[l]);
                ax[l] += tx;
                ay[l] += ty;
                az[l] += tz;
                overlaps[l] += ov;
            }
        }
        for j in blocks * LANES..n {
            let (tx, ty, tz, ov) = term(
                s.x[j], s.y[j], s.z[j], s.a[j], s.a2[j], s.fx[j], s.fy[j], s.fz[j],
            );
            ax[0] += tx;
            ay[0] += ty;
            az[0] += tz;
            overlaps[0] += ov;
        }
        *out = [lane_sum(&ax), lane_sum(&ay), lane_sum(&az)];
        if lane_sum(&overlaps) > 1.0 {
            add_overlapping(s, k, i, out);
        }
    }
}

vector_dispatch! {
    /// [`rows_impl`] in the widest vector unit present.
    fn rows(s: &SoaSpheres, k: Kernel, first: usize, u: &mut [[f64; 3]]) = rows_impl;
}

/// u_i = Σ_{j≠i} H_ij F_j for every sphere by rows, rows in parallel (on rayon's pool) when
/// `parallel`.
pub fn row_velocities(m: Mobility, mu: f64, s: &SoaSpheres, u: &mut [[f64; 3]], parallel: bool) {
    let (c1, c3) = prefactors(m, mu);
    let k = Kernel { m, mu, c1, c3 };
    if parallel {
        u.par_chunks_mut(ROWS_PER_TASK)
            .enumerate()
            .for_each(|(c, chunk)| rows(s, k, c * ROWS_PER_TASK, chunk));
    } else {
        rows(s, k, 0, u);
    }
}
