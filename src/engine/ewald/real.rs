//! The real-space part of Beenakker's product over cell lists, for a splitting whose r_c is at
//! most half the shortest side: then only a pair's minimum image can lie within r_c, and the
//! spheres within r_c of one are among the 27 cells of side r_c around it (O(N) pairs for a
//! bounded density, instead of every pair and its lattice shifts). The self term and the
//! overlapping-sphere corrections (pairs closer than a_i + a_j, found in the same cells) join it.

use super::split::Split;
use crate::engine::cells::CellGrid;
use crate::engine::periodic::PeriodicBox;
use nalgebra::Vector3;
use rayon::prelude::*;

/// Whether the cell-list pass holds for cutoff `rc` in `periodic`: r_c ≤ L_min/2.
pub(super) fn fits(periodic: &PeriodicBox, rc: f64) -> bool {
    rc <= 0.5 * periodic.shortest()
}

/// Add the real-space, self and overlap terms, in units of 1/(6πμ), to `out`; r_c = `rc` with
/// [`fits`] true, and cells as wide as r_c or the widest overlap (whichever is longer, at most
/// L_min/2: a wider overlap than that is a box the scene refuses).
#[allow(clippy::too_many_arguments)]
pub(super) fn add_real(
    split: &Split,
    periodic: &PeriodicBox,
    rc: f64,
    pos: &[Vector3<f64>],
    radii: &[f64],
    forces: &[Vector3<f64>],
    out: &mut [Vector3<f64>],
    parallel: bool,
) {
    let widest = 2.0 * radii.iter().copied().fold(0.0, f64::max);
    let size = rc.max(widest).min(0.5 * periodic.shortest());
    let rc2 = rc * rc;
    let coord = |q: usize| pos.iter().map(|p| p[q]).collect::<Vec<f64>>();
    let (x, y, z) = (coord(0), coord(1), coord(2));
    let grid = CellGrid::build_in(&x, &y, &z, size, Some(periodic));
    let unit = 6.0 * std::f64::consts::PI * split.mu;
    let row = |i: usize, u: &mut Vector3<f64>, runs: &mut Vec<(u32, u32)>| {
        let (xi, ai) = (pos[i], radii[i]);
        let mut v = split.self_excess(ai) * forces[i];
        grid.neighbour_runs(xi[0], xi[1], xi[2], runs);
        for &(start, end) in runs.iter() {
            for &j in &grid.order[start as usize..end as usize] {
                let j = j as usize;
                if j == i {
                    continue;
                }
                let r0 = periodic.min_image(xi - pos[j]);
                let r2 = r0.norm_squared();
                let f = &forces[j];
                if r2 <= rc2 && r2 > 0.0 {
                    let (ci, crr) = split.real(r2.sqrt(), split.s(ai, radii[j]));
                    v += ci * f + r0 * (crr * r0.dot(f) / r2);
                }
                let touch = ai + radii[j];
                if r2 < touch * touch {
                    v += split.overlap_apply(&r0, ai, radii[j], f) * unit;
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
