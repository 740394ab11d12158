//! Gaps between spheres: the smallest gap of a set (placement's check) and the closest
//! overlapping pair (the overlap guard), through cell lists from [`CELL_LIST_SPHERES`] spheres on,
//! all pairs below.

use super::pairs::SoaSpheres;
use rayon::prelude::*;

/// The smallest gap |x_i − x_j| − a_i − a_j over all pairs and a pair that has it (rows in
/// parallel when `parallel`). `None` for fewer than two spheres.
pub fn min_gap(s: &SoaSpheres, radii: &[f64], parallel: bool) -> Option<(f64, usize, usize)> {
    if s.len() >= CELL_LIST_SPHERES {
        if let Some(found) = min_gap_by_cells(s, radii, parallel) {
            return Some(found);
        }
    }
    min_gap_all_pairs(s, radii, parallel)
}

/// [`min_gap`] through cell lists, when that is certain to be the answer: cells of twice the mean
/// spacing (at least twice the largest radius) hold every pair closer than their side; if the
/// smallest gap among them, g, has g + 2·a_max below the side, the closest pair overall (whose
/// distance is at most that) is among them. `None` when it is not certain (then all pairs).
fn min_gap_by_cells(s: &SoaSpheres, radii: &[f64], parallel: bool) -> Option<(f64, usize, usize)> {
    let n = s.len();
    let a_max = radii.iter().copied().fold(0.0, f64::max);
    let extent = |v: &[f64]| {
        let (lo, hi) = v[..n]
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &x| {
                (l.min(x), h.max(x))
            });
        (hi - lo).max(0.0)
    };
    let volume = match &s.periodic {
        Some(b) => b.volume(),
        None => extent(&s.x) * extent(&s.y) * extent(&s.z),
    };
    let side = (2.0 * (volume / n as f64).cbrt()).max(2.0 * a_max);
    let fits = s.periodic.is_none_or(|b| side <= 0.5 * b.shortest());
    if !(side > 0.0 && side.is_finite() && fits) {
        return None;
    }
    let found = closest_in_cells(s, radii, side, parallel, |_| true)?;
    (found.0 + 2.0 * a_max < side).then_some(found)
}

fn min_gap_all_pairs(s: &SoaSpheres, radii: &[f64], parallel: bool) -> Option<(f64, usize, usize)> {
    let n = s.len();
    let row = |i: usize| -> Option<(f64, usize, usize)> {
        let mut best: Option<(f64, usize, usize)> = None;
        for j in i + 1..n {
            let (rx, ry, rz) = s.delta(i, j);
            let gap = (rx * rx + ry * ry + rz * rz).sqrt() - radii[i] - radii[j];
            if best.is_none_or(|b| gap < b.0) {
                best = Some((gap, i, j));
            }
        }
        best
    };
    if parallel {
        (0..n).into_par_iter().map(row).reduce(|| None, earlier)
    } else {
        (0..n).map(row).fold(None, earlier)
    }
}

/// Of two pairs (gap, i, j), the one of smaller gap, then smaller i, then smaller j; a NaN gap
/// never wins over the pair already held.
fn earlier(
    a: Option<(f64, usize, usize)>,
    b: Option<(f64, usize, usize)>,
) -> Option<(f64, usize, usize)> {
    match (a, b) {
        (Some(x), Some(y)) => Some(if (y.0, y.1, y.2) < (x.0, x.1, x.2) {
            y
        } else {
            x
        }),
        (x, None) => x,
        (None, y) => y,
    }
}

/// From this many spheres the overlap guard finds its candidates through cell lists.
pub const CELL_LIST_SPHERES: usize = 1024;

/// The pair [`min_gap`] would name if its gap is ≤ 0 (the smallest gap, then the smallest i, then
/// the smallest j), or `None` when no spheres overlap. Overlapping spheres are closer than twice
/// the largest radius, so from [`CELL_LIST_SPHERES`] spheres on only pairs in neighbouring cells
/// of that size are measured: O(N) instead of O(N²), the same answer.
pub fn closest_overlap(
    s: &SoaSpheres,
    radii: &[f64],
    parallel: bool,
) -> Option<(f64, usize, usize)> {
    let n = s.len();
    let reach = 2.0 * radii.iter().copied().fold(0.0, f64::max);
    let fits = s.periodic.is_none_or(|b| reach <= 0.5 * b.shortest());
    if n < CELL_LIST_SPHERES || !(reach > 0.0 && reach.is_finite() && fits) {
        return min_gap_all_pairs(s, radii, parallel).filter(|g| g.0 <= 0.0);
    }
    closest_in_cells(s, radii, reach, parallel, |gap| gap <= 0.0)
}

/// The pair (i < j) of smallest gap, then smallest i, then smallest j, among the pairs in
/// neighbouring cells of side `side` whose gap `keep` accepts: every pair closer than `side` is
/// among them.
fn closest_in_cells(
    s: &SoaSpheres,
    radii: &[f64],
    side: f64,
    parallel: bool,
    keep: impl Fn(f64) -> bool + Sync,
) -> Option<(f64, usize, usize)> {
    let n = s.len();
    let grid = super::cells::CellGrid::build_in(
        &s.x[..n],
        &s.y[..n],
        &s.z[..n],
        side,
        s.periodic.as_ref(),
    );
    let row = |i: usize| -> Option<(f64, usize, usize)> {
        let mut runs = Vec::with_capacity(27);
        grid.neighbour_runs(s.x[i], s.y[i], s.z[i], &mut runs);
        let mut best: Option<(f64, usize, usize)> = None;
        for (a, b) in runs {
            for &j in &grid.order[a as usize..b as usize] {
                let j = j as usize;
                if j <= i {
                    continue;
                }
                let (rx, ry, rz) = s.delta(i, j);
                let gap = (rx * rx + ry * ry + rz * rz).sqrt() - radii[i] - radii[j];
                if keep(gap) {
                    best = earlier(best, Some((gap, i, j)));
                }
            }
        }
        best
    };
    if parallel {
        (0..n).into_par_iter().map(row).reduce(|| None, earlier)
    } else {
        (0..n).map(row).fold(None, earlier)
    }
}
