//! What is recorded ([`Observable`]s) kept apart from when ([`Trigger`]): a recorder evaluates its
//! observables only at its trigger's times, never between them, and keeps the rows.

use super::error::{invalid, require_positive, Result};
use super::observable::Observable;
use super::scene::Scene;
use serde::{Deserialize, Serialize};

/// When a recorder takes a row.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Trigger {
    /// Every n periods from the recorder's creation (and at creation).
    EveryPeriods(f64),
    /// Every t seconds from the recorder's creation (and at creation).
    EverySeconds(f64),
    /// At the given absolute times (s).
    AtTimes(Vec<f64>),
    /// At the end of every run.
    AtEnd,
}

impl Trigger {
    /// Check the trigger's parameter.
    pub fn validate(&self) -> Result<()> {
        match self {
            Trigger::EveryPeriods(n) => require_positive("every_periods(n): n", *n, "periods"),
            Trigger::EverySeconds(t) => require_positive("every_seconds(t): t", *t, "s"),
            Trigger::AtTimes(ts) => {
                if ts.iter().any(|t| !t.is_finite()) {
                    return Err(invalid!(
                        "at_times: every time must be a finite number of seconds"
                    ));
                }
                Ok(())
            }
            Trigger::AtEnd => Ok(()),
        }
    }

    /// Human-readable form.
    pub fn describe(&self) -> String {
        match self {
            Trigger::EveryPeriods(n) => format!("every {n} periods"),
            Trigger::EverySeconds(t) => format!("every {t:e} s"),
            Trigger::AtTimes(ts) => format!("at {} given times", ts.len()),
            Trigger::AtEnd => "at the end of each run".into(),
        }
    }
}

/// A recorder: observables, a trigger, and the rows taken so far.
#[derive(Debug, Clone)]
pub struct Recorder {
    /// What is recorded.
    pub observables: Vec<Observable>,
    /// When.
    pub trigger: Trigger,
    /// Origin of periodic triggers (s).
    start: f64,
    /// Interval of periodic triggers (s), resolved at creation.
    interval: Option<f64>,
    /// Index of the next periodic sample (sample k is at start + k·interval).
    next_k: u64,
    /// Rows: time, then every observable's components in order.
    pub rows: Vec<Vec<f64>>,
}

impl Recorder {
    /// A recorder created on `scene` now; periodic triggers take their first row immediately.
    pub fn new(scene: &Scene, observables: Vec<Observable>, trigger: Trigger) -> Result<Self> {
        trigger.validate()?;
        for o in &observables {
            o.check(scene)?;
        }
        let interval = match &trigger {
            Trigger::EveryPeriods(n) => Some(n * scene.period()?),
            Trigger::EverySeconds(t) => Some(*t),
            _ => None,
        };
        let mut r = Recorder {
            observables,
            trigger,
            start: scene.time(),
            interval,
            next_k: 0,
            rows: Vec::new(),
        };
        if r.interval.is_some() {
            r.take(scene)?;
            r.next_k = 1;
        } else if let Trigger::AtTimes(ts) = &r.trigger {
            if ts.contains(&scene.time()) {
                r.take(scene)?;
            }
        }
        Ok(r)
    }

    /// Column names with units: `time [s]`, `R_H[0].x [m]`, ...
    pub fn header(&self) -> Vec<String> {
        let mut h = vec!["time [s]".to_string()];
        for o in &self.observables {
            h.extend(
                o.columns()
                    .into_iter()
                    .map(|c| format!("{c} [{}]", o.unit())),
            );
        }
        h
    }

    /// Column names without units.
    pub fn columns(&self) -> Vec<String> {
        let mut h = vec!["time".to_string()];
        for o in &self.observables {
            h.extend(o.columns());
        }
        h
    }

    /// The next time strictly after `t` at which this recorder wants a row (periodic and
    /// at-times triggers), or `None`.
    pub fn next_due(&self, t: f64) -> Option<f64> {
        match (&self.trigger, self.interval) {
            (_, Some(dt)) => Some(self.start + self.next_k as f64 * dt),
            (Trigger::AtTimes(ts), _) => ts.iter().copied().filter(|x| *x > t).reduce(f64::min),
            _ => None,
        }
    }

    /// Take rows due at the scene's current time (after a run segment ended there).
    pub fn fire(&mut self, scene: &Scene, end_of_run: bool) -> Result<()> {
        let t = scene.time();
        let due = match (&self.trigger, self.interval) {
            (_, Some(dt)) => t >= self.start + self.next_k as f64 * dt,
            (Trigger::AtTimes(ts), _) => ts.contains(&t),
            (Trigger::AtEnd, _) => end_of_run,
            _ => false,
        };
        if due {
            self.take(scene)?;
        }
        if let Some(dt) = self.interval {
            // Skip samples a run already passed (never two rows at one time).
            while self.start + self.next_k as f64 * dt <= t {
                self.next_k += 1;
            }
        }
        Ok(())
    }

    fn take(&mut self, scene: &Scene) -> Result<()> {
        let mut row = vec![scene.time()];
        for o in &self.observables {
            row.extend(o.evaluate(scene)?);
        }
        self.rows.push(row);
        Ok(())
    }

    /// Write the rows as CSV with a header carrying names and units.
    pub fn write_csv(&self, path: &std::path::Path) -> Result<()> {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .map_err(|e| invalid!("cannot create folder {}: {e}", dir.display()))?;
        }
        let err = |e: csv::Error| invalid!("cannot write {}: {e}", path.display());
        let mut w = csv::Writer::from_path(path).map_err(err)?;
        w.write_record(self.header()).map_err(err)?;
        for row in &self.rows {
            w.write_record(row.iter().map(|v| format!("{v:?}")))
                .map_err(err)?;
        }
        w.flush()
            .map_err(|e| invalid!("cannot write {}: {e}", path.display()))
    }
}
