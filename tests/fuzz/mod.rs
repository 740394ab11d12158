//! The seeded script fuzzers: generated scripts that must neither panic, hang, abort nor show a
//! Rust name. A script that runs too long is stopped by its own interrupt request, as Ctrl-C
//! would stop it (`driver.rs`), which leaves the other tests' runs alone.

mod boxes_noise_fields_outputs;
mod driver;
mod script_api;
mod walls_forces_continuum;
