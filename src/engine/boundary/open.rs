//! Open space: the unbounded fluid, with no images, nothing solid and nothing to fit (the
//! [`Geometry`] defaults), and the RPY or Oseen pairs of [`OpenSpace`] as its mobility.

use super::geometry::{Geometry, MobilitySettings, PairTerms};
use crate::engine::error::Result;
use crate::engine::mobility::MobilityOperator;
use crate::engine::open_space::OpenSpace;

/// The geometry of the unbounded fluid.
#[derive(Debug, Clone, Copy, Default)]
pub struct OpenFluid;

impl Geometry for OpenFluid {
    fn pair_terms(&self) -> PairTerms {
        PairTerms::Open
    }

    fn mobility(&self, settings: &MobilitySettings) -> Result<Box<dyn MobilityOperator>> {
        Ok(Box::new(OpenSpace::new(settings.mu, settings.kind)))
    }
}
