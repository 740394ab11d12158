//! The steric repulsion: its force law, the bodies it keeps apart, and the forces between the
//! spheres of different swimmers (through cell lists for large scenes).

use crate::engine::choice::{self, Choice, Named};
use crate::engine::error::{invalid, Result};
use crate::engine::periodic::{separation, PeriodicBox};
use nalgebra::Vector3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// A harmonic repulsion F = k (δ − gap) r̂ for surface gaps below δ.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Steric {
    /// δ: the gap below which spheres repel (m).
    pub range: f64,
    /// k: force per unit of gap below δ (N/m).
    pub stiffness: f64,
    /// What repels: the spheres alone, or each swimmer's whole body (saved; spheres for older files).
    #[serde(default)]
    pub body: StericBody,
    /// How the force grows inside the range (saved only when not harmonic).
    #[serde(default, skip_serializing_if = "StericLaw::is_harmonic")]
    pub law: StericLaw,
}

/// How a steric force grows with the overlap x = δ − gap of the range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum StericLaw {
    /// F = k x: a spring from the edge of the range (default); its stiffness starts at once.
    #[default]
    Harmonic,
    /// F = k x²/δ: the same force at contact (x = δ), growing from zero force and zero stiffness
    /// at the edge of the range, so the rates have no kink where a contact starts. A contact held
    /// near the edge by the far field then costs an adaptive step no more than the far field
    /// does, where the harmonic law's kink holds it to a fraction of a period.
    Smooth,
}

impl StericLaw {
    pub(crate) fn is_harmonic(&self) -> bool {
        *self == StericLaw::Harmonic
    }

    /// The force over the stiffness at overlap `x` of range `range` (m).
    #[inline]
    pub(crate) fn force(self, x: f64, range: f64) -> f64 {
        match self {
            StericLaw::Harmonic => x,
            // Past contact (x > δ, overlapping bodies) the parabola's tangent carries on.
            StericLaw::Smooth if x <= range => x * x / range,
            StericLaw::Smooth => 2.0 * x - range,
        }
    }
}

impl Named for StericLaw {
    const KIND: &'static str = "steric law";
    const CHOICES: &'static [Choice<Self>] = &[
        Choice {
            value: StericLaw::Harmonic,
            name: "harmonic",
            about: "default: force stiffness * (range - gap)",
        },
        Choice {
            value: StericLaw::Smooth,
            name: "smooth",
            about: "force stiffness * (range - gap)^2 / range: the same at contact, no kink at the range's edge",
        },
    ];
}

choice::inherent_names!(StericLaw);

/// The bodies a steric repulsion keeps apart.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum StericBody {
    /// Spheres of different swimmers (default).
    #[default]
    Spheres,
    /// Each swimmer as a rod: the segment joining its sphere centres, thickened by the radii
    /// interpolated along it (its spheres at the ends). Swimmers cannot pass through each other.
    Rods,
}

impl Named for StericBody {
    const KIND: &'static str = "steric body";
    const CHOICES: &'static [Choice<Self>] = &[
        Choice {
            value: StericBody::Spheres,
            name: "spheres",
            about: "default: spheres of different swimmers repel",
        },
        Choice {
            value: StericBody::Rods,
            name: "rods",
            about: "each swimmer is a rod from sphere to sphere: swimmers cannot cross",
        },
    ];
}

choice::inherent_names!(StericBody);

