//! Close approaches between swimmers: whether spheres of different swimmers may overlap, and an
//! optional short-range steric repulsion that keeps them apart.
//!
//! By default a run stops when two spheres touch (the guard of [`super::spheres`]). With
//! `allow_overlap`, spheres of *different* swimmers may overlap: the RPY mobility switches to the
//! overlapping-sphere form of Zuk et al. (2014), which stays positive definite, so the dynamics
//! stay well posed. A dumbbell's own two spheres overlapping still stops the run (its spring has
//! collapsed). The steric repulsion is a soft harmonic wall between spheres of different
//! swimmers: F = k (δ − gap) r̂ for gap < δ, zero beyond, pushing the spheres apart; it is a
//! pair force (momentum is conserved) and costs an O(N²) pass per right-hand side, paid only
//! when it is on. The averaged model places its swimmers' spheres at length ℓ for both (see
//! [`super::averaged::AveragedSystem::set_contacts`]).

use super::choice::{self, Choice, Named};
use super::error::{invalid, Result};
use super::periodic::{separation, PeriodicBox};
use nalgebra::Vector3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Contact handling of a scene (saved with it).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Contacts {
    /// Let spheres of different swimmers overlap instead of stopping the run.
    pub allow_overlap: bool,
    /// Steric repulsion between spheres of different swimmers (microscopic and averaged models).
    pub steric: Option<Steric>,
}

impl Contacts {
    /// What touching spheres of different swimmers do.
    pub fn overlaps(&self) -> Overlaps {
        if self.allow_overlap {
            Overlaps::Allow
        } else {
            Overlaps::Stop
        }
    }
}

/// What happens when spheres of different swimmers touch (saved as [`Contacts::allow_overlap`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Overlaps {
    /// The run stops with an error naming the two spheres.
    #[default]
    Stop,
    /// They overlap, moved by the RPY tensor for overlapping spheres.
    Allow,
}

impl Named for Overlaps {
    const KIND: &'static str = "overlaps setting";
    const CHOICES: &'static [Choice<Self>] = &[
        Choice {
            value: Overlaps::Stop,
            name: "stop",
            about: "default: the run stops when spheres of different swimmers touch",
        },
        Choice {
            value: Overlaps::Allow,
            name: "allow",
            about: "they overlap, moved by the RPY tensor for overlapping spheres",
        },
    ];
}

choice::inherent_names!(Overlaps);

/// A harmonic repulsion F = k (δ − gap) r̂ for surface gaps below δ.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Steric {
    /// δ: the gap below which spheres repel (m).
    pub range: f64,
    /// k: force per unit of gap below δ (N/m).
    pub stiffness: f64,
}

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
        Ok(Steric { range, stiffness })
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
        let r = separation(periodic, pos[i] - pos[j]);
        // Compare squares first: the square root is taken for the few close pairs only.
        let reach = self.range + radii[i] + radii[j];
        let d2 = r.norm_squared();
        (d2 < reach * reach && d2 > 0.0).then(|| {
            let d = d2.sqrt();
            r * (self.stiffness * (reach - d) / d)
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
        if pos.len() >= super::pairs::CELL_LIST_SPHERES && fits {
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
        let grid = super::cells::CellGrid::build_in(
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
}
