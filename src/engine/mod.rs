//! The physics and numerics of swimlab: no scripting, no terminal.
//!
//! A [`Scene`] holds [`Dumbbell`] swimmers, the fluid viscosity, the [`Model`] that moves them
//! (microscopic spheres and springs, or stroke-averaged R_H and N), the [`Mobility`] tensor and an
//! [`IntegratorSpec`]. All quantities are SI.

pub mod averaged;
pub mod backend;
pub mod build;
pub mod choice;
pub mod contacts;
pub mod error;
pub mod files;
pub mod gpu;
pub mod integrators;
pub mod micro;
pub mod mobility;
pub mod model;
pub mod observable;
pub mod pairs;
pub mod recorder;
pub mod rigid;
pub mod scene;
mod spheres;
pub mod swimmer;

pub use backend::Backend;
pub use contacts::{Contacts, Steric};
pub use error::{EngineError, Result};
pub use integrators::IntegratorSpec;
pub use mobility::Mobility;
pub use model::{Coefficients, Model};
pub use observable::Observable;
pub use recorder::{Recorder, Trigger};
pub use scene::Scene;
pub use swimmer::Dumbbell;
