//! The pair correlation g(r) of the swimmers' hydrodynamic centres in a periodic box, and its
//! orientational parts: g1(r) = ⟨N_i·N_j⟩ and g2(r) = ⟨P2(N_i·N_j)⟩ over the pairs at distance r.
//!
//! g is normalised by the ideal gas of the same number of centres in the same box: the N(N−1)/2
//! pairs of uniform, independent centres on the torus have minimum-image distances spread with
//! the density V_shell/V for r up to half the shortest side, so the expected count in the shell
//! [r_k, r_k+1) is N(N−1)/2 · V_shell/V and g = count / that. An ideal gas gives g = 1 exactly in
//! expectation (N − 1, not N: no self pair). Beyond half the shortest side the shells are cut by
//! the box and this normalisation no longer holds, so r_max is refused there. Open space has no
//! volume to normalise by, and is refused too (the raw counts are `pair_distances`).

use super::cells::CellGrid;
use super::error::{invalid, Result};
use super::periodic::PeriodicBox;
use super::scene::Scene;
use nalgebra::Vector3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Which part of the pair correlation an observable records.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum PairPart {
    /// g(r), the density part.
    Density,
    /// g1(r) = ⟨N_i·N_j⟩ over the pairs in the shell (polar order between neighbours).
    Polar,
    /// g2(r) = ⟨P2(N_i·N_j)⟩ = ⟨3(N_i·N_j)² − 1⟩/2 over the pairs in the shell (nematic order).
    Nematic,
}

impl PairPart {
    /// The column prefix: `g`, `g1`, `g2`.
    pub fn name(self) -> &'static str {
        match self {
            PairPart::Density => "g",
            PairPart::Polar => "g1",
            PairPart::Nematic => "g2",
        }
    }
}

/// g(r) and its orientational parts in `bins` shells of equal width from 0 to r_max.
#[derive(Debug, Clone, PartialEq)]
pub struct PairCorrelation {
    /// Shell centres (m).
    pub r: Vec<f64>,
    /// g(r): pairs in the shell over the ideal gas's expected count.
    pub g: Vec<f64>,
    /// The ideal-gas (Poisson) standard error of g from this one configuration, √count / ideal.
    pub g_err: Vec<f64>,
    /// g1(r) = ⟨N_i·N_j⟩ over the pairs in the shell (0 where the shell has none).
    pub polar: Vec<f64>,
    /// g2(r) = ⟨P2(N_i·N_j)⟩ over the pairs in the shell (0 where the shell has none).
    pub nematic: Vec<f64>,
    /// Pairs counted in each shell.
    pub pairs: Vec<f64>,
    /// The ideal gas's expected count in each shell, N(N−1)/2 · V_shell/V.
    pub ideal: Vec<f64>,
}

impl PairCorrelation {
    /// The values of one part, shell by shell.
    pub fn part(&self, part: PairPart) -> &[f64] {
        match part {
            PairPart::Density => &self.g,
            PairPart::Polar => &self.polar,
            PairPart::Nematic => &self.nematic,
        }
    }
}

/// From how many centres the pairs are found through cell lists of side r_max (when the box is
/// at least 4 r_max across, so that the 27 cells around a centre leave most pairs out).
const CELLS_FROM: usize = 512;

/// Rows per chunk: each chunk sums its rows into one histogram, and the chunks are added in
/// order, so the sums are the same on any number of threads.
const CHUNK: usize = 64;

