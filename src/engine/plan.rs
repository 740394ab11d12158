//! Where the next run goes: the CPU, or the GPU when the backend, the model, the options and the
//! integrator allow it (and, for "auto", when the scene is above the measured crossover).

use super::backend::{self, Backend};
use super::calibrate;
use super::contacts::Contacts;
use super::error::{unsupported, Result, Setting};
use super::model::Model;
use super::scene::Scene;

/// Which backend the next run of `s` takes, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The run takes the GPU.
    pub gpu: bool,
    /// Why, e.g. "auto: 4 spheres, below the measured GPU crossover of 512 (...)".
    pub why: String,
}

impl std::fmt::Display for Plan {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", if self.gpu { "gpu" } else { "cpu" }, self.why)
    }
}

/// Which backend the next run of `s` uses and why, e.g. "cpu: 4 spheres, below the GPU
/// crossover ...". For "gpu" on a scene that cannot run there, the error says why.
pub fn backend_info(s: &Scene) -> Result<String> {
    plan(s).map(|p| p.to_string())
}

/// The options the device kernels do not have: a periodic box, contact handling, the cutoff,
/// thermal noise.
fn gpu_options_supported(s: &Scene) -> std::result::Result<(), String> {
    let cpu_only = |what: &str| Err(format!("{what} runs on the CPU only"));
    match s.model() {
        _ if s.periodic().is_some() => cpu_only("a periodic box (Ewald sums, minimum images)"),
        _ if s.thermal().is_on() => cpu_only("thermal noise (temperature above 0)"),
        _ if s.contacts() != Contacts::default() => {
            cpu_only("contact handling (overlaps allowed, steric repulsion)")
        }
        Model::Averaged if s.cutoff().is_some() => cpu_only("the far-field cutoff"),
        _ => Ok(()),
    }
}

/// Whether the next run of `s` takes the GPU, and why.
pub fn plan(s: &Scene) -> Result<Plan> {
    let fit = backend::gpu_model_supported(s.model())
        .and_then(|()| gpu_options_supported(s))
        .and_then(|()| backend::gpu_tableau(&s.integrator()).map(|_| ()));
    let cpu = |why: String| Ok(Plan { gpu: false, why });
    match s.backend() {
        Backend::Cpu => cpu("the cpu backend was chosen".into()),
        Backend::Gpu => {
            fit.map_err(|e| {
                unsupported(
                    format!("the gpu backend: {e}"),
                    &[
                        Setting::Backend("cpu"),
                        Setting::Backend("auto"),
                        Setting::FixedStep,
                    ],
                )
            })?;
            let dev = super::gpu::device().map_err(|e| {
                unsupported(format!("the gpu backend: {e}"), &[Setting::Backend("cpu")])
            })?;
            Ok(Plan {
                gpu: true,
                why: format!("{} (the gpu backend was chosen)", dev.describe()),
            })
        }
        Backend::Auto => {
            if let Err(e) = fit {
                return cpu(format!("auto: {e}"));
            }
            let dev = match super::gpu::device() {
                Ok(d) => d,
                Err(e) => return cpu(format!("auto: {e}")),
            };
            let (size, unit) = match s.model() {
                Model::Averaged => (s.count(), "swimmers"),
                _ => (2 * s.count(), "spheres"),
            };
            let c = calibrate::crossover(s.model());
            Ok(match c.size {
                Some(n) if size >= n => Plan {
                    gpu: true,
                    why: format!("auto: {} with {size} {unit}, at or above the measured crossover of {n} ({})", dev.describe(), c.detail),
                },
                Some(n) => Plan {
                    gpu: false,
                    why: format!("auto: {size} {unit}, below the measured GPU crossover of {n} ({})", c.detail),
                },
                None => Plan {
                    gpu: false,
                    why: format!("auto: {}", c.detail),
                },
            })
        }
    }
}
