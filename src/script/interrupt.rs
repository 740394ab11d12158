//! The interrupt request (Ctrl-C): runs stop at the next clean step boundary.
//!
//! One request is process-wide: Ctrl-C and a kernel's interrupt set it. A front end that runs
//! several scripts at once gives each its own [`Interrupt`] through [`scoped`]: the engine's
//! statement check, scenes, continua and sweeps take the request current on the thread that
//! builds or starts them, so one script's interrupt stops that script alone.

use std::cell::RefCell;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, LazyLock};

/// One interrupt request: set to stop, cleared when an evaluation starts.
#[derive(Clone, Default)]
pub struct Interrupt(Arc<AtomicBool>);

impl Interrupt {
    /// A request of its own, not the process's.
    pub fn new() -> Self {
        Self::default()
    }

    /// Ask the runs under this request to stop at their next step boundary.
    pub fn request(&self) {
        self.0.store(true, Ordering::SeqCst);
    }

    /// Whether a stop was asked (and not yet cleared).
    pub fn requested(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }

    /// Forget a pending request.
    pub fn clear(&self) {
        self.0.store(false, Ordering::SeqCst);
    }
}

static PROCESS: LazyLock<Interrupt> = LazyLock::new(Interrupt::new);

thread_local! {
    static SCOPED: RefCell<Option<Interrupt>> = const { RefCell::new(None) };
}

/// The request current on this thread: the one [`scoped`] set, else the process's.
pub fn current() -> Interrupt {
    SCOPED
        .with(|s| s.borrow().clone())
        .unwrap_or_else(|| PROCESS.clone())
}

/// Run `f` with `interrupt` as this thread's current request (the previous one back after it,
/// also when `f` panics).
pub fn scoped<R>(interrupt: &Interrupt, f: impl FnOnce() -> R) -> R {
    struct Restore(Option<Interrupt>);
    impl Drop for Restore {
        fn drop(&mut self) {
            let previous = self.0.take();
            SCOPED.with(|s| *s.borrow_mut() = previous);
        }
    }
    let previous = SCOPED.with(|s| s.borrow_mut().replace(interrupt.clone()));
    let _restore = Restore(previous);
    f()
}

/// Ask the current request's runs to stop at their next step boundary.
pub fn request() {
    current().request();
}

/// Whether the current request was made (and not yet cleared).
pub fn requested() -> bool {
    current().requested()
}

/// Forget the current request's pending stop (at the start of each evaluation).
pub fn clear() {
    current().clear();
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
