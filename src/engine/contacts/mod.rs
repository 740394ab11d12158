//! Close approaches between swimmers: whether spheres of different swimmers may overlap, and an
//! optional short-range steric repulsion that keeps them apart.
//!
//! By default a run stops when two spheres touch (the guard of [`super::spheres`]). With
//! `allow_overlap`, spheres of *different* swimmers may overlap: the RPY mobility switches to the
//! overlapping-sphere form of Zuk et al. (2014), which stays positive definite, so the dynamics
//! stay well posed. A dumbbell's own two spheres overlapping still stops the run (its spring has
//! collapsed). The steric repulsion is a soft harmonic wall between spheres of different
//! swimmers: F = k (δ − gap) r̂ for gap < δ, zero beyond, pushing the spheres apart; it is a
//! pair force (momentum is conserved) and costs an O(N²) pass per right-hand side, paid only
//! when it is on. The averaged model places its swimmers' spheres at length ℓ for both (see
//! [`super::averaged::AveragedSystem::set_contacts`]).
//!
//! The scene's setting in `settings` ([`Contacts`], [`Overlaps`]); the repulsion's law, bodies
//! and sphere forces in `steric`; the repulsion between rods in `rods`.

mod rods;
mod settings;
mod steric;

pub use settings::{Contacts, Overlaps};
pub use steric::{Steric, StericBody, StericLaw};
