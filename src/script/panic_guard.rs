//! The last line of defence at the script boundary: a panic inside an evaluation (a bug in
//! swimlab, never the user's fault) becomes an internal error naming where it happened, and the
//! session, its scenes and their recorded rows live on.
//!
//! Scenes are behind locks that read through poisoning (every change to a scene is made whole or
//! not at all), so a scene touched by the failed call is still usable.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Evaluations under a guard right now (the hook stays quiet while there are any).
static GUARDED: AtomicUsize = AtomicUsize::new(0);
/// What the last panic said and where (file:line of the Rust code).
static LAST: Mutex<Option<String>> = Mutex::new(None);

fn install_hook() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let default = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            let msg = info
                .payload()
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| info.payload().downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "(no message)".into());
            let at = info
                .location()
                .map(|l| format!(" at {}:{}", l.file(), l.line()))
                .unwrap_or_default();
            if let Ok(mut last) = LAST.lock() {
                *last = Some(format!("{msg}{at}"));
            }
            if GUARDED.load(Ordering::SeqCst) == 0 {
                default(info);
            }
        }));
    });
}

/// Run `f`; a panic inside it is returned as an internal error about `what` (e.g. the input's
/// name) instead of unwinding further.
pub fn guard<T>(what: &str, f: impl FnOnce() -> Result<T, String>) -> Result<T, String> {
    install_hook();
    GUARDED.fetch_add(1, Ordering::SeqCst);
    let result = catch_unwind(AssertUnwindSafe(f));
    GUARDED.fetch_sub(1, Ordering::SeqCst);
    result.unwrap_or_else(|_| {
        let detail = LAST
            .lock()
            .ok()
            .and_then(|mut l| l.take())
            .unwrap_or_else(|| "(no message)".into());
        Err(format!(
            "error: {what}: internal error, a bug in swimlab (please report it with this input): {detail}; the session, its scenes and their recorded rows are kept\n"
        ))
    })
}
