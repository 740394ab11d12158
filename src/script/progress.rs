//! A progress bar for long runs at a terminal: periods done, rate and time left, drawn on stderr
//! once a run has lasted half a second, and only when both stdout and stderr are terminals (never
//! into pipes or files). `SWIMLAB_PROGRESS=0` turns it off. It is cleared when the run ends,
//! however it ends (done, error, Ctrl-C).

use crate::engine::stepping::Progress;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Runs shorter than this never show a bar.
const DELAY: Duration = Duration::from_millis(500);

/// Whether bars may be drawn here.
fn enabled() -> bool {
    std::env::var("SWIMLAB_PROGRESS").map_or(true, |v| v != "0")
        && std::io::stdout().is_terminal()
        && std::io::stderr().is_terminal()
}

/// The bar of one run from `t0` to `t_end` (s), counting periods of length `period` (s).
pub struct RunBar {
    bar: Arc<Mutex<Option<ProgressBar>>>,
}

impl RunBar {
    /// A bar and the progress report that feeds it; `None` where bars are not drawn.
    pub fn start(t0: f64, t_end: f64, period: Option<f64>) -> Option<(RunBar, Progress)> {
        if !enabled() || t_end <= t0 {
            return None;
        }
        let bar: Arc<Mutex<Option<ProgressBar>>> = Arc::new(Mutex::new(None));
        let shared = bar.clone();
        let started = Instant::now();
        let (unit, scale) = match period {
            Some(p) if p > 0.0 => ("periods", 1.0 / p),
            _ => ("s", 1.0),
        };
        let total = (t_end - t0) * scale;
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
            let rate = done / elapsed.as_secs_f64();
            let left = if rate > 0.0 {
                (total - done) / rate
            } else {
                f64::INFINITY
            };
            b.set_position((1000.0 * done / total) as u64);
            b.set_message(format!(
                "{done:.1}/{total:.1} {unit}, {rate:.3} {unit}/s, ETA {}",
                if left.is_finite() {
                    format!("{left:.0} s")
                } else {
                    "?".into()
                }
            ));
        });
        Some((RunBar { bar }, report))
    }
}

impl Drop for RunBar {
    fn drop(&mut self) {
        if let Ok(mut slot) = self.bar.lock() {
            if let Some(b) = slot.take() {
                b.finish_and_clear();
            }
        }
    }
}
