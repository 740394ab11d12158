//! Cost per stroke period against the number of swimmers S, for the microscopic and the averaged
//! model on the CPU, the averaged model with a far-field cutoff of [`CUTOFF_ELLS`] ℓ (cell
//! lists: O(S)), and both models on the GPU when an adapter is present, with the exponent of a
//! power-law fit.
//!
//! Each size is a cubic lattice of Fig-1 swimmers 3ℓ apart (every pair interacts,
//! [`crate::engine::build::lattice_scene`]). The time per RK4 step is measured
//! ([`step_time`]: repeated until a run lasts 20 ms) and multiplied by the steps a period takes:
//! T/h with the microscopic model's default step h = 0.8/rate (the spring's stiffness sets it,
//! whatever S), and one step per period for the averaged model (RK4 with h = T, as in the GPU
//! tests). A step's cost does not depend on the state, so this is the cost of running a period,
//! without running whole periods of the largest scenes (a 4,096-swimmer microscopic period is
//! minutes).

use super::table::Table;
use crate::engine::build::lattice_scene;
use crate::engine::calibrate::step_time_with_cutoff;
use crate::engine::{Backend, Model};

/// One series: a model on a backend, with or without a cutoff.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Line {
    /// Model.
    pub model: Model,
    /// The averaged model's far-field cutoff (m), if any.
    pub cutoff: Option<f64>,
    /// CPU or GPU.
    pub backend: Backend,
}

/// One measured size.
#[derive(Debug, Clone)]
pub struct Row {
    /// The series.
    pub line: Line,
    /// Swimmers.
    pub swimmers: usize,
    /// Seconds per RK4 step.
    pub step: f64,
    /// Steps per period.
    pub steps_per_period: f64,
}

impl Row {
    /// Seconds per stroke period.
    pub fn per_period(&self) -> f64 {
        self.step * self.steps_per_period
    }
}

/// The cutoff of the third series, in ℓ (the lattice is 3ℓ apart: ~150 partners each).
pub const CUTOFF_ELLS: f64 = 10.0;

/// The series measured: the three CPU series, and both models on the GPU when `gpu`.
pub fn series(gpu: bool) -> Vec<Line> {
    let ell = crate::engine::Dumbbell::default().ell;
    let cpu = |model, cutoff| Line {
        model,
        cutoff,
        backend: Backend::Cpu,
    };
    let mut v = vec![
        cpu(Model::Micro, None),
        cpu(Model::Averaged, None),
        cpu(Model::Averaged, Some(CUTOFF_ELLS * ell)),
    ];
    if gpu {
        for model in [Model::Micro, Model::Averaged] {
            v.push(Line {
                model,
                cutoff: None,
                backend: Backend::Gpu,
            });
        }
    }
    v
}

/// A series' label: the model, its cutoff, and "gpu" for the device.
pub fn label(line: &Line) -> String {
    let mut l = line.model.name().to_string();
    if line.cutoff.is_some() {
        l += &format!(", cutoff {CUTOFF_ELLS} ell");
    }
    if line.backend == Backend::Gpu {
        l += ", gpu";
    }
    l
}

/// Measure S = 2, 4, … `max` swimmers for both models, up to 8 `max` for the averaged model with
/// its cutoff, and both models on the GPU up to `max` when an adapter is present.
pub fn run(max: usize) -> Result<Vec<Row>, String> {
    let gpu = crate::engine::gpu::device().is_ok();
    let mut rows = Vec::new();
    for line in series(gpu) {
        let Line {
            model,
            cutoff,
            backend,
        } = line;
        let top = if cutoff.is_some() { 8 * max } else { max };
        let mut s = 2;
        while s <= top {
            let scene = lattice_scene(s, model).map_err(|e| e.to_string())?;
            let period = scene.period().map_err(|e| e.to_string())?;
            let steps_per_period = match model {
                Model::Averaged => 1.0,
                _ => (period / scene.default_micro_step()).ceil(),
            };
            let step =
                step_time_with_cutoff(model, backend, s, cutoff).map_err(|e| e.to_string())?;
            rows.push(Row {
                line,
                swimmers: s,
                step,
                steps_per_period,
            });
            s *= 2;
        }
    }
    Ok(rows)
}

/// Least-squares slope and prefactor of log(cost) against log(S) over the series' rows with
/// S ≥ `from`: cost ≈ c · S^slope. `None` with fewer than two such rows.
pub fn fit(rows: &[Row], line: &Line, from: usize) -> Option<(f64, f64)> {
    let pts: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r.line == *line && r.swimmers >= from)
        .map(|r| ((r.swimmers as f64).ln(), r.per_period().ln()))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
    let slope = sxy / sxx;
    Some((slope, (my - slope * mx).exp()))
}

/// The table: model, S, seconds per step, steps per period, seconds per period.
pub fn table(rows: &[Row]) -> Table {
    let mut t = Table::new(&[
        "model",
        "swimmers",
        "s_per_step",
        "steps_per_period",
        "s_per_period",
    ]);
    for r in rows {
        t.rows.push(vec![
            label(&r.line),
            r.swimmers.to_string(),
            format!("{:.3e}", r.step),
            format!("{:.0}", r.steps_per_period),
            format!("{:.3e}", r.per_period()),
        ]);
    }
    t
}
