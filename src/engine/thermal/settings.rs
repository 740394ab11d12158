//! A scene's thermal setting: its temperature and seed, and how the square root of the
//! mobility is applied to the noise.

use crate::engine::choice::{self, Choice, Named};
use crate::engine::error::{invalid, require_finite, Result};
use serde::{Deserialize, Serialize};

/// Boltzmann's constant (J/K, exact in the SI since 2019).
pub const BOLTZMANN: f64 = 1.380_649e-23;

/// The Lanczos iteration's default tolerance: the relative change of √M·z between iterations.
/// Its error in the noise's covariance is of this order, far below what any sample resolves.
pub const DEFAULT_LANCZOS_TOL: f64 = 1e-6;

/// Up to this many spheres "auto" takes the dense Cholesky factor, above it Lanczos (measured by
/// `examples/noise_roots.rs`, the book, "Thermal noise").
pub const CHOLESKY_MAX_SPHERES: usize = 48;

/// The highest temperature accepted (K): far above any liquid, low enough that the noise never
/// overflows.
pub const MAX_TEMPERATURE: f64 = 1e6;

/// How the square root B of the mobility (B Bᵀ = M) is applied to the noise.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum NoiseRoot {
    /// Cholesky up to [`CHOLESKY_MAX_SPHERES`] spheres, Lanczos above.
    #[default]
    Auto,
    /// The dense Cholesky factor: exact, O(N³) per step.
    Cholesky,
    /// The Lanczos iteration for √M·ξ on the pair kernel: O(N²) per iteration.
    Lanczos,
}

impl Named for NoiseRoot {
    const KIND: &'static str = "noise root";
    const CHOICES: &'static [Choice<Self>] = &[
        Choice {
            value: NoiseRoot::Auto,
            name: "auto",
            about: "Cholesky for small scenes, Lanczos for large, default",
        },
        Choice {
            value: NoiseRoot::Cholesky,
            name: "cholesky",
            about: "dense Cholesky factor, O(N^3)",
        },
        Choice {
            value: NoiseRoot::Lanczos,
            name: "lanczos",
            about: "matrix-free Krylov square root, O(N^2) per iteration",
        },
    ];
}

choice::inherent_names!(NoiseRoot);

impl NoiseRoot {
    /// Whether a scene of `spheres` spheres takes the dense Cholesky factor.
    pub fn dense_for(self, spheres: usize) -> bool {
        match self {
            NoiseRoot::Auto => spheres <= CHOLESKY_MAX_SPHERES,
            NoiseRoot::Cholesky => true,
            NoiseRoot::Lanczos => false,
        }
    }
}

/// A scene's temperature and the seed of its noise.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Thermal {
    /// Temperature (K); 0: no noise, every result as without this module.
    pub temperature: f64,
    /// Seed of the counter-based generator.
    #[serde(default)]
    pub seed: u64,
    /// How √M·ξ is computed.
    #[serde(default)]
    pub root: NoiseRoot,
    /// Tolerance of the Lanczos iteration.
    #[serde(default = "default_tol")]
    pub lanczos_tol: f64,
}

fn default_tol() -> f64 {
    DEFAULT_LANCZOS_TOL
}

impl Default for Thermal {
    fn default() -> Self {
        Thermal {
            temperature: 0.0,
            seed: 0,
            root: NoiseRoot::Auto,
            lanczos_tol: DEFAULT_LANCZOS_TOL,
        }
    }
}

impl Thermal {
    /// kT (J).
    pub fn kt(&self) -> f64 {
        BOLTZMANN * self.temperature
    }

    /// Whether there is noise (temperature above 0).
    pub fn is_on(&self) -> bool {
        self.temperature > 0.0
    }

    /// Whether every setting is the default (then a saved scene leaves it out).
    pub fn is_default(&self) -> bool {
        *self == Thermal::default()
    }

    /// A temperature (K): finite, from 0 to [`MAX_TEMPERATURE`].
    pub fn check_temperature(t: f64) -> Result<f64> {
        require_finite("temperature", t)?;
        if !(0.0..=MAX_TEMPERATURE).contains(&t) {
            return Err(invalid!(
                "temperature must lie between 0 and {MAX_TEMPERATURE:e} K, got {t} (0 turns the noise off; room temperature is about 300)"
            ));
        }
        Ok(t)
    }

    /// A Lanczos tolerance: in [1e-14, 0.1].
    pub fn check_lanczos_tol(tol: f64) -> Result<f64> {
        require_finite("lanczos_tol", tol)?;
        if !(1e-14..=0.1).contains(&tol) {
            return Err(invalid!(
                "lanczos_tol must lie in [1e-14, 0.1] (the relative change of the square root between iterations), got {tol:e}"
            ));
        }
        Ok(tol)
    }

    /// Check settings read from a file.
    pub fn validate(&self) -> Result<()> {
        Self::check_temperature(self.temperature)?;
        Self::check_lanczos_tol(self.lanczos_tol)?;
        Ok(())
    }
}
