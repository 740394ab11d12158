//! [`Publisher`]: the watcher a view attaches to a simulation. After a step it takes a frame only
//! when the interval since the last one has passed (a clock read and a compare otherwise), and
//! no sooner than nine times the last frame's encoding took, so that encoding a large scene costs
//! a run at most a tenth of its time. At the start and end of a run and when attached it always
//! takes one, so the last frame stays. A change between runs (a swimmer added, a box set) takes
//! one when one is due by the same rule; otherwise the latest change is drawn when the next is
//! due, through a refresh the script layer hands in (a thread waits for the due time), so a
//! script's thousands of changes in a row encode a few frames, not thousands. A
//! [`Pace`] holds a run to a number of periods per second of wall-clock time, for watching.

use super::frame::{encode, latest_rows, Parts, RowSnapshot};
use super::slot::Slot;
use crate::engine::{Look, Recorder, Scene, Watcher};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
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

/// Tells the watched simulation's watcher of its scene as it is now, as a change
/// ([`crate::engine::Simulation::show_change`] under its lock): a change drawn late, when due.
pub type Refresh = Arc<dyn Fn() + Send + Sync>;

/// A change waiting to be drawn, shared with the thread that waits for its due time.
#[derive(Default)]
struct Pending {
    /// A change was made since the last frame.
    stale: AtomicBool,
    /// A thread waits to draw it.
    scheduled: AtomicBool,
}

/// The longest single sleep of the thread that draws a late change, so that it ends soon after
/// its view stops.
const LATE_NAP: Duration = Duration::from_millis(50);

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
    pending: Arc<Pending>,
    refresh: Option<Refresh>,
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
            pending: Arc::default(),
            refresh: None,
        }
    }

    /// Draw a change that was not due when it was made through `refresh`, once it is due.
    /// Without one, such a change shows with the next frame taken (the next change that is
    /// due, or a run).
    pub fn with_refresh(mut self, refresh: Refresh) -> Self {
        self.refresh = Some(refresh);
        self
    }

    /// A thread that waits until the next frame is due (or the view stops) and then draws the
    /// latest change, if no frame has drawn it meanwhile.
    fn schedule_late_frame(&self) {
        let Some(refresh) = self.refresh.clone() else {
            return;
        };
        if self.pending.scheduled.swap(true, Ordering::SeqCst) {
            return;
        }
        let due = self.origin + Duration::from_nanos(self.next_frame.load(Ordering::Relaxed));
        let (pending, slot) = (self.pending.clone(), self.slot.clone());
        let spawned = std::thread::Builder::new()
            .name("swimlab-view-late".into())
            .spawn(move || {
                while Instant::now() < due && !slot.is_closed() {
                    std::thread::sleep(due.saturating_duration_since(Instant::now()).min(LATE_NAP));
                }
                pending.scheduled.store(false, Ordering::SeqCst);
                if !slot.is_closed() && pending.stale.load(Ordering::SeqCst) {
                    refresh();
                }
            });
        if spawned.is_err() {
            self.pending.scheduled.store(false, Ordering::SeqCst);
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
        self.pending.stale.store(false, Ordering::SeqCst);
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

    fn changed(&self, s: &Scene, recorders: &[Recorder]) {
        self.copy_rows(recorders);
        if self.due() {
            self.publish(s);
        } else {
            self.pending.stale.store(true, Ordering::SeqCst);
            self.schedule_late_frame();
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
