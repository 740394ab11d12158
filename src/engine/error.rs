//! Errors the engine reports. Each names the problem and, where there is one, the fix.

use thiserror::Error;

/// Everything that can go wrong in the engine.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum EngineError {
    /// A parameter or argument is out of its domain.
    #[error("{0}")]
    Invalid(String),
    /// A step produced a bad state (NaN/inf or overlapping spheres); the scene kept the last good one.
    #[error(
        "the run stopped at t = {time:.6e} s: {cause}; the scene keeps the last good state (t = {last_good:.6e} s). Likely fix: {hint}"
    )]
    StepFailed {
        /// Time at which the bad state was produced.
        time: f64,
        /// Time of the state the scene kept.
        last_good: f64,
        /// Swimmer (0-based) where the problem was found, if one can be named.
        swimmer: Option<usize>,
        /// What went wrong.
        cause: String,
        /// What to change.
        hint: String,
    },
    /// The run was interrupted from outside (Ctrl-C) at a clean step boundary.
    #[error("run interrupted at t = {time:.6e} s; the scene keeps the state at that time")]
    Interrupted {
        /// Time at which the run stopped.
        time: f64,
    },
}

/// Shorthand for engine results.
pub type Result<T> = std::result::Result<T, EngineError>;

/// Build an [`EngineError::Invalid`] from a format string.
macro_rules! invalid {
    ($($arg:tt)*) => { $crate::engine::error::EngineError::Invalid(format!($($arg)*)) };
}
pub(crate) use invalid;

/// Require that `value` is finite and strictly positive.
pub fn require_positive(name: &str, value: f64, unit: &str) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(invalid!(
            "{name} must be a finite positive number ({unit}), got {value}"
        ))
    }
}

/// Require that `value` is finite.
pub fn require_finite(name: &str, value: f64) -> Result<()> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(invalid!("{name} must be a finite number, got {value}"))
    }
}
