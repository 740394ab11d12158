//! The real-space part of Beenakker's product over cell lists, for a splitting whose r_c is at
//! most half the shortest side: then only a pair's minimum image can lie within r_c, and the
//! spheres within r_c of one are among the 27 cells of side r_c around it (O(N) pairs for a
//! bounded density, instead of every pair and its lattice shifts). Each row runs in vector lanes
//! over the spheres in cell order, with erfc and e^{−x²} from [`super::erfc`] (within a few ulp of
//! libm); the self term and the overlapping-sphere corrections (pairs closer than a_i + a_j, which
//! the lanes flag and a scalar pass then adds) join it.

use super::erfc::{ErfcTable, X_MAX};
use super::split::Split;
use crate::engine::cells::CellGrid;
use crate::engine::periodic::PeriodicBox;
use crate::engine::simd::{block, lane_sum, vector_dispatch, LANES};
use nalgebra::Vector3;
use rayon::prelude::*;

/// Whether the cell-list pass holds for cutoff `rc` in `periodic`: r_c ≤ L_min/2.
pub(super) fn fits(periodic: &PeriodicBox, rc: f64) -> bool {
    rc <= 0.5 * periodic.shortest()
}

/// The spheres in cell order, as the lanes read them (padded by a block at the end).
struct Sorted {
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    a: Vec<f64>,
    fx: Vec<f64>,
    fy: Vec<f64>,
    fz: Vec<f64>,
    /// The original index of each entry.
    id: Vec<usize>,
}

/// What one row reads besides the sorted spheres.
struct RowIn<'a> {
    split: &'a Split,
    table: &'a ErfcTable,
    l: [f64; 3],
    rc2: f64,
}

/// Row `i` (at `xi`, radius `ai`) over the entries `runs` of the cells around it: the real-space
/// sum in units of 1/(6πμ), and whether a partner overlaps it (closer than a_i + a_j).
#[inline(always)]
fn row_body(
    input: &RowIn,
    s: &Sorted,
    i: usize,
    xi: [f64; 3],
    ai: f64,
    runs: &[(u32, u32)],
) -> ([f64; 3], bool) {
    let split = input.split;
    let xi_ = split.xi;
    let inv_sqrt_pi = 1.0 / std::f64::consts::PI.sqrt();
    let finite = if split.finite_size { 0.5 } else { 0.0 };
    let l = input.l;
    let inv_l = l.map(|v| 1.0 / v);
    let mut acc = [[0.0; LANES]; 3];
    let mut touching = [false; LANES];
    for &(start, end) in runs {
        let (start, end) = (start as usize, end as usize);
        for b in (start..end).step_by(LANES) {
            // The block as arrays (the padding keeps b + LANES within them).
            let arr = |v: &[f64]| block(v, b);
            let (bx, by, bz, ba) = (arr(&s.x), arr(&s.y), arr(&s.z), arr(&s.a));
            let (bfx, bfy, bfz) = (arr(&s.fx), arr(&s.fy), arr(&s.fz));
            let ids: [usize; LANES] = s.id[b..b + LANES].try_into().unwrap_or([usize::MAX; LANES]);
            for k in 0..LANES {
                let j = ids[k];
                let mut r0 = [xi[0] - bx[k], xi[1] - by[k], xi[2] - bz[k]];
                for d in 0..3 {
                    r0[d] -= l[d] * (r0[d] * inv_l[d]).round();
                }
                let r2 = r0[0] * r0[0] + r0[1] * r0[1] + r0[2] * r0[2];
                let other = b + k < end && j != i;
                let touch = ai + ba[k];
                touching[k] |= other && r2 < touch * touch;
                let take = other && r2 <= input.rc2 && r2 > 0.0;
                let r2 = if take { r2 } else { 1.0 };
                let r = r2.sqrt();
                let inv_r = 1.0 / r;
                let inv_r2 = inv_r * inv_r;
                let (erfc, gauss) = input.table.eval(xi_ * r);
                let sv = finite * (ai * ai + ba[k] * ba[k]);
                let (ci, crr) = split.real_with(r, inv_r, sv, erfc, gauss * inv_sqrt_pi);
                let (fx, fy, fz) = (bfx[k], bfy[k], bfz[k]);
                let proj = crr * (r0[0] * fx + r0[1] * fy + r0[2] * fz) * inv_r2;
                let w = if take { 1.0 } else { 0.0 };
                acc[0][k] += w * (ci * fx + r0[0] * proj);
                acc[1][k] += w * (ci * fy + r0[1] * proj);
                acc[2][k] += w * (ci * fz + r0[2] * proj);
            }
        }
    }
    (acc.map(|a| lane_sum(&a)), touching.iter().any(|&t| t))
}

