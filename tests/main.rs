//! The integration tests, one binary: each file below is a module about one invariant or API
//! area ([Validation](../docs/src/validation.md) lists them with what each checks). One binary
//! links the crate and its dependencies once instead of once per file; `cargo test --test
//! suite NAME` runs one area (`walls`, `continuum::`, ...; the script fuzzers are `fuzz::`).

mod common;

/// Lavapipe, the Vulkan device of machines without a GPU (CI's), runs every dispatch on a pool of
/// as many threads as there are cores. Beside the suite's own test threads on every core those
/// pools wait on each other at each of the GPU tests' many small dispatches, in the kernel
/// (`LP_NUM_THREADS=0` makes the Fig-1 parity test 18 s → 5.5 s, most of the difference system
/// time). So the suite asks lavapipe to run dispatches on the calling thread, unless the caller
/// chose a number. It is set in the binary's initialiser, before `main` starts a thread: setting
/// the environment while another thread may read it is not sound. A real GPU ignores it.
#[cfg(target_os = "linux")]
#[used]
#[link_section = ".init_array"]
static LAVAPIPE_ON_THE_CALLING_THREAD: extern "C" fn() = {
    extern "C" fn init() {
        if std::env::var_os("LP_NUM_THREADS").is_none() {
            std::env::set_var("LP_NUM_THREADS", "0");
        }
    }
    init
};

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