/// Per shell: the pairs, Σ N_i·N_j and Σ P2(N_i·N_j), over all pairs (`cells` false) or through
/// cell lists of side r_max (the same pairs: every pair within r_max ≤ L/2 is among the 27 cells
/// around either centre; the orientation sums differ by the rounding of their order).
fn shell_sums(
    centres: &[Vector3<f64>],
    dirs: &[Vector3<f64>],
    b: &PeriodicBox,
    bins: usize,
    r_max: f64,
    cells: bool,
) -> Vec<[f64; 3]> {
    let n = centres.len();
    let width = r_max / bins as f64;
    let grid = cells.then(|| {
        let axis = |d: usize| centres.iter().map(|c| c[d]).collect::<Vec<f64>>();
        CellGrid::build_in(&axis(0), &axis(1), &axis(2), r_max, Some(b))
    });
    let pair = |i: usize, j: usize, h: &mut [[f64; 3]]| {
        let k = (b.min_image(centres[i] - centres[j]).norm() / width) as usize;
        if k < bins {
            let c = dirs[i].dot(&dirs[j]);
            h[k][0] += 1.0;
            h[k][1] += c;
            h[k][2] += 1.5 * c * c - 0.5;
        }
    };
    let chunk = |first: usize| {
        let mut h = vec![[0.0; 3]; bins];
        let mut runs = Vec::new();
        for i in first..(first + CHUNK).min(n) {
            match &grid {
                None => (i + 1..n).for_each(|j| pair(i, j, &mut h)),
                Some(g) => {
                    let c = centres[i];
                    g.neighbour_runs(c.x, c.y, c.z, &mut runs);
                    for &(start, end) in &runs {
                        for &j in &g.order[start as usize..end as usize] {
                            // Each pair once, from its lower index.
                            if j as usize > i {
                                pair(i, j as usize, &mut h);
                            }
                        }
                    }
                }
            }
        }
        h
    };
    let add = |mut a: Vec<[f64; 3]>, b: Vec<[f64; 3]>| {
        for (x, y) in a.iter_mut().zip(b) {
            for c in 0..3 {
                x[c] += y[c];
            }
        }
        a
    };
    let firsts = (0..n).step_by(CHUNK);
    let parts: Vec<Vec<[f64; 3]>> = if n >= 256 {
        firsts
            .collect::<Vec<_>>()
            .into_par_iter()
            .map(chunk)
            .collect()
    } else {
        firsts.map(chunk).collect()
    };
    parts.into_iter().fold(vec![[0.0; 3]; bins], add)
}

/// Check the shells against the box: 1 to `max_bins` bins, 0 < r_max ≤ half the shortest side.
pub fn check_shells(b: &PeriodicBox, bins: usize, r_max: f64, max_bins: usize) -> Result<()> {
    if bins == 0 || bins > max_bins || !(r_max.is_finite() && r_max > 0.0) {
        return Err(invalid!(
            "the pair correlation needs 1 to {max_bins} bins and a positive r_max in m, got {bins} and {r_max}; e.g. pair_correlation(50, 50e-6)"
        ));
    }
    let half = 0.5 * b.shortest();
    if r_max > half {
        return Err(invalid!(
            "the pair correlation reaches r_max = {r_max:e} m, beyond half the box's shortest side ({half:e} m), where the minimum-image shells are cut by the box and the ideal gas no longer normalises them; use r_max up to {half:e} m"
        ));
    }
    Ok(())
}

/// g(r), g1(r), g2(r) of `centres` with unit orientations `dirs` in box `b`, by minimum images
/// over all pairs (rows in parallel for large sets).
pub fn pair_correlation(
    centres: &[Vector3<f64>],
    dirs: &[Vector3<f64>],
    b: &PeriodicBox,
    bins: usize,
    r_max: f64,
) -> Result<PairCorrelation> {
    check_shells(b, bins, r_max, usize::MAX)?;
    let n = centres.len();
    if n < 2 || dirs.len() != n {
        return Err(invalid!(
            "the pair correlation needs at least two swimmers (one orientation each), got {n} centres and {} orientations; add swimmers first",
            dirs.len()
        ));
    }
    let width = r_max / bins as f64;
    let cells = n >= CELLS_FROM && b.shortest() >= 4.0 * r_max;
    let sums = shell_sums(centres, dirs, b, bins, r_max, cells);
    let pair_density = n as f64 * (n as f64 - 1.0) / (2.0 * b.volume());
    let first = pair_density * 4.0 / 3.0 * PI * width.powi(3);
    if !first.is_normal() {
        return Err(invalid!(
            "shells of width {width:e} m are too thin for f64 to hold the ideal gas's count in them ({first:e} pairs in the first); use fewer bins or a larger r_max"
        ));
    }
    let mut out = PairCorrelation {
        r: Vec::with_capacity(bins),
        g: Vec::with_capacity(bins),
        g_err: Vec::with_capacity(bins),
        polar: Vec::with_capacity(bins),
        nematic: Vec::with_capacity(bins),
        pairs: Vec::with_capacity(bins),
        ideal: Vec::with_capacity(bins),
    };
    for (k, [count, polar, nematic]) in sums.into_iter().enumerate() {
        let (lo, hi) = (k as f64 * width, (k + 1) as f64 * width);
        let ideal = pair_density * 4.0 / 3.0 * PI * (hi.powi(3) - lo.powi(3));
        let mean = |s: f64| if count > 0.0 { s / count } else { 0.0 };
        out.r.push(0.5 * (lo + hi));
        out.g.push(count / ideal);
        out.g_err.push(count.sqrt() / ideal);
        out.polar.push(mean(polar));
        out.nematic.push(mean(nematic));
        out.pairs.push(count);
        out.ideal.push(ideal);
    }
    Ok(out)
}

