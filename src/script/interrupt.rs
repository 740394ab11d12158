//! The process-wide interrupt request (Ctrl-C): runs stop at the next clean step boundary.

use std::sync::atomic::{AtomicBool, Ordering};

static REQUESTED: AtomicBool = AtomicBool::new(false);

/// Ask running simulations to stop at their next step boundary.
pub fn request() {
    REQUESTED.store(true, Ordering::SeqCst);
}

/// Whether an interrupt was requested (and not yet cleared).
pub fn requested() -> bool {
    REQUESTED.load(Ordering::Relaxed)
}

/// Forget a pending request (at the start of each evaluation).
pub fn clear() {
    REQUESTED.store(false, Ordering::SeqCst);
}
