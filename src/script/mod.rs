//! Rhai bindings of the engine: one [`engine()`] builder used by the binary, the REPL, the tests and
//! the examples; one error renderer ([`render_error`]).

mod checkpoint_api;
mod collective_api;
pub mod console;
mod continuum_api;
mod convert;
mod csv_api;
mod doc;
pub mod docs;
mod dumbbell_api;
mod engine_builder;
mod field_api;
pub mod figures;
mod float_cmp;
mod integrator_api;
pub mod interrupt;
pub mod limits;
mod observable_api;
mod panic_guard;
pub mod params;
mod picture_api;
mod plot_api;
pub mod progress;
mod render;
mod run_api;
mod scene_api;
mod scene_settings_api;
mod show;
mod signatures;
mod source;
pub mod stdlib;
mod sweep_api;
mod types;
mod util_api;
pub use util_api::shell_quote;
pub mod view_api;
mod wall_api;
mod wrong_calls;

pub use convert::{engine_message, script_error, setting_in_script, ScriptResult};

/// The documented name closest to `word`, for "did you mean".
pub fn suggest_name(word: &str) -> Option<&'static str> {
    let names: Vec<&'static str> = docs::DOCS.iter().map(|d| d.name).collect();
    convert::suggest(word, &names)
}
pub use crate::engine::files::write_atomically;
pub use crate::engine::gpu::quiet_device_selection;
pub use dumbbell_api::DumbbellSpec;
pub use engine_builder::{
    engine, engine_and_stdlib, eval_expression, run_file, run_file_with, run_source,
    run_source_with,
};
pub use observable_api::RecorderHandle;
pub use panic_guard::guard;
pub use picture_api::Picture;
pub use render::render_error;
pub use scene_api::SceneHandle;
pub use show::show;
pub use source::{read_text, strip_bom, MAX_SOURCE_BYTES};
pub use types::type_word;
pub use util_api::quick;
