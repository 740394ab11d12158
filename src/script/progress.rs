//! A progress bar for long runs at a terminal: periods done, rate and time left, drawn on stderr
//! once a run has lasted half a second, and only when both stdout and stderr are terminals (never
//! into pipes or files). `SWIMLAB_PROGRESS=0` turns it off. It is cleared when the run ends,
//! however it ends (done, error, Ctrl-C). A front end of its own (a notebook kernel) sets a
//! [`ProgressSink`] instead, which gets the same line a few times a second and the end.

use crate::engine::stepping::Progress;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Runs shorter than this never show a bar.
const DELAY: Duration = Duration::from_millis(500);

/// The least time between two lines sent to a [`ProgressSink`].
const SINK_INTERVAL: Duration = Duration::from_millis(250);

/// A front end's own progress display: `Some(line)` while a run goes on, `None` when it ended.
pub type ProgressSink = Arc<dyn Fn(Option<&str>) + Send + Sync>;

static SINK: super::console::Hook<ProgressSink> = super::console::Hook::new();

/// Show the progress of long runs through `sink` (or the terminal bar again, given `None`).
pub fn set_sink(sink: Option<ProgressSink>) {
    SINK.set(sink);
}

/// Whether bars may be drawn here.
fn enabled() -> bool {
    std::env::var("SWIMLAB_PROGRESS").map_or(true, |v| v != "0")
        && std::io::stdout().is_terminal()
        && std::io::stderr().is_terminal()
}

/// The progress line: periods (or seconds) done of the total, the rate and the time left.
fn line(done: f64, total: f64, unit: &str, elapsed: Duration) -> String {
    let rate = done / elapsed.as_secs_f64();
    let left = if rate > 0.0 {
        (total - done) / rate
    } else {
        f64::INFINITY
    };
    format!(
        "{done:.1}/{total:.1} {unit}, {rate:.3} {unit}/s, ETA {}",
        if left.is_finite() {
            format!("{left:.0} s")
        } else {
            "?".into()
        }
    )
}

/// The bar of one run from `t0` to `t_end` (s), counting periods of length `period` (s).
pub struct RunBar {
    bar: Arc<Mutex<Option<ProgressBar>>>,
    /// A front end's sink, and whether it was sent a line.
    sink: Option<(ProgressSink, Arc<Mutex<Option<Instant>>>)>,
}

impl RunBar {
    /// A bar and the progress report that feeds it; `None` where bars are not drawn.
    pub fn start(t0: f64, t_end: f64, period: Option<f64>) -> Option<(RunBar, Progress)> {
        if t_end <= t0 {
            return None;
        }
        let (unit, scale) = match period {
            Some(p) if p > 0.0 => ("periods", 1.0 / p),
            _ => ("s", 1.0),
        };
        let total = (t_end - t0) * scale;
        let started = Instant::now();
        let wanted = std::env::var("SWIMLAB_PROGRESS").map_or(true, |v| v != "0");
        if let Some(sink) = SINK.get().filter(|_| wanted) {
            let last: Arc<Mutex<Option<Instant>>> = Arc::new(Mutex::new(None));
            let (to, shared) = (sink.clone(), last.clone());
            let report: Progress = Arc::new(move |t: f64| {
                let elapsed = started.elapsed();
                let Ok(mut last) = shared.lock() else { return };
                if elapsed < DELAY || last.is_some_and(|l| l.elapsed() < SINK_INTERVAL) {
                    return;
                }
                *last = Some(Instant::now());
                let done = ((t - t0) * scale).clamp(0.0, total);
                to(Some(&line(done, total, unit, elapsed)));
            });
            let bar = RunBar {
                bar: Arc::new(Mutex::new(None)),
                sink: Some((sink, last)),
            };
            return Some((bar, report));
        }
        if !enabled() {
            return None;
        }
        let bar: Arc<Mutex<Option<ProgressBar>>> = Arc::new(Mutex::new(None));
        let shared = bar.clone();
        let report: Progress = Arc::new(move |t: f64| {
            let elapsed = started.elapsed();
            if elapsed < DELAY {
                return;
            }
            let Ok(mut slot) = shared.lock() else { return };
            let b = slot.get_or_insert_with(|| {
                let b = ProgressBar::new(1000);
                if let Ok(style) = ProgressStyle::with_template("{bar:30.cyan/blue} {msg}") {
                    b.set_style(style);
                }
                b
            });
            let done = ((t - t0) * scale).clamp(0.0, total);
            b.set_position((1000.0 * done / total) as u64);
            b.set_message(line(done, total, unit, elapsed));
        });
        Some((RunBar { bar, sink: None }, report))
    }
}

/// Run `f` on `target` (a scene or a continuum) with a bar over its next `duration` seconds from
/// `t0`, counted in periods of `period` when given: `set` hands the bar's report to the target
/// before the run and takes it back after (nothing where bars are not drawn).
pub(super) fn with_bar<S, T>(
    target: &mut S,
    t0: f64,
    duration: f64,
    period: Option<f64>,
    set: impl Fn(&mut S, Option<Progress>),
    f: impl FnOnce(&mut S) -> T,
) -> T {
    match RunBar::start(t0, t0 + duration, period) {
        Some((bar, report)) => {
            set(target, Some(report));
            let r = f(target);
            set(target, None);
            drop(bar);
            r
        }
        None => f(target),
    }
}

impl Drop for RunBar {
    fn drop(&mut self) {
        if let Some((sink, last)) = &self.sink {
            if last.lock().is_ok_and(|l| l.is_some()) {
                sink(None);
            }
        }
        if let Ok(mut slot) = self.bar.lock() {
            if let Some(b) = slot.take() {
                b.finish_and_clear();
            }
        }
    }
}
