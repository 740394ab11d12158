//! The physics and numerics of swimlab: no scripting, no terminal.
//!
//! A [`Scene`] holds [`Dumbbell`] swimmers, the fluid viscosity, the [`Model`] that moves them
//! (microscopic spheres and springs, or stroke-averaged R_H and N), the [`Mobility`] tensor and an
//! [`IntegratorSpec`]: state and settings. A [`Simulation`] owns a scene and runs it: recorders,
//! the stepper and device buffers, interrupt and progress. All quantities are SI.

pub(crate) mod advance;
pub mod averaged;
pub(crate) mod backend;
pub(crate) mod boundary;
pub mod build;
pub(crate) mod calibrate;
pub(crate) mod cells;
pub(crate) mod cg;
pub mod checkpoint;
pub mod choice;
pub(crate) mod contacts;
pub mod continuum;
pub mod effective_diffusion;
pub mod error;
pub mod ewald;
pub(crate) mod fft3;
pub mod fields;
pub mod files;
pub mod forces;
pub mod gaps;
pub mod gpu;
pub mod integrators;
pub mod micro;
pub mod mobility;
pub(crate) mod model;
pub(crate) mod models;
pub mod neighbours;
pub(crate) mod observable;
pub(crate) mod open_space;
pub mod pair_correlation;
pub mod pairs;
mod parallel;
pub mod periodic;
pub mod plan;
pub(crate) mod recorder;
pub mod rigid;
pub mod rng;
pub(crate) mod scene;
pub(crate) mod simd;
pub(crate) mod simulation;
mod spheres;
pub(crate) mod stepping;
pub mod structure;
pub mod swimmer;
pub mod tensions;
pub mod thermal;
pub(crate) mod trajectory;
mod vtk;
pub mod wall;

pub use backend::Backend;
pub use contacts::{Contacts, Overlaps, Steric, StericBody, StericLaw};
pub use error::{compact_numbers, EngineError, Result};
pub use integrators::IntegratorSpec;
pub use mobility::Mobility;
pub use model::{Coefficients, Model};
pub use observable::Observable;
pub use recorder::{Recorder, Trigger};
pub use scene::{Scene, DEFAULT_AUTO_TOL};
pub use simulation::{Simulation, Watcher};
pub use stepping::{Look, RunControl};
pub use swimmer::Dumbbell;
