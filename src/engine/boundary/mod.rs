//! The boundary of the fluid, one value a scene owns: open space, a periodic box or a no-slip
//! wall below the fluid ([`Boundary`]).
//!
//! What a boundary means for the spheres is its [`Geometry`]: how separations are measured
//! (minimum images), what is solid (gaps, the repulsion that keeps spheres off it, the guard's
//! report of a sphere that touched it), what fits in it (a swimmer meeting its own image) and
//! how far it may reach (the extent positions are held to), and the mobility operator of its
//! fluid. Callers ask the geometry; the one match on the kind is [`Boundary::geometry`]. A new
//! boundary (a slit between two walls, a wall in a box periodic along its plane) is one file
//! here implementing [`Geometry`] and one arm of [`Boundary`].
//!
//! - `kinds.rs`: the [`Boundary`] value, the one match on its kind, and the rule of which kinds
//!   exclude each other;
//! - `geometry.rs`: the [`Geometry`] trait, the [`Extent`] positions are held to and the settings
//!   a boundary's mobility is built from;
//! - `open.rs`, `periodic.rs`, `wall.rs`: the geometry of each kind.

mod geometry;
mod kinds;
mod open;
mod periodic;
mod wall;

pub use geometry::{Extent, Geometry, MobilitySettings, PairTerms, MAX_EXTENT_IN_RADII};
pub use kinds::{Boundary, Kind};
pub use periodic::ewald;
