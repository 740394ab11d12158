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
    /// Beenakker's sums over images and waves: O(N²) per product.
    Beenakker,
    /// Spectral Ewald on an FFT grid: O(N log N) per product.
    Spectral,
}

/// From this many spheres "auto" takes the spectral method: within the crossover that
/// `swimlab bench ewald` measures (the book, "Suspensions, boxes and fields"; the figures are in
/// its design notes).
pub const SPECTRAL_FROM_SPHERES: usize = 700;

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
            about: "sums over images and waves, O(N^2) per product",
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

/// The default tolerance of the Ewald sums (relative to the spheres' Stokes mobility).
pub const DEFAULT_EWALD_TOL: f64 = 1e-10;

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
