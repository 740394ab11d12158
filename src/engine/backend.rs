//! Where a scene's dynamics run: the CPU, a GPU, or the one that is faster for the scene at hand;
//! and what the GPU can run (models, integrators). The choice for a given scene is made in
//! [`super::plan`]; "auto"'s measured crossover in [`super::calibrate`].

use super::choice::{self, Choice, Named};
use super::gpu::rk_stages::Tableau;
use super::integrators::{IntegratorSpec, DOPRI5_A, DOPRI5_C, DOPRI5_E};
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

/// How the device steps: uniform steps of `dt`, or adaptive steps at relative tolerance `rtol`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GpuSteps {
    /// Uniform steps (s).
    Fixed(f64),
    /// Error-controlled steps of an embedded pair.
    Adaptive(f64),
}

/// The device Runge-Kutta method for an integrator, or why it has none.
pub fn gpu_tableau(spec: &IntegratorSpec) -> std::result::Result<(GpuSteps, Tableau), String> {
    match *spec {
        IntegratorSpec::Euler { dt } => Ok((GpuSteps::Fixed(dt), Tableau::euler())),
        IntegratorSpec::Rk4 { dt } => Ok((GpuSteps::Fixed(dt), Tableau::rk4())),
        IntegratorSpec::Dopri5 { rtol } => Ok((GpuSteps::Adaptive(rtol), dopri5_tableau())),
        IntegratorSpec::Platen { .. } => Err(format!(
            "the GPU backend steps euler(dt), rk4(dt) and dopri5(rtol); {spec}, the weak scheme for thermal noise, runs on the CPU"
        )),
        other => Err(format!(
            "the GPU backend steps euler(dt), rk4(dt) and dopri5(rtol); {other} runs on the CPU"
        )),
    }
}

/// The CPU's Dormand-Prince 5(4) tableau, for the device.
fn dopri5_tableau() -> Tableau {
    let a: Vec<Vec<f64>> = DOPRI5_A
        .iter()
        .enumerate()
        .map(|(s, row)| row[..s].to_vec())
        .collect();
    // The last row is the solution; its stage (taken there) has weight 0.
    let mut b = DOPRI5_A[6].to_vec();
    b.push(0.0);
    Tableau {
        c: DOPRI5_C.to_vec(),
        a,
        b,
        e: DOPRI5_E.to_vec(),
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
