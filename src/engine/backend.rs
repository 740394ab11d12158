//! Where a scene's dynamics run: the CPU, a GPU, or the one that is faster for the scene at hand;
//! and what the GPU can run (models, integrators). The choice for a given scene is made in
//! [`super::plan`]; "auto"'s measured crossover in [`super::calibrate`].

use super::choice::{self, Choice, Named};
use super::gpu::rk_stages::Tableau;
use super::integrators::IntegratorSpec;
use super::model::Model;
use serde::{Deserialize, Serialize};

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
        IntegratorSpec::Platen { .. } => Err(format!(
            "the GPU backend steps the fixed-step methods euler(dt) and rk4(dt); {spec}, the weak scheme for thermal noise, runs on the CPU"
        )),
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
