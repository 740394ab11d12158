//! Which equations move the scene, and the layout of their state vector.
//!
//! Both models keep 6 numbers per swimmer σ at `y[6σ..6σ+6]`:
//! - `y[6σ..6σ+3]`: the displacement ΔR of the hydrodynamic centre from its *base* position (kept
//!   apart in the scene). The net drift per period is ~1e-7 ℓ at D = 10ℓ; adding it to an absolute
//!   position of size ~10ℓ every step would round it at ~1e-15·10ℓ per step, a systematic error of up to
//!   1e-4 of the drift over a period of ~1,000 steps. A displacement stays small and rounds far below.
//! - `y[6σ+3..6σ+6]`: the microscopic model's dumbbell vector b = X₂ − X₁ (m); the averaged model's
//!   unit orientation N, and so the rigid-stroke model's (whose length is L(t)).

use super::choice::{self, Choice, Named};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Water at room temperature (Pa s), the paper's μ.
pub const DEFAULT_MU: f64 = 1e-3;

/// Numbers per swimmer in the state vector.
pub const STATE_PER_SWIMMER: usize = 6;

/// The model that moves a scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Model {
    /// All spheres, springs and the full mobility (e:langevin).
    #[default]
    Micro,
    /// Stroke-averaged R_H and N per swimmer (e:eom … e:eom_last).
    Averaged,
    /// The microscopic model in the rigid-stroke limit k0 → ∞: lengths follow L(t) exactly.
    Rigid,
}

impl Named for Model {
    const KIND: &'static str = "model";
    const CHOICES: &'static [Choice<Self>] = &[
        Choice {
            value: Model::Micro,
            name: "micro",
            about: "spheres and springs, default",
        },
        Choice {
            value: Model::Rigid,
            name: "rigid",
            about: "spheres, lengths prescribed",
        },
        Choice {
            value: Model::Averaged,
            name: "averaged",
            about: "stroke-averaged R_H and N",
        },
    ];
}

choice::inherent_names!(Model);

/// Coefficients of the averaged model's I and J terms.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Coefficients {
    /// Eqs. e:eom … e:eom_last exactly as published: I weighted by (a2²−a1²)/(a1²+a2²).
    #[default]
    Paper,
    /// Leading order (Oseen, shape-driven, far field): I weighted by (a2−a1)/(a1+a2), J by 4a1a2/(a1+a2)².
    LeadingOrder,
}

impl Named for Coefficients {
    const KIND: &'static str = "coefficient set";
    const CHOICES: &'static [Choice<Self>] = &[
        Choice {
            value: Coefficients::Paper,
            name: "paper",
            about: "as published, default",
        },
        Choice {
            value: Coefficients::LeadingOrder,
            name: "leading_order",
            about: "the leading-order ones",
        },
    ];
}

choice::inherent_names!(Coefficients);

/// The 3-vector at `y[i..i+3]`.
#[inline]
pub fn vec3(y: &[f64], i: usize) -> Vector3<f64> {
    Vector3::new(y[i], y[i + 1], y[i + 2])
}

/// Write a 3-vector to `y[i..i+3]`.
#[inline]
pub fn set_vec3(y: &mut [f64], i: usize, v: &Vector3<f64>) {
    y[i..i + 3].copy_from_slice(v.as_slice());
}
