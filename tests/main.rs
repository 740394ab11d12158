//! The integration tests, one binary: each file below is a module about one invariant or API
//! area ([Validation](../docs/src/validation.md) lists them with what each checks). One binary
//! links the crate and its dependencies once instead of once per file; `cargo test --test
//! suite NAME` runs one area (`walls`, `continuum::`, ...; the script fuzzers are `fuzz::`).

mod common;

mod architecture;
mod averaged_model;
mod bad_input;
mod bad_input_continuum;
mod bad_input_messages;
mod bad_input_placement;
mod bad_input_runs;
mod bad_input_types_limits_files;
mod book;
mod bulk_suspensions;
mod collective;
mod continuum;
mod engine_messages;
mod fields;
mod fuzz;
mod gpu;
mod help_docs;
mod integrator_order;
mod invariance;
mod kernel;
mod long_runs;
mod mobility;
mod pair_kernel;
mod periodic;
mod pictures;
mod recording;
mod repl_pty;
mod repl_session;
mod rigid_stroke;
mod scallop_theorem;
mod script_errors;
mod script_numbers;
mod shipped_scripts;
mod streams_and_signals;
mod stroboscopic;
mod suspensions;
mod sweeps;
mod thermal;
mod trajectories;
mod view;
mod viewers;
mod walls;
