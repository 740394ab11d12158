//! Bulk suspensions of the averaged model (`swimlab bench suspension`): one right-hand side of a
//! dilute boxed suspension with a cutoff against one all-pairs right-hand side of a dense
//! lattice, side by side in alternating rounds; random placement; the cost of runs per
//! swimmer-period against the number of swimmers.
//!
//! The suspension is the bulk demo's: symmetric Fig-1 swimmers (a = 0.15ℓ) at sphere volume
//! fraction φ in a cubic box, placed at random with at least ℓ between sphere surfaces, random
//! orientations and phases, cutoff 6ℓ, steric repulsion between rods ([`STERIC`]), run by the
//! averaged model's default integrator.

use super::table::Table;
use crate::engine::build::{
    box_side, lattice_scene_of, random_suspension_apart, Draw, Orientations, Phases,
};
use crate::engine::error::Result;
use crate::engine::integrators::OdeSystem;
use crate::engine::{
    Dumbbell, IntegratorSpec, Model, Scene, Simulation, Steric, StericBody, StericLaw,
};
use std::time::Instant;

/// The cutoff of the bulk suspension, in ℓ.
pub const CUTOFF_ELLS: f64 = 6.0;
/// The steric repulsion of the bulk suspension: range (m) and stiffness (N/m), between rods (so
/// that swimmers cannot pass through each other's middles, where sphere repulsion never acts)
/// with the smooth law. Its push at contact, kδ/(6πμa) ≈ 3.5e-3 m/s, outruns the far field of a
/// pair side by side at contact (≈ 7e-4 m/s at D = 2a + δ), which a tenth of it (1e-5 N/m) does
/// not: the swimmers then overlap within a few thousand periods.
pub const STERIC: (f64, f64) = (0.5e-6, 1e-4);

/// The bulk suspension's steric repulsion.
pub fn steric() -> Result<Steric> {
    Ok(Steric::new(STERIC.0, STERIC.1)?
        .with_body(StericBody::Rods)
        .with_law(StericLaw::Smooth))
}

/// The bulk suspension of `n` swimmers `d` at sphere volume fraction `phi`, seeded by `seed`.
pub fn bulk_scene(n: usize, d: Dumbbell, phi: f64, seed: u64) -> Result<Scene> {
    bulk_scene_apart(n, d, phi, seed, Some(d.ell))
}

