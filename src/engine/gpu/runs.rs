//! What a run on the device is asked to do and how it reports: the model it steps, uniform or
//! adaptive steps, and how the run ended.

use crate::engine::mobility::Mobility;
use crate::engine::model::Coefficients;

/// Which model the device steps, with what it needs to know.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GpuModel {
    /// Spheres and springs.
    Micro {
        /// Viscosity (Pa s).
        mu: f64,
        /// Pair tensor.
        mobility: Mobility,
    },
    /// Stroke-averaged R_H and N.
    Averaged {
        /// Coefficient set.
        coefficients: Coefficients,
    },
}

/// How a run on the device ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunOutcome {
    /// All steps done.
    Done,
    /// A guard fired in step `steps_done` (0-based); the state is the one after `steps_done` steps.
    Failed {
        /// Steps committed before the failing one.
        steps_done: u64,
    },
    /// Stopped from outside after `steps_done` steps.
    Interrupted {
        /// Steps committed.
        steps_done: u64,
    },
}

/// `count` steps of size `h` from time `t0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UniformSteps {
    /// Start time (s).
    pub t0: f64,
    /// Step (s).
    pub h: f64,
    /// Number of steps.
    pub count: u64,
}

/// Adaptive steps from `t0` to `t_end`, trying `h` first, at relative tolerance `rtol` of each
/// state component's `scale` (the method is the buffers' embedded tableau).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptiveSteps<'a> {
    /// Start time (s).
    pub t0: f64,
    /// End time (s).
    pub t_end: f64,
    /// The step to try first (s).
    pub h: f64,
    /// Relative tolerance of the error norm.
    pub rtol: f64,
    /// The absolute size of each state component the tolerance refers to.
    pub scale: &'a [f64],
}

/// Where an adaptive run on the device stopped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptiveReport {
    /// How it ended (`steps_done`: accepted steps).
    pub outcome: RunOutcome,
    /// The time of the state read back (s).
    pub t: f64,
    /// The step to try next (s); after a failure, the one the failing step began with.
    pub h: f64,
    /// Accepted steps.
    pub steps: u64,
    /// Rejected attempts (after a failure: not counting the failing step's).
    pub rejected: u64,
}
