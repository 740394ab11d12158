//! The seeded script fuzzers, a binary of their own: a script that runs too long is stopped by
//! the process-wide interrupt (as Ctrl-C would), which would stop any other test's run in the
//! same process. They take turns through the driver's lock.

mod boxes_noise_fields_outputs;
#[path = "../common/mod.rs"]
mod common;
mod driver;
mod script_api;
mod walls_forces_continuum;
