//! The periodic box's mobility product by both Ewald methods against the number of spheres:
//! Beenakker's sums (O(N²)) and spectral Ewald (O(N log N)), side by side in one process, with the
//! open-space all-pairs kernel at the same positions for scale, the methods' difference against
//! the tolerance, and the crossover that "auto" uses.

use super::table::Table;
use crate::engine::build::Rng;
use crate::engine::ewald::{Ewald, EwaldMethod, SPECTRAL_FROM_SPHERES};
use crate::engine::mobility::Mobility;
use crate::engine::pairs::{interaction_velocities, SoaSpheres};
use crate::engine::periodic::PeriodicBox;
use nalgebra::Vector3;
use std::f64::consts::PI;
use std::time::Instant;

/// Viscosity (Pa s) and lattice spacing (m): one sphere per (8 µm)³, radii 0.5-1.5 µm, about the
/// sphere density of a microscopic suspension of dumbbells 15 µm apart.
const MU: f64 = 1e-3;
const SPACING: f64 = 8e-6;

/// One size's measurements.
#[derive(Debug, Clone)]
pub struct Row {
    /// Spheres in the box.
    pub spheres: usize,
    /// Seconds per product by Beenakker's sums (None above the size limit).
    pub beenakker: Option<f64>,
    /// Seconds per product by spectral Ewald.
    pub spectral: f64,
    /// Seconds per product of the open-space all-pairs kernel at the same positions.
    pub open: f64,
    /// The spectral grid per axis.
    pub grid: [usize; 3],
    /// Largest difference between the methods, relative to the Stokes velocity of the largest
    /// force on the smallest sphere (the tolerance's scale), over the tolerance.
    pub difference: Option<f64>,
}

/// Spheres in a box with a force on each.
struct Loaded {
    periodic: PeriodicBox,
    pos: Vec<Vector3<f64>>,
    radii: Vec<f64>,
    forces: Vec<Vector3<f64>>,
}

/// n³ spheres on a jittered cubic lattice filling a cube of side n·SPACING, random forces.
fn spheres(side: usize, rng: &mut Rng) -> Result<Loaded, String> {
    let l = side as f64 * SPACING;
    let mut pos = Vec::new();
    let mut radii = Vec::new();
    let mut forces = Vec::new();
    for k in 0..side * side * side {
        let ijk = [k % side, (k / side) % side, k / (side * side)];
        let mut x = Vector3::zeros();
        for a in 0..3 {
            x[a] = (ijk[a] as f64 + 0.5 + 0.5 * (rng.uniform() - 0.5)) * SPACING - l / 2.0;
        }
        pos.push(x);
        radii.push(0.5e-6 + 1e-6 * rng.uniform());
        forces.push(
            Vector3::new(rng.uniform(), rng.uniform(), rng.uniform()).add_scalar(-0.5) * 1e-12,
        );
    }
    Ok(Loaded {
        periodic: PeriodicBox::new([l; 3]).map_err(|e| e.to_string())?,
        pos,
        radii,
        forces,
    })
}

/// Median seconds of `repeats` calls of `f`.
fn median(repeats: usize, mut f: impl FnMut()) -> f64 {
    let mut t: Vec<f64> = (0..repeats.max(1))
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64()
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}

/// Every lattice side from 4 up to `max` spheres; Beenakker's sums up to `beenakker_max`.
pub fn run(max: usize, beenakker_max: usize, tol: f64) -> Result<Vec<Row>, String> {
    let mut rng = Rng::new(0x9e37_79b9_7f4a_7c15);
    let mut rows = Vec::new();
    for side in [4, 5, 6, 8, 10, 13, 16, 20, 25] {
        let n = side * side * side;
        if n > max {
            break;
        }
        let Loaded {
            periodic: b,
            pos,
            radii,
            forces,
        } = spheres(side, &mut rng)?;
        let repeats = if n <= 1000 { 5 } else { 3 };
        let make = |m| {
            Ewald::with_method(b, MU, Mobility::Rpy, n, tol, m, None).map_err(|e| e.to_string())
        };
        let spectral = make(EwaldMethod::Spectral)?;
        let mut us = vec![Vector3::zeros(); n];
        let ts = median(repeats, || {
            spectral.interaction_velocities(&pos, &radii, &forces, &mut us)
        });
        let (tb, difference) = if n <= beenakker_max {
            let e = make(EwaldMethod::Beenakker)?;
            let mut ub = vec![Vector3::zeros(); n];
            let t = median(repeats, || {
                e.interaction_velocities(&pos, &radii, &forces, &mut ub)
            });
            let fmax = forces.iter().map(|f| f.norm()).fold(0.0, f64::max);
            let scale = fmax / (6.0 * PI * MU * 0.5e-6);
            let diff = us
                .iter()
                .zip(&ub)
                .map(|(a, b)| (a - b).norm())
                .fold(0.0, f64::max);
            (Some(t), Some(diff / scale / tol))
        } else {
            (None, None)
        };
        let mut soa = SoaSpheres::default();
        soa.resize(n);
        for (k, ((p, a), f)) in pos.iter().zip(&radii).zip(&forces).enumerate() {
            (soa.x[k], soa.y[k], soa.z[k]) = (p[0], p[1], p[2]);
            (soa.fx[k], soa.fy[k], soa.fz[k]) = (f[0], f[1], f[2]);
            soa.set_radius(k, *a);
        }
        let mut uo = vec![[0.0; 3]; n];
        let to = median(repeats, || {
            interaction_velocities(Mobility::Rpy, MU, &soa, &mut uo, true)
        });
        rows.push(Row {
            spheres: n,
            beenakker: tb,
            spectral: ts,
            open: to,
            grid: spectral.spectral().map_or([0; 3], |s| s.grid()),
            difference,
        });
    }
    Ok(rows)
}

/// The table: spheres, seconds per product by each method and in open space, the ratios, the
/// spectral grid, the methods' difference over the tolerance.
pub fn table(rows: &[Row]) -> Table {
    let mut t = Table::new(&[
        "spheres",
        "beenakker_s",
        "spectral_s",
        "beenakker_over_spectral",
        "open_space_s",
        "spectral_over_open",
        "grid",
        "difference_over_tol",
    ]);
    for r in rows {
        let dash = || "-".to_string();
        t.rows.push(vec![
            r.spheres.to_string(),
            r.beenakker.map_or_else(dash, |b| format!("{b:.3e}")),
            format!("{:.3e}", r.spectral),
            r.beenakker
                .map_or_else(dash, |b| format!("{:.2}", b / r.spectral)),
            format!("{:.3e}", r.open),
            format!("{:.0}", r.spectral / r.open),
            format!("{}x{}x{}", r.grid[0], r.grid[1], r.grid[2]),
            r.difference.map_or_else(dash, |d| format!("{d:.3}")),
        ]);
    }
    t
}

/// The smallest size in the table from which the spectral method is faster at every larger size
/// measured with both.
pub fn crossover(rows: &[Row]) -> Option<usize> {
    let both: Vec<_> = rows
        .iter()
        .filter_map(|r| r.beenakker.map(|b| (r.spheres, b < r.spectral)))
        .collect();
    let last_slower = both
        .iter()
        .rposition(|&(_, beenakker_faster)| beenakker_faster);
    match last_slower {
        Some(k) => both.get(k + 1).map(|&(n, _)| n),
        None => both.first().map(|&(n, _)| n),
    }
}

/// What "auto" uses, for the report.
pub fn auto_threshold() -> usize {
    SPECTRAL_FROM_SPHERES
}
