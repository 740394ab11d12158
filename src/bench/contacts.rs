//! Whole runs of suspensions in contact, the accurate models at the run's default tolerance:
//! seconds and right-hand sides a period, in open space and in a periodic box.
//!
//! Each scene is the density study's: `S` asymmetric swimmers (a1 = 0.225 ℓ, a2 = a1/2, Λ =
//! 0.15 ℓ) placed at random at sphere volume fraction φ = 1% (seed 1001, the default gap), the
//! study's contact law (steric rods, range 0.5 µm, 1e-3 N/m, the smooth law, overlaps allowed),
//! run from placement under `auto(1e-4)`; the open-space scene is the same placement with the box
//! removed. A run's first period includes the settling of the rods placed within the range.

use super::boundaries::asymmetric_swimmer;
use super::table::Table;
use crate::engine::build::{box_side, random_suspension, Orientations, Phases};
use crate::engine::contacts::{Overlaps, Steric, StericBody, StericLaw};
use crate::engine::{IntegratorSpec, Model, Scene, Simulation};
use std::time::Instant;

/// The sphere volume fraction of every scene.
pub const PHI: f64 = 0.01;

/// The runs' tolerance.
pub const TOL: f64 = 1e-4;

/// One run.
#[derive(Debug, Clone)]
pub struct Row {
    /// The model.
    pub model: Model,
    /// Swimmers.
    pub swimmers: usize,
    /// Whether in the periodic box (else open space).
    pub periodic: bool,
    /// Periods run.
    pub periods: f64,
    /// Wall-clock seconds a period.
    pub seconds: f64,
    /// Right-hand sides a period.
    pub rhs: f64,
    /// Accepted steps a period (macro steps of stroboscopic averaging count once).
    pub steps: f64,
}

/// The study's scene of `swimmers` under `model`, in its box or in open space.
pub fn scene(model: Model, swimmers: usize, periodic: bool) -> Result<Scene, String> {
    let err = |e: crate::engine::EngineError| e.to_string();
    let d = asymmetric_swimmer();
    let side = box_side(swimmers, &d, PHI).map_err(err)?;
    let mut s = Scene::new();
    s.set_box(Some([side; 3])).map_err(err)?;
    random_suspension(
        &mut s,
        swimmers,
        d,
        [side; 3],
        Orientations::Random,
        Phases::Random,
        1001,
    )
    .map_err(err)?;
    let steric = Steric::new(0.5e-6, 1e-3)
        .map_err(err)?
        .with_body(StericBody::Rods)
        .with_law(StericLaw::Smooth);
    s.set_steric(Some(steric));
    s.set_overlaps(Overlaps::Allow);
    if !periodic {
        s.set_box(None).map_err(err)?;
    }
    s.set_model(model);
    s.set_integrator(Some(IntegratorSpec::Auto { tol: TOL }));
    Ok(s)
}

/// `periods` of the study's scene of `swimmers` under `model`, timed.
pub fn measure(model: Model, swimmers: usize, periodic: bool, periods: f64) -> Result<Row, String> {
    let mut sim = Simulation::new(scene(model, swimmers, periodic)?);
    let start = Instant::now();
    sim.run_periods(periods).map_err(|e| e.to_string())?;
    let seconds = start.elapsed().as_secs_f64();
    let stats = sim.scene().stats();
    Ok(Row {
        model,
        swimmers,
        periodic,
        periods,
        seconds: seconds / periods,
        rhs: stats.rhs_evals as f64 / periods,
        steps: stats.steps as f64 / periods,
    })
}

/// The runs: 64 swimmers of each model in open space and in the box (the rigid model over 10
/// periods, the spring model, whose steps its springs hold short, over one and a quarter), and
/// the first twentieth of a period of 1,000 rigid swimmers in open space, where the rods placed
/// within the range settle; `quick`: 16 swimmers, a period each (a quarter for springs in the
/// box), and no 1,000.
pub fn run(quick: bool) -> Result<Vec<Row>, String> {
    let n = if quick { 16 } else { 64 };
    let rigid = if quick { 1.0 } else { 10.0 };
    let mut rows = vec![
        measure(Model::Rigid, n, false, rigid)?,
        measure(Model::Rigid, n, true, rigid)?,
        measure(Model::Micro, n, false, 1.0)?,
        measure(Model::Micro, n, true, 0.25)?,
    ];
    if !quick {
        rows.push(measure(Model::Rigid, 1000, false, 0.05)?);
    }
    Ok(rows)
}

/// The table: one row a run.
pub fn table(rows: &[Row]) -> Table {
    let mut t = Table::new(&[
        "model",
        "swimmers",
        "boundary",
        "periods",
        "s_per_period",
        "rhs_per_period",
        "steps_per_period",
    ]);
    for r in rows {
        t.rows.push(vec![
            r.model.name().to_string(),
            r.swimmers.to_string(),
            if r.periodic { "box" } else { "open" }.to_string(),
            format!("{}", r.periods),
            format!("{:.3e}", r.seconds),
            format!("{:.0}", r.rhs),
            format!("{:.1}", r.steps),
        ]);
    }
    t
}
