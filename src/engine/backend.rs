//! Where a scene's dynamics run: the CPU, a GPU, or the one that is faster for the scene at hand.
//!
//! "auto" takes the GPU only when an f64-capable adapter exists, the scene's model and integrator
//! run there, and the scene has at least as many spheres (swimmers for the averaged model) as the
//! crossover measured on this machine: once per process and model, [`crossover`] times RK4 steps
//! of lattice scenes of 16, 32, 64, ... spheres on both backends until the GPU has won at two
//! sizes in a row (the crossover is the first of them) or a CPU step exceeds 20 ms; then it
//! extrapolates cost = overhead + c·N² from the two largest sizes (none if the GPU's cost per
//! pair is not lower, as with a CPU-emulated adapter slower than the CPU kernel).

use super::choice::{self, Choice, Named};
use super::error::Result;
use super::gpu::rk_stages::Tableau;
use super::integrators::IntegratorSpec;
use super::model::Model;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::sync::Mutex;
use std::time::Instant;

/// The user's choice of backend.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Backend {
    /// Always the CPU.
    #[default]
    Cpu,
    /// Always the GPU; an error when there is none or the scene cannot run there.
    Gpu,
    /// The GPU when present and faster for this scene's size, else the CPU.
    Auto,
}

impl Named for Backend {
    const KIND: &'static str = "backend";
    const CHOICES: &'static [Choice<Self>] = &[
        Choice {
            value: Backend::Cpu,
            name: "cpu",
            about: "default",
        },
        Choice {
            value: Backend::Gpu,
            name: "gpu",
            about: "always the GPU",
        },
        Choice {
            value: Backend::Auto,
            name: "auto",
            about: "the GPU when present and faster for the scene\'s size",
        },
    ];
}

choice::inherent_names!(Backend);

/// The device Runge-Kutta method for an integrator, or why it has none.
pub fn gpu_tableau(spec: &IntegratorSpec) -> std::result::Result<(f64, Tableau), String> {
    match *spec {
        IntegratorSpec::Euler { dt } => Ok((dt, Tableau::euler())),
        IntegratorSpec::Rk4 { dt } => Ok((dt, Tableau::rk4())),
        other => Err(format!(
            "the GPU backend steps the fixed-step methods euler(dt) and rk4(dt); {other} is adaptive and runs on the CPU"
        )),
    }
}

/// Whether a model runs on the GPU, or why not.
pub fn gpu_model_supported(model: Model) -> std::result::Result<(), String> {
    match model {
        Model::Micro | Model::Averaged => Ok(()),
        Model::Rigid => Err(
            "the rigid-stroke model runs on the CPU only (its per-swimmer stroke solve has no GPU kernel)"
                .into(),
        ),
    }
}

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
                detail: e,
            }
        }
    };
    let unit = if model == Model::Averaged {
        "swimmers"
    } else {
        "spheres"
    };
    // Double the size until the GPU has won at two sizes in a row, or a CPU step takes longer
    // than the calibration budget.
    let mut points: Vec<(f64, f64, f64)> = Vec::new();
    let mut size = 16usize;
    let mut streak_start = None;
    loop {
        let swimmers = if model == Model::Averaged {
            size
        } else {
            size / 2
        };
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

/// Wall time per RK4 step of a cubic lattice of `swimmers` Fig-1 swimmers on one backend.
pub fn step_time(model: Model, backend: Backend, swimmers: usize) -> Result<f64> {
    let mut s = super::scene::lattice_scene(swimmers, model)?;
    s.set_backend(backend);
    let dt = s.default_micro_step();
    s.set_integrator(Some(IntegratorSpec::rk4(dt)?));
    if backend != Backend::Cpu {
        // One step first: device buffers and pipelines are set up outside the timing.
        s.run(dt, &super::scene::never)?;
    }
    // Double the run until it lasts 20 ms, so timer resolution does not matter.
    let mut steps = 1.0;
    loop {
        let start = Instant::now();
        s.run(steps * dt, &super::scene::never)?;
        let elapsed = start.elapsed().as_secs_f64();
        if elapsed >= 0.02 || steps >= 1024.0 {
            return Ok(elapsed / steps);
        }
        steps *= 2.0;
    }
}
