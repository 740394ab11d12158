//! The GPU backend: both models stepped on a wgpu device (Vulkan, Metal, DX12) in f64.
//!
//! Layout: [`device`](mod@device) finds and opens an adapter (nothing else touches adapters);
//! each kernel is a pair of files, `name.rs` (host side: pipelines, data layout) and `name.wgsl`
//! (the shader), all sharing `common.rs` and `common.wgsl`; [`kernels`] compiles their pipelines
//! once per device; [`runner`] owns a scene's device buffers on a device handed to it and encodes
//! whole runs of steps, which [`runs`] describes; [`support`] says what the device can run.
//!
//! Design, for real GPUs as much as for the CPU emulation CI has:
//! - the state lives on the device; a run of many steps is encoded into one submission and the
//!   state is read back only at the end of a run segment (a recorder's row or the run's end);
//! - the O(N²) pair sums tile the sources through workgroup memory (64 per tile), so each
//!   source sphere is read from global memory once per workgroup instead of once per thread;
//! - buffers and bind groups are made once per scene size and reused by every step and run;
//! - stage coefficients are tiny per-stage buffers chosen by bind group, so a step costs
//!   dispatches only, no uploads;
//! - the guards (finite state, runaway spring, contact) run on the device into one atomic flag;
//!   once it is set every kernel returns at once, the last good state stays in place, and the host
//!   replays the failing step on the CPU, which reports it exactly as the CPU backend would.

pub mod averaged_rates;
pub mod common;
pub mod device;
pub mod kernels;
pub mod micro_rates;
pub mod rk_stages;
pub mod runner;
pub mod runs;
pub mod support;

pub use common::WORKGROUP;
pub use device::{available, device, quiet_device_selection, GpuDevice};
pub use kernels::Kernels;
pub use runner::{GpuRun, Peek};
pub use runs::{AdaptiveReport, AdaptiveSteps, GpuModel, RunOutcome, UniformSteps};
