//! Which equations move the scene, and the layout of their state vector.
//!
//! Both models keep 6 numbers per swimmer σ at `y[6σ..6σ+6]`:
//! - `y[6σ..6σ+3]`: the displacement ΔR of the hydrodynamic centre from its *base* position (kept
//!   apart in the scene). The net drift per period is ~1e-7 ℓ at D = 10ℓ; adding it to an absolute
//!   position of size ~10ℓ every step would round it at ~1e-15·10ℓ per step, a systematic error of up to
//!   1e-4 of the drift over a period of ~1,000 steps. A displacement stays small and rounds far below.
//! - `y[6σ+3..6σ+6]`: the microscopic model's dumbbell vector b = X₂ − X₁ (m); the averaged model's
//!   unit orientation N, and so the rigid-stroke model's (whose length is L(t)).

use super::error::{invalid, Result};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

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

impl Model {
    /// Parse a user-facing name.
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "micro" => Ok(Model::Micro),
            "averaged" => Ok(Model::Averaged),
            "rigid" => Ok(Model::Rigid),
            other => Err(invalid!(
                "unknown model \"{other}\"; use \"micro\" (spheres and springs, default), \"rigid\" (spheres, lengths prescribed) or \"averaged\" (stroke-averaged R_H and N)"
            )),
        }
    }

    /// The user-facing name.
    pub fn name(self) -> &'static str {
        match self {
            Model::Micro => "micro",
            Model::Averaged => "averaged",
            Model::Rigid => "rigid",
        }
    }
}

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

impl Coefficients {
    /// Parse a user-facing name.
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "paper" => Ok(Coefficients::Paper),
            "leading_order" => Ok(Coefficients::LeadingOrder),
            other => Err(invalid!(
                "unknown coefficient set \"{other}\"; use \"paper\" (as published, default) or \"leading_order\""
            )),
        }
    }

    /// The user-facing name.
    pub fn name(self) -> &'static str {
        match self {
            Coefficients::Paper => "paper",
            Coefficients::LeadingOrder => "leading_order",
        }
    }
}

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
