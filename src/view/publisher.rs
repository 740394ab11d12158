//! [`Publisher`]: the watcher a view attaches to a simulation. After a step it takes a frame only
//! when the interval since the last one has passed (a clock read and a compare otherwise), and
//! no sooner than nine times the last frame's encoding took, so that encoding a large scene costs
//! a run at most a tenth of its time. At the start and end of a run and when attached it always
//! takes one, so the last frame stays. A
//! [`Pace`] holds a run to a number of periods per second of wall-clock time, for watching.

use super::frame::{encode, latest_rows, Parts, RowSnapshot};
use super::slot::Slot;
use crate::engine::{Look, Recorder, Scene, Watcher};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Runs held to at most `seconds_per_second` of simulated time per second of wall-clock time;
/// while a run waits for the clock it asks `stop` (every few milliseconds) whether to go on.
#[derive(Clone)]
pub struct Pace {
    /// Simulated seconds per wall-clock second.
    pub seconds_per_second: f64,
    /// Whether the run should stop waiting (an interrupt): the next step boundary then stops it.
    pub stop: Arc<dyn Fn() -> bool + Send + Sync>,
}

/// The longest single sleep of a paced run, so that an interrupt is seen promptly.
const PACE_NAP: Duration = Duration::from_millis(20);

/// A paced run sleeps only when it is ahead of the clock by more than this.
const PACE_SLACK: Duration = Duration::from_millis(2);

/// The watcher that publishes a simulation's frames into a [`Slot`]. See the [module docs](self).
pub struct Publisher {
    slot: Arc<Slot>,
    parts: Parts,
    every: Duration,
    pace: Option<Pace>,
    origin: Instant,
    /// Nanoseconds after `origin` when the next frame is due.
    next_frame: AtomicU64,
    /// Nanoseconds after `origin` when the rows are next copied.
    next_rows: AtomicU64,
    rows: Mutex<Vec<RowSnapshot>>,
    /// Where the run's pace counts from: wall-clock and scene time at the run's start.
    pace_origin: Mutex<Option<(Instant, f64)>>,
}

impl Publisher {
    /// A publisher into `slot` of `parts`, one frame per `every` at most, runs held to `pace`.
    pub fn new(slot: Arc<Slot>, parts: Parts, every: Duration, pace: Option<Pace>) -> Self {
        Publisher {
            slot,
            parts,
            every,
            pace,
            origin: Instant::now(),
            next_frame: AtomicU64::new(0),
            next_rows: AtomicU64::new(0),
            rows: Mutex::new(Vec::new()),
            pace_origin: Mutex::new(None),
        }
    }

    fn now(&self) -> u64 {
        self.origin.elapsed().as_nanos() as u64
    }

    /// Whether the interval `next` counts down has passed; if so it starts again from now.
    fn interval_passed(&self, next: &AtomicU64) -> bool {
        let now = self.now();
        if now < next.load(Ordering::Relaxed) {
            return false;
        }
        next.store(now + self.every.as_nanos() as u64, Ordering::Relaxed);
        true
    }

    /// Encode and publish the frame of `s`; the next frame is due after the interval, and after
    /// nine times this one's cost.
    fn publish(&self, s: &Scene) {
        let started = self.now();
        let rows = self.rows.lock().unwrap_or_else(|e| e.into_inner());
        let frame = encode(s, &rows, self.parts);
        drop(rows);
        self.slot.publish(frame);
        let now = self.now();
        let gap = (self.every.as_nanos() as u64).max(9 * (now - started));
        self.next_frame.store(now + gap, Ordering::Relaxed);
    }

    fn copy_rows(&self, recorders: &[Recorder]) {
        if self.parts.rows {
            *self.rows.lock().unwrap_or_else(|e| e.into_inner()) = latest_rows(recorders);
        }
    }
}

impl Look for Publisher {
    fn due(&self) -> bool {
        self.now() >= self.next_frame.load(Ordering::Relaxed)
    }

    fn look(&self, s: &Scene) {
        self.publish(s);
    }

    /// Sleep while the run is ahead of its pace.
    fn pace(&self, time: f64) {
        let Some(pace) = &self.pace else { return };
        let Some((wall0, t0)) = *self.pace_origin.lock().unwrap_or_else(|e| e.into_inner()) else {
            return;
        };
        let target = (time - t0) / pace.seconds_per_second;
        if !target.is_finite() || target <= 0.0 {
            return;
        }
        let target = wall0 + Duration::from_secs_f64(target.min(1e9));
        loop {
            let now = Instant::now();
            if now + PACE_SLACK >= target || (pace.stop)() {
                return;
            }
            std::thread::sleep((target - now).min(PACE_NAP));
        }
    }
}

impl Watcher for Publisher {
    fn recorded(&self, recorders: &[Recorder]) {
        if self.parts.rows && self.interval_passed(&self.next_rows) {
            self.copy_rows(recorders);
        }
    }

    fn settled(&self, s: &Scene, recorders: &[Recorder]) {
        self.copy_rows(recorders);
        self.publish(s);
        // A run begins or ends here: the pace counts from now.
        *self.pace_origin.lock().unwrap_or_else(|e| e.into_inner()) =
            Some((Instant::now(), s.time()));
    }
}
