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

/// Ctrl-C (SIGINT) for a batch run (`swimlab run`, `-e`, `make-figures`): the first one stops
/// the run at its next step boundary, exactly as in the shell, so the script gets the interrupt
/// error and streamed files end on a whole row; a second one ends the process at once (exit 130).
pub fn install_batch_handler() {
    let _ = ctrlc::set_handler(|| {
        if requested() {
            std::process::exit(130);
        }
        request();
        super::console::to_stderr(
            "\nswimlab: stopping at the next step boundary (Ctrl-C again quits at once)\n",
        );
    });
}
