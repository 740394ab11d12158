//! CPU against GPU: wall time per RK4 step against scene size for both models, transfers
//! included (each timed run uploads the state, steps on the device and reads the state back),
//! and the crossover where the GPU starts to win on the machine at hand.

use super::table::Table;
use crate::engine::calibrate::{crossover, step_time};
use crate::engine::{Backend, Model};

/// One measured size.
#[derive(Debug, Clone)]
pub struct Row {
    /// Model.
    pub model: Model,
    /// Spheres (micro) or swimmers (averaged).
    pub size: usize,
    /// Seconds per step on the CPU (None: skipped, over the time budget).
    pub cpu: Option<f64>,
    /// Seconds per step on the GPU (None: skipped or no adapter).
    pub gpu: Option<f64>,
}

/// Skip a backend at sizes where the last step time, scaled by N², would exceed this (s).
const BUDGET_PER_STEP: f64 = 20.0;

/// Measure both backends at sizes 8 … `max` (doubling), both models.
pub fn run(max: usize) -> Vec<Row> {
    let gpu = crate::engine::gpu::device().is_ok();
    let mut rows = Vec::new();
    for model in [Model::Micro, Model::Averaged] {
        let (mut last_cpu, mut last_gpu) = (0.0f64, 0.0f64);
        let mut size = 8;
        while size <= max {
            let swimmers = if model == Model::Averaged {
                size
            } else {
                size / 2
            };
            let time = |backend, last: &mut f64, enabled: bool| {
                if !enabled || *last * 4.0 > BUDGET_PER_STEP {
                    return None;
                }
                let t = step_time(model, backend, swimmers).ok()?;
                *last = t;
                Some(t)
            };
            let cpu = time(Backend::Cpu, &mut last_cpu, true);
            let gpu = time(Backend::Gpu, &mut last_gpu, gpu);
            rows.push(Row {
                model,
                size,
                cpu,
                gpu,
            });
            size *= 2;
        }
    }
    rows
}

fn cell(v: Option<f64>) -> String {
    v.map(|t| format!("{t:.3e}")).unwrap_or_else(|| "-".into())
}

/// The table: model, size, CPU and GPU seconds per step, their ratio.
pub fn table(rows: &[Row]) -> Table {
    let mut t = Table::new(&[
        "model",
        "size",
        "unit",
        "cpu_s_per_step",
        "gpu_s_per_step",
        "gpu/cpu",
    ]);
    for r in rows {
        let ratio = match (r.cpu, r.gpu) {
            (Some(c), Some(g)) => format!("{:.3}", g / c),
            _ => "-".into(),
        };
        t.rows.push(vec![
            r.model.name().into(),
            r.size.to_string(),
            if r.model == Model::Averaged {
                "swimmers"
            } else {
                "spheres"
            }
            .into(),
            cell(r.cpu),
            cell(r.gpu),
            ratio,
        ]);
    }
    t
}

/// The smallest measured size from which the GPU was faster at every larger measured size.
pub fn measured_crossover(rows: &[Row], model: Model) -> Option<usize> {
    let mine: Vec<&Row> = rows.iter().filter(|r| r.model == model).collect();
    let wins = |r: &&Row| matches!((r.cpu, r.gpu), (Some(c), Some(g)) if g < c);
    let both: Vec<&&Row> = mine
        .iter()
        .filter(|r| r.cpu.is_some() && r.gpu.is_some())
        .collect();
    let first_loss_after = both.iter().rposition(|r| !wins(r));
    match first_loss_after {
        None => both.first().map(|r| r.size),
        Some(i) => both.get(i + 1).map(|r| r.size),
    }
}

/// The calibration "auto" uses, for the report.
pub fn auto_thresholds() -> Vec<(Model, String)> {
    [Model::Micro, Model::Averaged]
        .into_iter()
        .map(|m| (m, crossover(m).detail))
        .collect()
}