/// [`bulk_scene`] with sphere gaps above `gap` at the start (`None`: only what the strokes need).
pub fn bulk_scene_apart(
    n: usize,
    d: Dumbbell,
    phi: f64,
    seed: u64,
    gap: Option<f64>,
) -> Result<Scene> {
    let mut s = Scene::new();
    s.set_model(Model::Averaged);
    let side = box_side(n, &d, phi)?;
    s.set_box(Some([side; 3]))?;
    random_suspension_apart(
        &mut s,
        n,
        d,
        [side; 3],
        Draw {
            orientations: Orientations::Random,
            phases: Phases::Random,
            seed,
            gap,
        },
    )?;
    s.set_cutoff(Some(CUTOFF_ELLS * d.ell))?;
    s.set_steric(Some(steric()?));
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

/// One run of a bulk suspension with the default integrator: the cost of each stretch.
#[derive(Debug, Clone)]
pub struct Run {
    /// Swimmers.
    pub swimmers: usize,
    /// Periods run and the seconds each stretch took: (periods so far, seconds so far).
    pub stretches: Vec<(f64, f64)>,
    /// Steps, rejected attempts, right-hand sides and refined steps at the end.
    pub stats: crate::engine::integrators::Stats,
    /// The integrator that ran, as `s.integrator_info` says it.
    pub integrator: String,
}

impl Run {
    /// Seconds per swimmer-period over the first `periods` (the stretch that ends there).
    pub fn cost_per_swimmer_period(&self, periods: f64) -> Option<f64> {
        self.stretches
            .iter()
            .find(|(p, _)| *p >= periods)
            .map(|(p, t)| t / (p * self.swimmers as f64))
    }
}

/// Run `n` bulk swimmers (φ = 0.1%) for `periods` periods in `stretches` equal stretches.
pub fn run_bulk(n: usize, periods: f64, stretches: usize, seed: u64) -> Result<Run> {
    let s = bulk_scene(n, Dumbbell::default(), 1e-3, seed)?;
    let integrator = s.integrator_info()?;
    let mut sim = Simulation::new(s);
    let start = Instant::now();
    let mut out = Vec::new();
    for k in 1..=stretches {
        let target = periods * k as f64 / stretches as f64;
        let now = sim.scene().time() / sim.scene().period()?;
        sim.run_periods(target - now)?;
        out.push((target, start.elapsed().as_secs_f64()));
    }
    Ok(Run {
        swimmers: n,
        stretches: out,
        stats: sim.scene().stats(),
        integrator,
    })
}

/// One tolerance of [`accuracy`]: (tol, relative error, steps, right-hand sides, seconds).
pub type AccuracyRow = (f64, f64, u64, u64, f64);

/// The accuracy check: 1,000 swimmers at φ = 0.3% placed half an ℓ apart (contacts form), the
/// bulk steric repulsion, `periods` periods by `suspension(tol)` for each tolerance against RK4
/// at T/128 (itself checked against T/256): per tolerance the RMS displacement error relative to
/// the RMS displacement, steps, right-hand sides, seconds.
pub fn accuracy(periods: f64, tols: &[f64]) -> Result<(f64, Vec<AccuracyRow>)> {
    let run = |spec: IntegratorSpec| -> Result<(Vec<f64>, crate::engine::integrators::Stats, f64)> {
        let d = Dumbbell::default();
        let mut s = bulk_scene_apart(1000, d, 3e-3, 2026, Some(0.5 * d.ell))?;
        s.set_integrator(Some(spec));
        let mut sim = Simulation::new(s);
        let start = Instant::now();
        sim.run_periods(periods)?;
        let el = start.elapsed().as_secs_f64();
        Ok((sim.scene().raw_state().0.to_vec(), sim.scene().stats(), el))
    };
    let t = 2.0 * std::f64::consts::PI / Dumbbell::default().omega;
    let (fine, ..) = run(IntegratorSpec::rk4(t / 256.0)?)?;
    let (reference, ..) = run(IntegratorSpec::rk4(t / 128.0)?)?;
    let reference_error = displacement_error(&reference, &fine);
    let mut rows = Vec::new();
    for &tol in tols {
        let (y, st, el) = run(IntegratorSpec::suspension(tol)?)?;
        rows.push((
            tol,
            displacement_error(&y, &reference),
            st.steps,
            st.rhs_evals,
            el,
        ));
    }
    Ok((reference_error, rows))
}

/// RMS over swimmers of |ΔR_a − ΔR_b|, relative to the RMS of |ΔR_b| (states from one start).
pub fn displacement_error(a: &[f64], b: &[f64]) -> f64 {
    let (mut e, mut m) = (0.0, 0.0);
    for i in 0..a.len() / 6 {
        for k in 0..3 {
            e += (a[6 * i + k] - b[6 * i + k]).powi(2);
            m += b[6 * i + k].powi(2);
        }
    }
    (e / m).sqrt()
}

/// The side-by-side right-hand sides as a table, with the median ratio.
pub fn rhs_table(n: usize, m: usize, rounds: &[RhsRound]) -> Table {
    let listed = format!("{n} in a box, cutoff 6 ell (s)");
    let dense = format!("{m} all pairs (s)");
    let mut t = Table::new(&["round", &listed, &dense, "ratio"]);
    for (k, r) in rounds.iter().enumerate() {
        t.rows.push(vec![
            (k + 1).to_string(),
            format!("{:.3e}", r.suspension),
            format!("{:.3e}", r.dense),
            format!("{:.3}", r.suspension / r.dense),
        ]);
    }
    t
}
