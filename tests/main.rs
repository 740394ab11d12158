//! The integration tests, one binary: each file below is a module about one invariant or API
//! area ([Validation](../docs/src/validation.md) lists them with what each checks). One binary
//! links the crate and its dependencies once instead of once per file; `cargo test --test
//! suite NAME` runs one area (`walls`, `continuum::`, ...; the script fuzzers are `fuzz::`).

mod common;

/// Settings of the suite's environment, made in the binary's initialiser before `main` starts
/// a thread (setting the environment while another thread may read it is not sound), each only
/// where the caller has not chosen:
/// - `RUST_TEST_THREADS`: two test threads more than cores. A dozen tests spend most of their
///   time waiting (on a child process, a socket, a browser, a terminal, a timer), and with one
///   thread per core a core idles whenever one of them runs (the getting-started chapter has the
///   suite's times by thread count). `--test-threads` still overrides.
/// - `LP_NUM_THREADS=0`: lavapipe, the Vulkan device of machines without a GPU (CI's), runs
///   every dispatch on a pool of as many threads as cores; beside the test threads those pools
///   wait on each other in the kernel at each of the GPU tests' many small dispatches, which
///   then cost several times their work, most of it system time. A real GPU ignores it.
#[cfg(target_os = "linux")]
#[used]
#[link_section = ".init_array"]
static SUITE_ENVIRONMENT: extern "C" fn() = {
    extern "C" fn init() {
        if std::env::var_os("RUST_TEST_THREADS").is_none() {
            let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
            std::env::set_var("RUST_TEST_THREADS", (cores + 2).to_string());
        }
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
mod checkpoints;
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
mod study;
mod suspensions;
mod sweeps;
mod thermal;
mod trajectories;
mod view;
mod viewers;
mod walls;
