//! The user's choice of model ([`Model`]) mapped to its implementation of the model seam
//! ([`SwimmerModel`]), in this one place: the spring model ([`Springs`]), the rigid-stroke limit
//! ([`RigidStrokes`]) and the stroke-averaged model ([`StrokeAveraged`]). A new model is its own
//! file implementing the seam, one choice in [`Model`] and one arm here.

use super::averaged::StrokeAveraged;
use super::micro::Springs;
use super::model::{Model, SwimmerModel};
use super::rigid::RigidStrokes;

/// The implementation of `model`.
pub fn of(model: Model) -> &'static dyn SwimmerModel {
    match model {
        Model::Micro => &Springs,
        Model::Rigid => &RigidStrokes,
        Model::Averaged => &StrokeAveraged,
    }
}
