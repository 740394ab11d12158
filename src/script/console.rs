//! Text that script functions write themselves (a text plot), to standard output or to a front
//! end's own sink (a notebook's stdout stream); values shown by `display(value)`, as text or
//! through a front end's display sink (a notebook shows a picture inline); notes a run gives
//! while it goes on, to standard error or a front end's note sink. Rhai's `print` goes through
//! the session's `on_print`, which a notebook points at the same stream.

use std::io::Write;
use std::sync::{Arc, Mutex};

/// A process-wide slot for a front end's callback (text, displays, progress), empty by default.
pub struct Hook<T>(Mutex<Option<T>>);

impl<T: Clone> Hook<T> {
    /// An empty slot.
    pub const fn new() -> Self {
        Hook(Mutex::new(None))
    }

    /// Put `f` in the slot (or empty it, given `None`).
    pub fn set(&self, f: Option<T>) {
        if let Ok(mut s) = self.0.lock() {
            *s = f;
        }
    }

    /// The callback in the slot, if any.
    pub fn get(&self) -> Option<T> {
        self.0.lock().ok().and_then(|s| s.clone())
    }
}

impl<T: Clone> Default for Hook<T> {
    fn default() -> Self {
        Self::new()
    }
}

/// Where written text goes instead of standard output.
pub type TextSink = Arc<dyn Fn(&str) + Send + Sync>;

static SINK: Hook<TextSink> = Hook::new();

/// Send written text to `sink` (or standard output again, given `None`).
pub fn set_sink(sink: Option<TextSink>) {
    SINK.set(sink);
}

/// Where `display(value)` shows values instead of writing their text.
pub type DisplaySink = Arc<dyn Fn(&rhai::Dynamic) + Send + Sync>;

static DISPLAY: Hook<DisplaySink> = Hook::new();

/// Show `display(value)` values through `sink` (or as text again, given `None`).
pub fn set_display_sink(sink: Option<DisplaySink>) {
    DISPLAY.set(sink);
}

static NOTE: Hook<TextSink> = Hook::new();

/// Send notes (what a run says while it goes on) to `sink` (or standard error again, given
/// `None`).
pub fn set_note_sink(sink: Option<TextSink>) {
    NOTE.set(sink);
}

/// Tell the user `text` as a note ("note: ..." on standard error, or a front end's note sink):
/// not a result, so never on standard output, where it would mix with a script's own output.
pub fn note(text: &str) {
    let line = format!("note: {text}\n");
    match NOTE.get() {
        Some(f) => f(&line),
        None => to_stderr(&line),
    }
}

/// Show `v` now: through the display sink, else as `text` gives it (the shell's text of values).
pub fn display(v: &rhai::Dynamic, text: impl FnOnce(&rhai::Dynamic) -> String) {
    match DISPLAY.get() {
        Some(f) => f(v),
        None => write(&format!("{}\n", text(v))),
    }
}

/// Write `text` as it is (no newline added).
pub fn write(text: &str) {
    match SINK.get() {
        Some(f) => f(text),
        None => to_stdout(text),
    }
}

/// The exit status of a process whose standard output was closed under it: the one a shell
/// gives a process that SIGPIPE ended (128 + 13).
pub const CLOSED_STDOUT_STATUS: i32 = 141;

/// Write `text` to standard output, flushed. When its reader has gone (`swimlab run s.rhai |
/// head -1`), nothing more written could be read: the process ends at once, quietly, with
/// [`CLOSED_STDOUT_STATUS`], as command-line tools do (files written so far are whole: every
/// writer renames or appends whole lines). Any other failure (a full disk) is told once on
/// standard error; the script goes on, its printed text lost.
pub fn to_stdout(text: &str) {
    use std::sync::atomic::{AtomicBool, Ordering};
    static TOLD: AtomicBool = AtomicBool::new(false);
    if let Err(e) = write_stdout(text) {
        if !TOLD.swap(true, Ordering::SeqCst) {
            note(&format!(
                "cannot write standard output ({e}): what the script prints is lost; check where it is redirected"
            ));
        }
    }
}

/// Write `text` to standard output for a command whose output is what it makes (`swimlab
/// reference`, a benchmark's tables, a sweep's lines): as [`to_stdout`] for a reader that went
/// away; any other failure (a full disk) is the command's error, since its output is lost.
pub fn emit(text: &str) -> Result<(), String> {
    write_stdout(text).map_err(|e| {
        format!(
            "error: cannot write standard output ({e}): what this command writes is lost; redirect it to a file on a disk with room\n"
        )
    })
}

/// [`emit`] with a newline.
pub fn emit_line(text: &str) -> Result<(), String> {
    emit(&format!("{text}\n"))
}

/// Write `text` to standard error as it is, never failing: a message that cannot be shown has
/// nowhere else to go (Rust's own `eprint!` would panic).
pub fn to_stderr(text: &str) {
    let mut err = std::io::stderr().lock();
    let _ = err.write_all(text.as_bytes());
    let _ = err.flush();
}

/// Standard output written whole and flushed; a closed reader ends the process (see
/// [`to_stdout`]).
fn write_stdout(text: &str) -> std::io::Result<()> {
    let mut out = std::io::stdout().lock();
    let r = out.write_all(text.as_bytes()).and_then(|()| out.flush());
    if let Err(e) = &r {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(CLOSED_STDOUT_STATUS);
        }
    }
    r
}
