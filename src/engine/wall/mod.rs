//! A no-slip plane wall z = z0 below the fluid: its hydrodynamics (the Rotne-Prager-Blake
//! mobility, [`WallMobility`]) and its body (a steric repulsion that keeps spheres above it).
//!
//! - `plane.rs`: [`Wall`], the plane and its repulsion;
//! - `operator.rs`: [`WallMobility`], the mobility above it;
//! - `rpb.rs`: the Rotne-Prager-Blake wall correction;
//! - `lanes.rs`: its pair terms over all pairs in vector lanes, the product's kernel.

mod lanes;
mod operator;
mod plane;
pub mod rpb;

pub(crate) use lanes::image_coefficients;
pub use operator::WallMobility;
pub use plane::{Wall, DEFAULT_WALL_RANGE, DEFAULT_WALL_STIFFNESS};
