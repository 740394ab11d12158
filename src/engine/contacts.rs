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

    /// Adds the repulsion on every sphere to `forces`. Sphere α belongs to swimmer α/2; spheres of
    /// one swimmer do not repel. Each row sums its own partners in index order (no scatter), so
    /// rows run in parallel when `parallel` with results independent of the thread count.
    pub(crate) fn add_forces(
        &self,
        pos: &[Vector3<f64>],
        radii: &[f64],
        forces: &mut [Vector3<f64>],
        parallel: bool,
    ) {
        let row = |i: usize, f: &mut Vector3<f64>| {
            for (j, (pj, aj)) in pos.iter().zip(radii).enumerate() {
                if j / 2 == i / 2 {
                    continue;
                }
                let r = pos[i] - pj;
                // Compare squares first: the square root is taken for the few close pairs only.
                let reach = self.range + radii[i] + aj;
                let d2 = r.norm_squared();
                if d2 < reach * reach && d2 > 0.0 {
                    let d = d2.sqrt();
                    *f += r * (self.stiffness * (reach - d) / d);
                }
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