vector_dispatch! {
    /// [`row_body`] in the widest vector unit present.
    fn row_lanes(input: &RowIn, s: &Sorted, i: usize, xi: [f64; 3], ai: f64, runs: &[(u32, u32)]) -> ([f64; 3], bool) = row_body;
}

/// Add the real-space, self and overlap terms, in units of 1/(6πμ), to `out`; r_c = `rc` with
/// [`fits`] true, and cells as wide as r_c or the widest overlap (whichever is longer, at most
/// L_min/2: a wider overlap than that is a box the scene refuses).
#[allow(clippy::too_many_arguments)]
pub(super) fn add_real(
    split: &Split,
    periodic: &PeriodicBox,
    rc: f64,
    table: &ErfcTable,
    pos: &[Vector3<f64>],
    radii: &[f64],
    forces: &[Vector3<f64>],
    out: &mut [Vector3<f64>],
    parallel: bool,
) {
    // x = ξr ≤ ξr_c = p, the truncation (≤ 6.5 at the tightest tolerance), within the table.
    debug_assert!(split.xi * rc <= X_MAX);
    let widest = 2.0 * radii.iter().copied().fold(0.0, f64::max);
    let size = rc.max(widest).min(0.5 * periodic.shortest());
    let coord = |q: usize| pos.iter().map(|p| p[q]).collect::<Vec<f64>>();
    let (x, y, z) = (coord(0), coord(1), coord(2));
    let grid = CellGrid::build_in(&x, &y, &z, size, Some(periodic));
    // Padded by a block: a run's last block reads past its end (those lanes are masked).
    let sorted_of = |v: &dyn Fn(usize) -> f64| -> Vec<f64> {
        let mut out: Vec<f64> = grid.order.iter().map(|&j| v(j as usize)).collect();
        out.resize(out.len() + LANES, 0.0);
        out
    };
    let mut id: Vec<usize> = grid.order.iter().map(|&j| j as usize).collect();
    id.resize(id.len() + LANES, usize::MAX);
    let sorted = Sorted {
        x: sorted_of(&|j| pos[j][0]),
        y: sorted_of(&|j| pos[j][1]),
        z: sorted_of(&|j| pos[j][2]),
        a: sorted_of(&|j| radii[j]),
        fx: sorted_of(&|j| forces[j][0]),
        fy: sorted_of(&|j| forces[j][1]),
        fz: sorted_of(&|j| forces[j][2]),
        id,
    };
    let input = RowIn {
        split,
        table,
        l: periodic.sides(),
        rc2: rc * rc,
    };
    let unit = 6.0 * std::f64::consts::PI * split.mu;
    let row = |i: usize, u: &mut Vector3<f64>, runs: &mut Vec<(u32, u32)>| {
        let (xi, ai) = (pos[i], radii[i]);
        grid.neighbour_runs(xi[0], xi[1], xi[2], runs);
        let (v, touching) = row_lanes(&input, &sorted, i, [xi[0], xi[1], xi[2]], ai, runs);
        let mut v = Vector3::from(v) + split.self_excess(ai) * forces[i];
        if touching {
            for &(start, end) in runs.iter() {
                for &j in &grid.order[start as usize..end as usize] {
                    let j = j as usize;
                    if j != i {
                        let r0 = periodic.min_image(xi - pos[j]);
                        v += split.overlap_apply(&r0, ai, radii[j], &forces[j]) * unit;
                    }
                }
            }
        }
        *u += v;
    };
    if parallel {
        out.par_iter_mut()
            .enumerate()
            .for_each_init(Vec::new, |runs, (i, u)| row(i, u, runs));
    } else {
        let mut runs = Vec::new();
        for (i, u) in out.iter_mut().enumerate() {
            row(i, u, &mut runs);
        }
    }
}
