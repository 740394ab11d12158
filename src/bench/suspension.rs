//! Bulk suspensions of the averaged model (`swimlab bench suspension`): one right-hand side of a
//! dilute boxed suspension with a cutoff against one all-pairs right-hand side of a dense
//! lattice, side by side in alternating rounds; random placement; the cost of runs per
//! swimmer-period against the number of swimmers.
//!
//! The suspension is the bulk demo's: symmetric Fig-1 swimmers (a = 0.15ℓ) at sphere volume
//! fraction φ in a cubic box, placed at random with at least ℓ between sphere surfaces, random
//! orientations and phases, cutoff 6ℓ, steric repulsion 0.5 µm at 1e-5 N/m.

use crate::engine::build::{
    box_side, lattice_scene_of, random_suspension_apart, Orientations, Phases,
};
use crate::engine::error::Result;
use crate::engine::integrators::OdeSystem;
use crate::engine::{Dumbbell, Model, Scene, Steric};
use std::time::Instant;

/// The cutoff of the bulk suspension, in ℓ.
pub const CUTOFF_ELLS: f64 = 6.0;
/// The steric repulsion of the bulk suspension: range (m) and stiffness (N/m).
pub const STERIC: (f64, f64) = (0.5e-6, 1e-5);

/// The bulk suspension of `n` swimmers `d` at sphere volume fraction `phi`, seeded by `seed`.
pub fn bulk_scene(n: usize, d: Dumbbell, phi: f64, seed: u64) -> Result<Scene> {
    let mut s = Scene::new();
    s.set_model(Model::Averaged);
    let side = box_side(n, &d, phi)?;
    s.set_box(Some([side; 3]))?;
    random_suspension_apart(
        &mut s,
        n,
        d,
        [side; 3],
        Orientations::Random,
        Phases::Random,
        seed,
        Some(d.ell),
    )?;
    s.set_cutoff(Some(CUTOFF_ELLS * d.ell))?;
    s.set_steric(Some(Steric::new(STERIC.0, STERIC.1)?));
    Ok(s)
}

/// The dense reference: a cubic lattice of `n` swimmers `d` 3ℓ apart, orientations turned out of
/// line (so the 3D rows run), every pair interacting.
pub fn dense_scene(n: usize, d: Dumbbell) -> Result<Scene> {
    let lattice = lattice_scene_of(n, Model::Averaged, d)?;
    let mut s = Scene::new();
    s.set_model(Model::Averaged);
    for (i, d) in lattice.swimmers().iter().enumerate() {
        let a = i as f64 * 0.37;
        let (y, base) = lattice.raw_state();
        let c = base[i] + nalgebra::Vector3::new(y[6 * i], y[6 * i + 1], y[6 * i + 2]);
        s.add(*d, c, nalgebra::Vector3::new(a.cos(), a.sin(), 0.3))?;
    }
    Ok(s)
}

/// Seconds per right-hand side of `s` (its system built once, the list built before timing),
/// over `reps` evaluations.
pub fn rhs_seconds(sys: &mut dyn OdeSystem, y: &[f64], reps: usize) -> f64 {
    let mut dy = vec![0.0; y.len()];
    let start = Instant::now();
    for _ in 0..reps {
        sys.rhs(0.0, y, &mut dy);
    }
    start.elapsed().as_secs_f64() / reps as f64
}

/// One round of the side-by-side figure: seconds per right-hand side of the suspension and of
/// the dense lattice.
#[derive(Debug, Clone, Copy)]
pub struct RhsRound {
    /// The suspension's right-hand side (s).
    pub suspension: f64,
    /// The dense lattice's (s).
    pub dense: f64,
}

/// `rounds` alternating rounds of `reps` right-hand sides of `suspension` and of `dense`.
pub fn rhs_rounds(
    suspension: &Scene,
    dense: &Scene,
    rounds: usize,
    reps: usize,
) -> Result<Vec<RhsRound>> {
    let mut a = suspension.system()?;
    let mut b = dense.system()?;
    let (ya, _) = suspension.raw_state();
    let (yb, _) = dense.raw_state();
    // Warm up: the suspension's first right-hand side builds its neighbour list.
    rhs_seconds(a.as_mut(), ya, 1);
    rhs_seconds(b.as_mut(), yb, 1);
    Ok((0..rounds)
        .map(|_| RhsRound {
            suspension: rhs_seconds(a.as_mut(), ya, reps),
            dense: rhs_seconds(b.as_mut(), yb, reps),
        })
        .collect())
}

/// The median of `v` (not empty).
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

/// Seconds to place `n` swimmers `d` at random in a box at volume fraction `phi` with at least ℓ
/// between sphere surfaces.
pub fn placement_seconds(n: usize, d: Dumbbell, phi: f64, seed: u64) -> Result<f64> {
    let start = Instant::now();
    bulk_scene(n, d, phi, seed)?;
    Ok(start.elapsed().as_secs_f64())
}
