//! How the box's mobility products are summed ([`EwaldMethod`]: auto, Beenakker's sums, spectral
//! Ewald), and the tolerance of the sums.

use crate::engine::choice::{self, Choice, Named};
use crate::engine::error::{invalid, Result};
use serde::{Deserialize, Serialize};

/// How the box's mobility products are summed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EwaldMethod {
    /// Beenakker's sums below [`SPECTRAL_FROM_SPHERES`] spheres, the spectral method from there.
    #[default]
    Auto,
    /// Beenakker's sums over the pairs within a cutoff and the waves: O(N^1.5) per product.
    Beenakker,
    /// Spectral Ewald on an FFT grid: O(N log N) per product.
    Spectral,
}

/// From this many spheres "auto" takes the spectral method: within the crossover that
/// `swimlab bench ewald` measures, between 8,000 and 15,625 spheres (the book, "Suspensions,
/// boxes and fields"; the figures are in its design notes).
pub const SPECTRAL_FROM_SPHERES: usize = 12_000;

/// Below this many spheres a run by spectral sums says it costs far more than it need: its grid
/// costs the same whatever the number of spheres, and Beenakker's sums are 4× faster or more
/// there (`swimlab bench ewald`: 4.3× at 216 spheres, 7× at 125).
pub const SPECTRAL_COSTLY_BELOW: usize = 175;

impl Named for EwaldMethod {
    const KIND: &'static str = "Ewald method";
    const CHOICES: &'static [Choice<Self>] = &[
        Choice {
            value: EwaldMethod::Auto,
            name: "auto",
            about: "Beenakker for few spheres, spectral for many, default",
        },
        Choice {
            value: EwaldMethod::Beenakker,
            name: "beenakker",
            about: "pairs within a cutoff and waves, O(N^1.5) per product",
        },
        Choice {
            value: EwaldMethod::Spectral,
            name: "spectral",
            about: "spectral Ewald on an FFT grid, O(N log N) per product",
        },
    ];
}

choice::inherent_names!(EwaldMethod);

impl EwaldMethod {
    /// Beenakker or spectral for `spheres` spheres.
    pub fn resolve(self, spheres: usize) -> Self {
        match self {
            EwaldMethod::Auto if spheres >= SPECTRAL_FROM_SPHERES => EwaldMethod::Spectral,
            EwaldMethod::Auto => EwaldMethod::Beenakker,
            m => m,
        }
    }
}

/// The tolerance of the Ewald sums (relative to the spheres' Stokes mobility) where the run's
/// integrator keeps no drift tolerance (fixed steps: euler, rk4, platen, the noisy defaults).
pub const DEFAULT_EWALD_TOL: f64 = 1e-10;

/// The Ewald tolerance a run with drift tolerance `tol` takes unless one is set: `tol` times
/// this. A run's relative drift error is 1-5 times the sums' tolerance (the book, "What tolerance
/// a run needs"), so a tenth keeps the sums' share of the drift error at most half the run's.
pub const EWALD_TOL_PER_DRIFT_TOL: f64 = 0.1;

/// The Ewald tolerance that serves a run keeping its drift within `drift_tol` (relative), or
/// [`DEFAULT_EWALD_TOL`] for a run that keeps none; within the range [`check_tol`] allows.
pub fn ewald_tol_for(drift_tol: Option<f64>) -> f64 {
    drift_tol.map_or(DEFAULT_EWALD_TOL, |t| {
        (t * EWALD_TOL_PER_DRIFT_TOL).clamp(1e-15, 1e-2)
    })
}

/// The Ewald tolerance must lie in [1e-15, 1e-2].
pub fn check_tol(tol: f64) -> Result<()> {
    if tol.is_finite() && (1e-15..=1e-2).contains(&tol) {
        Ok(())
    } else {
        Err(invalid!(
            "the Ewald tolerance must lie between 1e-15 and 1e-2, got {tol}; e.g. 1e-10"
        ))
    }
}
