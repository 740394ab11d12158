//! Rhai bindings of the engine: one [`engine()`] builder used by the binary, the REPL, the tests and
//! the examples; one error renderer ([`render_error`]).

mod convert;
mod csv_api;
mod dumbbell_api;
mod engine_builder;
mod float_cmp;
mod integrator_api;
pub mod interrupt;
mod render;
mod scene_api;
mod util_api;

pub use convert::{script_error, ScriptResult};
pub use dumbbell_api::DumbbellSpec;
pub use engine_builder::{engine, run_file, run_source};
pub use render::render_error;
pub use scene_api::SceneHandle;
pub use util_api::quick;
