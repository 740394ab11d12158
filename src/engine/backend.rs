//! Where a scene's dynamics run: the CPU, a GPU, or the one that is faster for the scene at hand.
//! The choice for a given scene is made in [`super::plan`], what the device can run in
//! [`super::gpu::support`], "auto"'s measured crossover in [`super::calibrate`].

use super::choice::{self, Choice, Named};
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
