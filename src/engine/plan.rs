//! Where the next run goes: the CPU, or the GPU when the backend, the model, the options and the
//! integrator allow it (and, for "auto", when the scene is above the measured crossover).

use super::backend::Backend;
use super::calibrate;
use super::error::{unsupported, Result, Setting};
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

/// Whether the next run of `s` takes the GPU, and why.
pub fn plan(s: &Scene) -> Result<Plan> {
    let fit = super::gpu::support::supports(s);
    let cpu = |why: String| Ok(Plan { gpu: false, why });
    match s.backend() {
        Backend::Cpu => cpu("the cpu backend was chosen".into()),
        Backend::Gpu => {
            fit.map_err(|e| {
                let method = super::gpu::support::only_the_integrator_refused(s);
                let fixes = [
                    Setting::Backend("cpu"),
                    Setting::Backend("auto"),
                    Setting::FixedStep,
                ];
                unsupported(
                    format!("the gpu backend: {e}"),
                    &fixes[..if method { 3 } else { 2 }],
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
            let (per_swimmer, unit) = s.swimmer_model().bodies();
            let size = per_swimmer * s.count();
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
