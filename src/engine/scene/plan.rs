//! Where the next run goes: the CPU, or the GPU when the backend, the model, the options and the
//! integrator allow it (and, for "auto", when the scene is above the measured crossover).

use super::*;

impl Scene {
    /// Which backend the next run uses and why, e.g. "cpu: 4 spheres, below the GPU crossover
    /// ...". For "gpu" on a scene that cannot run there, the error says why.
    pub fn backend_info(&self) -> Result<String> {
        self.plan()
            .map(|(gpu, why)| format!("{}: {why}", if gpu { "gpu" } else { "cpu" }))
    }

    /// The options the device kernels do not have: contact handling and the cutoff.
    pub(super) fn gpu_options_supported(&self) -> std::result::Result<(), String> {
        let cpu_only = |what: &str| Err(format!("{what} runs on the CPU only"));
        match self.model {
            _ if self.contacts != Contacts::default() => {
                cpu_only("contact handling (overlaps allowed, steric repulsion)")
            }
            Model::Averaged if self.cutoff.is_some() => cpu_only("the far-field cutoff"),
            _ => Ok(()),
        }
    }

    /// Whether the next run takes the GPU, and why.
    pub(super) fn plan(&self) -> Result<(bool, String)> {
        let fit = backend::gpu_model_supported(self.model)
            .and_then(|()| self.gpu_options_supported())
            .and_then(|()| backend::gpu_tableau(&self.integrator()).map(|_| ()));
        match self.backend {
            Backend::Cpu => Ok((false, "the cpu backend was chosen".into())),
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
                let dev = crate::engine::gpu::device().map_err(|e| {
                    unsupported(format!("the gpu backend: {e}"), &[Setting::Backend("cpu")])
                })?;
                Ok((
                    true,
                    format!("{} (the gpu backend was chosen)", dev.describe()),
                ))
            }
            Backend::Auto => {
                if let Err(e) = fit {
                    return Ok((false, format!("auto: {e}")));
                }
                let dev = match crate::engine::gpu::device() {
                    Ok(d) => d,
                    Err(e) => return Ok((false, format!("auto: {e}"))),
                };
                let (size, unit) = match self.model {
                    Model::Averaged => (self.count(), "swimmers"),
                    _ => (2 * self.count(), "spheres"),
                };
                let c = backend::crossover(self.model);
                Ok(match c.size {
                    Some(n) if size >= n => (
                        true,
                        format!("auto: {} with {size} {unit}, at or above the measured crossover of {n} ({})", dev.describe(), c.detail),
                    ),
                    Some(n) => (
                        false,
                        format!("auto: {size} {unit}, below the measured GPU crossover of {n} ({})", c.detail),
                    ),
                    None => (false, format!("auto: {}", c.detail)),
                })
            }
        }
    }
}
