//! The measured crossover of "auto": once per process and model, [`crossover`] times RK4 steps of
//! lattice scenes of 16, 32, 64, ... spheres on both backends until the GPU has won at two sizes
//! in a row (the crossover is the first of them) or a CPU step exceeds 20 ms; then it
//! extrapolates cost = overhead + c·N² from the two largest sizes (none if the GPU's cost per
//! pair is not lower, as with a CPU-emulated adapter slower than the CPU kernel).
//!
//! "auto" takes the GPU only when an f64-capable adapter exists, the scene's model and integrator
//! run there, and the scene has at least as many spheres (swimmers for the averaged model) as the
//! crossover ([`super::plan`]).

use super::backend::Backend;
use super::build::lattice_scene;
use super::error::Result;
use super::integrators::IntegratorSpec;
use super::model::Model;
use super::scene::Scene;
use super::stepping::{advance_cpu, advance_gpu, RunControl, Workspace};
use std::collections::HashMap;
use std::sync::Mutex;
use std::time::Instant;

/// The measured size above which the GPU steps a model faster than the CPU.
#[derive(Debug, Clone, PartialEq)]
pub struct Crossover {
    /// Spheres (micro) or swimmers (averaged) from which the GPU wins; `None`: it never does.
    pub size: Option<usize>,
    /// The measurement, for `s.backend_info` and the benchmark.
    pub detail: String,
}

/// Per-step cost of one backend measured at two sizes, as overhead + c·N².
#[derive(Debug, Clone, Copy)]
struct Fit {
    overhead: f64,
    per_pair: f64,
}

impl Fit {
    fn from_points((n1, t1): (f64, f64), (n2, t2): (f64, f64)) -> Fit {
        let per_pair = ((t2 - t1) / (n2 * n2 - n1 * n1)).max(1e-300);
        Fit {
            overhead: (t1 - per_pair * n1 * n1).max(0.0),
            per_pair,
        }
    }
}

/// The crossover for `model`, measured on first use in this process (a fraction of a second).
pub fn crossover(model: Model) -> Crossover {
    static CACHE: Mutex<Option<HashMap<&'static str, Crossover>>> = Mutex::new(None);
    let mut cache = match CACHE.lock() {
        Ok(c) => c,
        Err(p) => p.into_inner(),
    };
    cache
        .get_or_insert_with(HashMap::new)
        .entry(model.name())
        .or_insert_with(|| measure_crossover(model))
        .clone()
}

fn measure_crossover(model: Model) -> Crossover {
    let dev = match super::gpu::device() {
        Ok(d) => d,
        Err(e) => {
            return Crossover {
                size: None,
                detail: e.to_string(),
            }
        }
    };
    let (per_swimmer, unit) = super::models::of(model).bodies();
    // Double the size until the GPU has won at two sizes in a row, or a CPU step takes longer
    // than the calibration budget.
    let mut points: Vec<(f64, f64, f64)> = Vec::new();
    let mut size = 16usize;
    let mut streak_start = None;
    loop {
        let swimmers = size / per_swimmer;
        let (cpu, gpu) = match (
            step_time(model, Backend::Cpu, swimmers),
            step_time(model, Backend::Gpu, swimmers),
        ) {
            (Ok(c), Ok(g)) => (c, g),
            (Err(e), _) | (_, Err(e)) => {
                return Crossover {
                    size: None,
                    detail: format!("the calibration run failed: {e}"),
                }
            }
        };
        points.push((size as f64, cpu, gpu));
        if gpu < cpu {
            let first = *streak_start.get_or_insert(size);
            if size >= 2 * first {
                break;
            }
        } else {
            streak_start = None;
        }
        if cpu > CALIBRATION_BUDGET {
            break;
        }
        size *= 2;
    }
    let table: Vec<String> = points
        .iter()
        .map(|(n, c, g)| format!("{n} {unit}: cpu {c:.2e} s, gpu {g:.2e} s"))
        .collect();
    let (found, how) = match streak_start {
        Some(n) => (Some(n), format!("the GPU is faster from {n} {unit}")),
        None => {
            // Not reached within the budget: extrapolate cost = overhead + c·N² through the two
            // largest sizes of each backend.
            let k = points.len();
            let (n1, c1, g1) = points[k.saturating_sub(2)];
            let (n2, c2, g2) = points[k - 1];
            let cpu = Fit::from_points((n1, c1), (n2, c2));
            let gpu = Fit::from_points((n1, g1), (n2, g2));
            if k >= 2 && gpu.per_pair < cpu.per_pair {
                let n = ((gpu.overhead - cpu.overhead).max(0.0) / (cpu.per_pair - gpu.per_pair))
                    .sqrt()
                    .ceil()
                    .max(n2) as usize;
                (Some(n), format!("the GPU would be faster from ~{n} {unit} (extrapolated as overhead + c·N²)"))
            } else {
                (
                    None,
                    "the GPU is never faster here (its cost per pair is not lower)".into(),
                )
            }
        }
    };
    Crossover {
        size: found,
        detail: format!(
            "calibrated on {} per RK4 step, {}; {how}",
            dev.describe(),
            table.join("; ")
        ),
    }
}

/// A calibration stops doubling once a CPU step takes this long (s).
const CALIBRATION_BUDGET: f64 = 0.02;

/// Wall time per RK4 step of a cubic lattice of `swimmers` Fig-1 swimmers on one backend (`auto`
/// is timed on the GPU: this measures the backends, it does not choose between them).
pub fn step_time(model: Model, backend: Backend, swimmers: usize) -> Result<f64> {
    step_time_with_cutoff(model, backend, swimmers, None)
}

/// [`step_time`] of the lattice with the averaged model's far-field cutoff `cutoff` (m).
pub fn step_time_with_cutoff(
    model: Model,
    backend: Backend,
    swimmers: usize,
    cutoff: Option<f64>,
) -> Result<f64> {
    let mut s = lattice_scene(swimmers, model)?;
    s.set_cutoff(cutoff)?;
    s.set_backend(backend);
    let dt = s.default_micro_step();
    s.set_integrator(Some(IntegratorSpec::rk4(dt)?));
    let mut ws = Workspace::default();
    let control = RunControl::default();
    let mut run = |s: &mut Scene, duration: f64| {
        let t_end = s.time() + duration;
        match backend {
            Backend::Cpu => advance_cpu(s, &mut ws, &control, t_end, u64::MAX),
            Backend::Gpu | Backend::Auto => advance_gpu(s, &mut ws, &control, t_end),
        }
    };
    if backend != Backend::Cpu {
        // One step first: device buffers and pipelines are set up outside the timing.
        run(&mut s, dt)?;
    }
    // Double the run until it lasts 20 ms, so timer resolution does not matter.
    let mut steps = 1.0;
    loop {
        let start = Instant::now();
        run(&mut s, steps * dt)?;
        let elapsed = start.elapsed().as_secs_f64();
        if elapsed >= 0.02 || steps >= 1024.0 {
            return Ok(elapsed / steps);
        }
        steps *= 2.0;
    }
}
