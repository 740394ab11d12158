//! Text that script functions write themselves (a text plot), to standard output or to a front
//! end's own sink (a notebook's stdout stream); values shown by `display(value)`, as text or
//! through a front end's display sink (a notebook shows a picture inline). Rhai's `print` goes
//! through the session's `on_print`, which a notebook points at the same stream.

use std::io::Write;
use std::sync::{Arc, Mutex};

/// Where written text goes instead of standard output.
pub type TextSink = Arc<dyn Fn(&str) + Send + Sync>;

static SINK: Mutex<Option<TextSink>> = Mutex::new(None);

/// Send written text to `sink` (or standard output again, given `None`).
pub fn set_sink(sink: Option<TextSink>) {
    if let Ok(mut s) = SINK.lock() {
        *s = sink;
    }
}

/// Where `display(value)` shows values instead of writing their text.
pub type DisplaySink = Arc<dyn Fn(&rhai::Dynamic) + Send + Sync>;

static DISPLAY: Mutex<Option<DisplaySink>> = Mutex::new(None);

/// Show `display(value)` values through `sink` (or as text again, given `None`).
pub fn set_display_sink(sink: Option<DisplaySink>) {
    if let Ok(mut s) = DISPLAY.lock() {
        *s = sink;
    }
}

/// Show `v` now: through the display sink, else as the shell shows values.
pub fn display(v: &rhai::Dynamic) {
    let sink = DISPLAY.lock().ok().and_then(|s| s.clone());
    match sink {
        Some(f) => f(v),
        None => write(&format!("{}\n", super::show(v))),
    }
}

/// Write `text` as it is (no newline added).
pub fn write(text: &str) {
    let sink = SINK.lock().ok().and_then(|s| s.clone());
    match sink {
        Some(f) => f(text),
        None => {
            let mut out = std::io::stdout().lock();
            let _ = out.write_all(text.as_bytes());
            let _ = out.flush();
        }
    }
}
