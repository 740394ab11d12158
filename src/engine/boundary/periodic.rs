//! A periodic box's geometry: minimum images, wrapping for what is shown, a swimmer that must
//! not meet its own image, sides within the extent, and Ewald sums as its mobility.

use super::geometry::{Extent, Geometry, MobilitySettings, PairTerms, MAX_EXTENT_IN_RADII};
use crate::engine::error::{invalid, short, Result};
use crate::engine::ewald::Ewald;
use crate::engine::mobility::MobilityOperator;
use crate::engine::periodic::PeriodicBox;
use crate::engine::swimmer::Dumbbell;
use nalgebra::Vector3;

/// The box's periodic mobility, its products by the settings' Ewald method ("auto" resolved for
/// the number of spheres; blocks and matrices are Beenakker's either way).
pub fn ewald(b: &PeriodicBox, settings: &MobilitySettings) -> Result<Ewald> {
    Ewald::with_method(
        *b,
        settings.mu,
        settings.kind,
        settings.spheres,
        settings.ewald_tol,
        settings.ewald_method,
        None,
    )
}

impl Geometry for PeriodicBox {
    fn pair_terms(&self) -> PairTerms {
        PairTerms::MinimumImages(*self)
    }

    fn periodic(&self) -> Option<&PeriodicBox> {
        Some(self)
    }

    fn separation(&self, r: Vector3<f64>) -> Vector3<f64> {
        self.min_image(r)
    }

    fn shown(&self, p: Vector3<f64>) -> Vector3<f64> {
        self.wrap(p)
    }

    /// The box's shortest side above 2(ℓ + λ + a1 + a2): the swimmer never meets its own image.
    fn check_fits(&self, d: &Dumbbell) -> Result<()> {
        let reach = d.ell + d.lambda + d.a1 + d.a2;
        if self.shortest() <= 2.0 * reach {
            return Err(invalid!(
                "a box side of {:e} m is too short for a swimmer of reach ell + lambda + a1 + a2 = {reach:e} m, which would meet its own image; make every side longer than {:e} m",
                self.shortest(),
                2.0 * reach
            ));
        }
        Ok(())
    }

    fn check_cell(&self, extent: &Extent) -> Result<()> {
        let (limit, r) = (extent.limit, extent.radius);
        for (k, l) in ["x", "y", "z"].iter().zip(self.sides()) {
            if l > limit {
                return Err(invalid!(
                    "the box side along {k}, {l:e} m, is longer than the {} m that positions may reach ({MAX_EXTENT_IN_RADII:e} times the smallest sphere radius, {} m): across it f64 no longer resolves the spheres, and wrapping cannot carry them; give sides up to {} m, or no box for open space",
                    short(limit),
                    short(r),
                    short(limit)
                ));
            }
        }
        Ok(())
    }

    fn mobility(&self, settings: &MobilitySettings) -> Result<Box<dyn MobilityOperator>> {
        Ok(Box::new(ewald(self, settings)?))
    }

    fn off_device(&self) -> Option<&'static str> {
        Some("a periodic box (Ewald sums, minimum images)")
    }
}