impl Steric {
    /// A repulsion of range δ (m) and stiffness k (N/m), both positive and finite.
    pub fn new(range: f64, stiffness: f64) -> Result<Self> {
        for (name, v, unit) in [("range", range, "m"), ("stiffness", stiffness, "N/m")] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid!(
                    "steric {name} must be a positive number of {unit}, got {v}; e.g. range 1e-7 m and stiffness 1e-3 N/m"
                ));
            }
        }
        Ok(Steric {
            range,
            stiffness,
            body: StericBody::Spheres,
            law: StericLaw::Harmonic,
        })
    }

    /// The same repulsion between other bodies.
    pub fn with_body(self, body: StericBody) -> Self {
        Steric { body, ..self }
    }

    /// The same repulsion with force law `law`.
    pub fn with_law(self, law: StericLaw) -> Self {
        Steric { law, ..self }
    }

    /// The repulsion on sphere `i` from sphere `j`, if they are within reach.
    #[inline]
    fn pair_force(
        &self,
        pos: &[Vector3<f64>],
        radii: &[f64],
        periodic: Option<&PeriodicBox>,
        i: usize,
        j: usize,
    ) -> Option<Vector3<f64>> {
        self.sphere_force(separation(periodic, pos[i] - pos[j]), radii[i], radii[j])
    }

    /// The repulsion on a sphere of radius `ai` from one of radius `aj` at separation `r` (its
    /// centre minus the other's), if they are within reach.
    #[inline]
    pub(crate) fn sphere_force(&self, r: Vector3<f64>, ai: f64, aj: f64) -> Option<Vector3<f64>> {
        self.sphere_force_within(r, ai, aj, 0.0)
    }

    /// [`Steric::sphere_force`] with the law k (δ − gap) r̂ carried on, attractive, to gaps of
    /// δ + `extra` (the linearly implicit methods' Jacobian of contacts about to form).
    #[inline]
    pub(super) fn sphere_force_within(
        &self,
        r: Vector3<f64>,
        ai: f64,
        aj: f64,
        extra: f64,
    ) -> Option<Vector3<f64>> {
        // Compare squares first: the square root is taken for the few close pairs only.
        let reach = self.range + ai + aj;
        let limit = reach + extra;
        let d2 = r.norm_squared();
        (d2 < limit * limit && d2 > 0.0).then(|| {
            let d = d2.sqrt();
            r * (self.stiffness * self.law.force(reach - d, self.range) / d)
        })
    }

    /// Adds the repulsion on every sphere to `forces`. Sphere α belongs to swimmer α/2; spheres of
    /// one swimmer do not repel. Each row sums its own partners in index order (no scatter), so
    /// rows run in parallel when `parallel` with results independent of the thread count. In a
    /// periodic box pairs are measured by their minimum image.
    pub(crate) fn add_forces(
        &self,
        pos: &[Vector3<f64>],
        radii: &[f64],
        periodic: Option<&PeriodicBox>,
        forces: &mut [Vector3<f64>],
        parallel: bool,
    ) {
        if self.body == StericBody::Rods {
            return self.add_rod_forces(pos, radii, periodic, forces, parallel);
        }
        let row = |i: usize, f: &mut Vector3<f64>| {
            for j in 0..pos.len() {
                if j / 2 != i / 2 {
                    if let Some(df) = self.pair_force(pos, radii, periodic, i, j) {
                        *f += df;
                    }
                }
            }
        };
        let reach_max = self.range + 2.0 * radii.iter().copied().fold(0.0, f64::max);
        let fits = periodic.is_none_or(|b| reach_max <= 0.5 * b.shortest());
        if pos.len() >= crate::engine::gaps::CELL_LIST_SPHERES && fits {
            return self.add_forces_by_cells(pos, radii, periodic, forces, parallel);
        }
        if parallel {
            forces
                .par_iter_mut()
                .enumerate()
                .for_each(|(i, f)| row(i, f));
        } else {
            forces.iter_mut().enumerate().for_each(|(i, f)| row(i, f));
        }
    }

    /// [`Steric::add_forces`] for large scenes: the partners within reach come from the cells (of
    /// side range + 2·largest radius) around each sphere, and are added in index order, so the
    /// forces are bitwise the all-pairs loop's (the pairs out of reach add nothing there).
    fn add_forces_by_cells(
        &self,
        pos: &[Vector3<f64>],
        radii: &[f64],
        periodic: Option<&PeriodicBox>,
        forces: &mut [Vector3<f64>],
        parallel: bool,
    ) {
        let reach_max = self.range + 2.0 * radii.iter().copied().fold(0.0, f64::max);
        let coords = |k: usize| -> Vec<f64> { pos.iter().map(|p| p[k]).collect() };
        let grid = crate::engine::cells::CellGrid::build_in(
            &coords(0),
            &coords(1),
            &coords(2),
            reach_max,
            periodic,
        );
        let row = |i: usize, f: &mut Vector3<f64>| {
            let mut runs = Vec::with_capacity(27);
            grid.neighbour_runs(pos[i].x, pos[i].y, pos[i].z, &mut runs);
            let mut close: Vec<(usize, Vector3<f64>)> = Vec::new();
            for (a, b) in runs {
                for &j in &grid.order[a as usize..b as usize] {
                    let j = j as usize;
                    if j / 2 != i / 2 {
                        if let Some(df) = self.pair_force(pos, radii, periodic, i, j) {
                            close.push((j, df));
                        }
                    }
                }
            }
            close.sort_unstable_by_key(|c| c.0);
            for (_, df) in close {
                *f += df;
            }
        };
        if parallel {
            forces
                .par_iter_mut()
                .enumerate()
                .for_each(|(i, f)| row(i, f));
        } else {
            forces.iter_mut().enumerate().for_each(|(i, f)| row(i, f));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cell-list path gives bitwise the all-pairs loop's forces: 1,200 spheres (above the
    /// threshold) at random in a box where a few hundred pairs are within reach.
    #[test]
    fn steric_forces_by_cells_are_the_all_pairs_forces() {
        let n = 1200;
        let mut state = 0x9e3779b97f4a7c15u64;
        let mut uniform = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let side = 60e-6;
        let pos: Vec<Vector3<f64>> = (0..n)
            .map(|_| Vector3::new(uniform(), uniform(), uniform()) * side)
            .collect();
        let radii: Vec<f64> = (0..n)
            .map(|i| if i % 2 == 0 { 1e-6 } else { 0.5e-6 })
            .collect();
        let st = Steric::new(1e-6, 1e-3).unwrap();
        let mut by_cells = vec![Vector3::zeros(); n];
        st.add_forces(&pos, &radii, None, &mut by_cells, true);
        let mut all = vec![Vector3::zeros(); n];
        // The all-pairs loop, as add_forces runs it below the threshold.
        for i in 0..n {
            for j in 0..n {
                if j / 2 == i / 2 {
                    continue;
                }
                let r = pos[i] - pos[j];
                let reach = st.range + radii[i] + radii[j];
                let d2 = r.norm_squared();
                if d2 < reach * reach && d2 > 0.0 {
                    let d = d2.sqrt();
                    all[i] += r * (st.stiffness * (reach - d) / d);
                }
            }
        }
        let pushed = all.iter().filter(|f| f.norm() > 0.0).count();
        assert!(pushed > 50, "only {pushed} spheres within reach");
        assert_eq!(by_cells, all);
    }

    /// The smooth law: the harmonic law's force at contact, none from the range on, and a slope
    /// that starts from zero at the range (the harmonic law's jumps there from 0 to k); past
    /// contact the tangent carries on. Tolerances: rounding of forces of size kδ (1e-12), and
    /// the finite-difference slope's own error, h/δ = 1e-6.
    #[test]
    fn the_smooth_law_starts_without_a_kink() {
        let (range, k, a) = (0.5e-6, 1e-4, 1e-6);
        let harmonic = Steric::new(range, k).unwrap();
        let smooth = harmonic.with_law(StericLaw::Smooth);
        let at = |st: &Steric, gap: f64| {
            st.sphere_force(Vector3::new(2.0 * a + gap, 0.0, 0.0), a, a)
                .map_or(0.0, |f| f.x)
        };
        assert!((at(&smooth, 0.0) - at(&harmonic, 0.0)).abs() <= 1e-12 * k * range);
        assert!((at(&smooth, 0.0) - k * range).abs() <= 1e-12 * k * range);
        assert_eq!(at(&smooth, range), 0.0);
        assert_eq!(at(&smooth, 2.0 * range), 0.0);
        let h = 1e-6 * range;
        let slope = |st: &Steric| (at(st, range - 2.0 * h) - at(st, range - h)) / h;
        assert!(slope(&smooth).abs() < 1e-5 * k, "{:e}", slope(&smooth));
        assert!(
            (slope(&harmonic) - k).abs() < 1e-6 * k,
            "{:e}",
            slope(&harmonic)
        );
        // Past contact: F = k(2x − δ) at overlap x, slope 2k.
        let x = 0.2 * range;
        assert!(
            (at(&smooth, -0.2 * range) - k * (2.0 * (range + x) - range)).abs()
                <= 1e-12 * k * range
        );
    }
}