/// The pair correlation of the scene's hydrodynamic centres and orientations; refused outside a
/// periodic box (open space and the wall's half space have no volume to normalise by).
pub fn of_scene(scene: &Scene, bins: usize, r_max: f64) -> Result<PairCorrelation> {
    let Some(b) = scene.periodic() else {
        return Err(invalid!(
            "the pair correlation g(r) is normalised by the ideal gas of the box's number density, and this scene has no periodic box (open space or a wall has no volume to normalise by); put the scene in a box of sides [Lx, Ly, Lz] first, or use pair_distances(bins, r_max) for the raw counts of pair distances"
        ));
    };
    let n = scene.count();
    let centres: Vec<Vector3<f64>> = (0..n).map(|i| scene.center(i)).collect::<Result<_>>()?;
    let dirs: Vec<Vector3<f64>> = (0..n).map(|i| scene.dir(i)).collect::<Result<_>>()?;
    pair_correlation(&centres, &dirs, b, bins, r_max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::build::Rng;

    /// An ideal gas: 2,000 uniform, independent centres in a cube, 20 shells up to half its side.
    /// On the torus the pair indicators are pairwise independent (given one centre, the others'
    /// images are uniform), so a shell's count has variance M p (1 − p) ≤ its mean: the reported
    /// √count / ideal is one standard error or a little more. Every shell within 4 of them (each
    /// fails with probability 6e-5, the 20 together 1.3e-3), and the mean of the 20 within 4 of its
    /// own error, √(Σ err²)/20 (6e-5). g1 and g2 of independent random orientations have mean 0
    /// and per-pair standard deviations 1/√3 and 1/√5: each shell within 4 of them over √count.
    #[test]
    fn an_ideal_gas_gives_one() {
        let l = 100e-6;
        let b = PeriodicBox::new([l; 3]).unwrap();
        let mut rng = Rng::new(7);
        let n = 2000;
        let centres: Vec<Vector3<f64>> = (0..n)
            .map(|_| Vector3::new(rng.uniform(), rng.uniform(), rng.uniform()) * l)
            .collect();
        let dirs: Vec<Vector3<f64>> = (0..n).map(|_| rng.unit_vector()).collect();
        let bins = 20;
        let pc = pair_correlation(&centres, &dirs, &b, bins, 0.5 * l).unwrap();
        for k in 0..bins {
            let (g, e, m) = (pc.g[k], pc.g_err[k], pc.pairs[k]);
            assert!((g - 1.0).abs() < 4.0 * e, "shell {k}: g {g} ± {e}");
            assert!(
                pc.polar[k].abs() < 4.0 / (3.0 * m).sqrt(),
                "g1[{k}] {}",
                pc.polar[k]
            );
            assert!(
                pc.nematic[k].abs() < 4.0 / (5.0 * m).sqrt(),
                "g2[{k}] {}",
                pc.nematic[k]
            );
        }
        let mean = pc.g.iter().sum::<f64>() / bins as f64;
        let err = pc.g_err.iter().map(|e| e * e).sum::<f64>().sqrt() / bins as f64;
        assert!((mean - 1.0).abs() < 4.0 * err, "mean g {mean} ± {err}");
    }

    /// A simple cubic lattice of spacing a, 6³ sites filling the box: every site has 6, 12, 8, 6,
    /// 24, 24, 12 neighbours at a√1, √2, √3, √4, √5, √6, √8 (none at √7; all within 2.9a, below
    /// half the side, 3a). 45 shells of width 2.9a/45 put each distance at least 0.01 of a shell
    /// from an edge (far beyond rounding), so the counts are exact: N z / 2 pairs there, none
    /// between, and g there is N z / (2 ideal). Aligned orientations give g1 = g2 = 1 wherever
    /// there are pairs. Exact counts make every check exact (to rounding).
    #[test]
    fn a_lattice_has_its_shells() {
        let (a, m) = (10e-6, 6);
        let b = PeriodicBox::new([a * m as f64; 3]).unwrap();
        let mut centres = Vec::new();
        for x in 0..m {
            for y in 0..m {
                for z in 0..m {
                    centres.push(Vector3::new(x as f64, y as f64, z as f64) * a);
                }
            }
        }
        let n = centres.len() as f64;
        let dirs = vec![Vector3::z(); centres.len()];
        let (bins, r_max) = (45, 2.9 * a);
        let pc = pair_correlation(&centres, &dirs, &b, bins, r_max).unwrap();
        let shells = [
            (1.0, 6.0),
            (2.0, 12.0),
            (3.0, 8.0),
            (4.0, 6.0),
            (5.0, 24.0),
            (6.0, 24.0),
            (8.0, 12.0),
        ];
        let width = r_max / bins as f64;
        for k in 0..bins {
            let shell = shells
                .iter()
                .find(|(d2, _)| (f64::sqrt(*d2) * a / width) as usize == k);
            match shell {
                Some((_, z)) => {
                    assert_eq!(pc.pairs[k], n * z / 2.0, "shell {k}");
                    let want = n * z / 2.0 / pc.ideal[k];
                    assert!((pc.g[k] / want - 1.0).abs() < 1e-12, "g[{k}] {}", pc.g[k]);
                    assert!((pc.polar[k] - 1.0).abs() < 1e-12);
                    assert!((pc.nematic[k] - 1.0).abs() < 1e-12);
                }
                None => {
                    assert_eq!(pc.g[k], 0.0, "shell {k} between the lattice shells");
                    assert_eq!(pc.polar[k], 0.0);
                }
            }
        }
    }

    /// Through cell lists the same pairs are counted (exactly) and their orientation sums agree
    /// to rounding: 3,000 uniform centres, shells to a fifth of the side (5 cells per axis).
    #[test]
    fn cell_lists_count_the_same_pairs_as_all_pairs() {
        let l = 100e-6;
        let b = PeriodicBox::new([l; 3]).unwrap();
        let mut rng = Rng::new(11);
        let n = 3000;
        let centres: Vec<Vector3<f64>> = (0..n)
            .map(|_| Vector3::new(rng.uniform(), rng.uniform(), rng.uniform()) * l)
            .collect();
        let dirs: Vec<Vector3<f64>> = (0..n).map(|_| rng.unit_vector()).collect();
        let all = shell_sums(&centres, &dirs, &b, 16, 0.2 * l, false);
        let cells = shell_sums(&centres, &dirs, &b, 16, 0.2 * l, true);
        for (a, c) in all.iter().zip(&cells) {
            assert_eq!(a[0], c[0]);
            assert!((a[1] - c[1]).abs() < 1e-12 * a[0].max(1.0), "{a:?} {c:?}");
            assert!((a[2] - c[2]).abs() < 1e-12 * a[0].max(1.0), "{a:?} {c:?}");
        }
        assert!(all.iter().map(|a| a[0]).sum::<f64>() > 1e5);
    }

    #[test]
    fn shells_beyond_half_the_box_and_too_few_centres_are_refused() {
        let b = PeriodicBox::new([10e-6, 20e-6, 20e-6]).unwrap();
        let c = [Vector3::zeros(), Vector3::x() * 1e-6];
        let d = [Vector3::z(); 2];
        let e = pair_correlation(&c, &d, &b, 10, 6e-6)
            .unwrap_err()
            .to_string();
        assert!(e.contains("use r_max up to 5e-6 m"), "{e}");
        let e = pair_correlation(&c[..1], &d[..1], &b, 10, 4e-6)
            .unwrap_err()
            .to_string();
        assert!(e.contains("at least two swimmers"), "{e}");
        let e = pair_correlation(&c, &d, &b, 0, 4e-6)
            .unwrap_err()
            .to_string();
        assert!(e.contains("1 to"), "{e}");
    }
}
