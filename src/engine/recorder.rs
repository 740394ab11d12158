//! What is recorded ([`Observable`]s) kept apart from when ([`Trigger`]): a recorder evaluates its
//! observables only at its trigger's times, never between them, and keeps the rows.

use super::advance::Probe;
use super::error::{invalid, require_positive, Result};
use super::files::{write_atomically, LineStream};
use super::integrators::require_resolvable;
use super::observable::Observable;
use super::scene::Scene;
use super::stepping::{RunControl, Workspace};
use super::trajectory::Trajectory;
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
            Trigger::EveryPeriods(n) if (1e-3..1e6).contains(n) => format!("every {n} periods"),
            Trigger::EveryPeriods(n) => format!("every {n:e} periods"),
            Trigger::EverySeconds(t) => format!("every {t:e} s"),
            Trigger::AtTimes(ts) => format!("at {} given times", ts.len()),
            Trigger::AtEnd => "at the end of each run".into(),
        }
    }
}

impl std::fmt::Display for Trigger {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.describe())
    }
}

/// Most rows one run may add to one recorder. Rows are kept in memory (and `rec.rows` turns them
/// into script maps), so a trigger far finer than the run needs is refused before the run starts,
/// with the numbers; a longer recording is split into several runs.
pub const MAX_ROWS_PER_RUN: f64 = 1e7;

const RECORD_LESS_OFTEN: &str = "record less often (a larger every_periods(n) or every_seconds(t))";

/// A recorder: observables, a trigger, and the rows taken so far.
#[derive(Debug)]
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
    /// Where each new row is also appended as CSV, if anywhere.
    stream: Option<LineStream>,
    /// The trajectory that takes a frame with every row, if this recorder writes one.
    frames: Option<Trajectory>,
}

impl Recorder {
    /// A recorder created on `scene` now; periodic triggers take their first row immediately.
    pub fn new(scene: &Scene, observables: Vec<Observable>, trigger: Trigger) -> Result<Self> {
        let mut ws = Workspace::default();
        Self::start(
            scene,
            observables,
            trigger,
            &mut Probe::new(&mut ws, &RunControl::default()),
        )
    }

    /// [`Recorder::new`], its first row's probe runs (if any) made by `probe`.
    pub fn start(
        scene: &Scene,
        observables: Vec<Observable>,
        trigger: Trigger,
        probe: &mut Probe,
    ) -> Result<Self> {
        Self::start_with(scene, observables, trigger, None, probe)
    }

    /// A recorder that writes a frame of `trajectory` with every row (its rows hold the times of
    /// the frames): the trajectory shares the recorders' triggers.
    pub fn start_trajectory(
        scene: &Scene,
        trajectory: Trajectory,
        trigger: Trigger,
        probe: &mut Probe,
    ) -> Result<Self> {
        Self::start_with(scene, Vec::new(), trigger, Some(trajectory), probe)
    }

    fn start_with(
        scene: &Scene,
        observables: Vec<Observable>,
        trigger: Trigger,
        frames: Option<Trajectory>,
        probe: &mut Probe,
    ) -> Result<Self> {
        trigger.validate()?;
        for o in &observables {
            o.check(scene)?;
        }
        let interval = match &trigger {
            Trigger::EveryPeriods(n) => Some(n * scene.period()?),
            Trigger::EverySeconds(t) => Some(*t),
            _ => None,
        };
        if let Some(dt) = interval {
            require_resolvable(
                &format!(
                    "a recorder {} (an interval of {dt:e} s)",
                    trigger.describe()
                ),
                dt,
                scene.time(),
                RECORD_LESS_OFTEN,
            )?;
        }
        let mut r = Recorder {
            observables,
            trigger,
            start: scene.time(),
            interval,
            next_k: 0,
            rows: Vec::new(),
            stream: None,
            frames,
        };
        if r.interval.is_some() {
            r.take(scene, probe)?;
            r.next_k = 1;
        } else if let Trigger::AtTimes(ts) = &r.trigger {
            if ts.contains(&scene.time()) {
                r.take(scene, probe)?;
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
    pub fn fire(&mut self, scene: &Scene, end_of_run: bool, probe: &mut Probe) -> Result<()> {
        let t = scene.time();
        let due = match (&self.trigger, self.interval) {
            (_, Some(dt)) => t >= self.start + self.next_k as f64 * dt,
            (Trigger::AtTimes(ts), _) => ts.contains(&t),
            (Trigger::AtEnd, _) => end_of_run,
            _ => false,
        };
        if due {
            self.take(scene, probe)?;
        }
        if let Some(dt) = self.interval {
            // Skip samples a run already passed (never two rows at one time), in O(1): the
            // interval is resolvable at t (checked by `check_run`), so the loop is short.
            // One below the estimate, so the loop finds the same first sample as counting up
            // from next_k would, whatever the rounding of the division.
            let k = ((t - self.start) / dt).floor() - 1.0;
            if k.is_finite() && k >= 0.0 {
                self.next_k = self.next_k.max(k as u64);
            }
            while self.start + self.next_k as f64 * dt <= t {
                self.next_k += 1;
            }
        }
        Ok(())
    }

    /// This recorder in words, for messages: "the trajectory out/t.xyz", "the recorder of
    /// R_H[0].x, R_H[0].y", or "the recorder of times only".
    fn name(&self) -> String {
        if let Some(t) = &self.frames {
            return format!("the trajectory {}", t.path().display());
        }
        match self.columns().get(1..) {
            Some(c) if !c.is_empty() => format!("the recorder of {}", c.join(", ")),
            _ => "the recorder of times only".into(),
        }
    }

    /// Refuse, before a run from `t0` to `t_end`, a periodic trigger that the run cannot resolve
    /// or that would add more than [`MAX_ROWS_PER_RUN`] rows.
    pub fn check_run(&self, t0: f64, t_end: f64) -> Result<()> {
        let Some(dt) = self.interval else {
            return Ok(());
        };
        let scale = t0.abs().max(t_end.abs()).max(self.start.abs());
        require_resolvable(
            &format!(
                "{} ({}, an interval of {dt:e} s)",
                self.name(),
                self.trigger.describe()
            ),
            dt,
            scale,
            RECORD_LESS_OFTEN,
        )?;
        let rows = (t_end - t0) / dt;
        if rows > MAX_ROWS_PER_RUN {
            let values = rows * self.columns().len() as f64;
            return Err(invalid!(
                "this run would add {rows:.3e} rows to {} ({}), about {:.1} GB in memory; the limit is {MAX_ROWS_PER_RUN:e} rows per run: record less often, or split the run into shorter runs",
                self.name(),
                self.trigger.describe(),
                values * 8e-9
            ));
        }
        Ok(())
    }

    fn take(&mut self, scene: &Scene, probe: &mut Probe) -> Result<()> {
        let mut row = vec![scene.time()];
        for o in &self.observables {
            row.extend(o.measure(scene, probe)?);
        }
        // The row is kept in memory even if its line cannot be written.
        let streamed = match &mut self.stream {
            Some(s) => s.append(&csv_line(row.iter().map(f64_field))),
            None => Ok(()),
        };
        self.rows.push(row);
        streamed?;
        match &mut self.frames {
            Some(t) => t.write_frame(scene),
            None => Ok(()),
        }
    }

    /// Stream rows to `path` as CSV from now on: the file is created with the header and every
    /// row taken so far, then each new row is appended (one whole line, unbuffered) as it is
    /// taken. A kill loses no row already recorded; a later `stream_csv` moves the stream.
    /// `retiring` is the owner's flag ([`super::files::Claim::take`]).
    pub fn stream_csv(
        &mut self,
        path: &std::path::Path,
        retiring: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    ) -> Result<()> {
        super::files::check_csv_name(path, "stream_csv")?;
        let mut lines = vec![csv_line(self.header())];
        lines.extend(self.rows.iter().map(|r| csv_line(r.iter().map(f64_field))));
        // Moved onto the file it writes already: that claim is this recorder's own.
        if self.stream.as_ref().is_some_and(|s| s.is_at(path)) {
            self.stream = None;
        }
        self.stream = Some(LineStream::create(
            path,
            &lines,
            "a recorder's CSV stream",
            retiring,
        )?);
        Ok(())
    }

    /// What a checkpoint keeps of this recorder ([`RecorderMark`]); a trajectory's frames cannot
    /// be taken back after a kill, so a trajectory is refused.
    pub fn mark(&self) -> Result<RecorderMark> {
        self.check_resumable()?;
        Ok(RecorderMark {
            columns: self.columns(),
            trigger: self.trigger.clone(),
            start: self.start,
            next_k: self.next_k,
            rows: self
                .rows
                .iter()
                .map(|r| csv_line(r.iter().map(f64_field)))
                .collect(),
        })
    }

    /// Refuse a recorder a checkpoint cannot carry: a trajectory, whose frames written after the
    /// last checkpoint cannot be taken back (a run started again would write them twice).
    pub fn check_resumable(&self) -> Result<()> {
        match &self.frames {
            Some(_) => Err(invalid!(
                "{} cannot go on from a checkpoint: its frames written after the last checkpoint would be written again; record rows (s.record, rec.stream_csv) in a checkpointed run, and write trajectories in a run of their own (or save the scene at each checkpoint and write frames from the saved scenes)",
                self.name()
            )),
            None => Ok(()),
        }
    }

    /// Refuse a checkpoint's mark written by another recorder than this one (other columns,
    /// trigger or origin), naming the difference.
    pub fn check_mark(&self, m: &RecorderMark) -> Result<()> {
        if m.columns != self.columns() {
            return Err(invalid!(
                "it recorded {}, this recorder records {}",
                m.columns.join(", "),
                self.columns().join(", ")
            ));
        }
        if m.trigger != self.trigger || m.start != self.start {
            return Err(invalid!(
                "it recorded {} from t = {:e} s, this recorder {} from t = {:e} s",
                m.trigger.describe(),
                m.start,
                self.trigger.describe(),
                self.start
            ));
        }
        Ok(())
    }

    /// The rows of a checkpoint's mark of this recorder, read and checked (its columns, trigger
    /// and origin this recorder's, every row as wide as this recorder's).
    pub fn rows_of(&self, m: &RecorderMark) -> Result<Vec<Vec<f64>>> {
        self.check_mark(m)?;
        let width = self.columns().len();
        m.rows
            .iter()
            .map(|line| {
                let row: Vec<f64> = line
                    .split(',')
                    .map(str::parse)
                    .collect::<std::result::Result<_, _>>()
                    .map_err(|_| invalid!("a row that is not numbers: {line}"))?;
                if row.len() == width {
                    Ok(row)
                } else {
                    Err(invalid!(
                        "a row of {} values where the recorder has {width} columns",
                        row.len()
                    ))
                }
            })
            .collect()
    }

    /// Go on from a checkpoint's mark `m`, whose rows [`Recorder::rows_of`] read: those rows in
    /// place of this recorder's, its next sample, and this recorder's CSV stream, if any, written
    /// anew with exactly those rows (rows streamed after the checkpoint are taken back).
    /// `retiring` is the owner's flag ([`super::files::Claim::take`]).
    pub fn resume_from(
        &mut self,
        m: &RecorderMark,
        rows: Vec<Vec<f64>>,
        retiring: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    ) -> Result<()> {
        self.rows = rows;
        self.next_k = m.next_k;
        if let Some(path) = self.stream.as_ref().map(|s| s.path().to_path_buf()) {
            self.stream_csv(&path, retiring)?;
        }
        Ok(())
    }

    /// Write the rows as CSV with a header carrying names and units (to a temporary file renamed
    /// over `path`: a crash keeps the old file whole).
    pub fn write_csv(&self, path: &std::path::Path) -> Result<()> {
        super::files::check_csv_name(path, "to_csv")?;
        write_atomically(path, |w| {
            let mut csv = csv::Writer::from_writer(w);
            csv.write_record(self.header())?;
            for row in &self.rows {
                csv.write_record(row.iter().map(f64_field))?;
            }
            csv.flush()
        })
    }
}

/// What a checkpoint keeps of a recorder: what it records and from when (to check that the same
/// recorder takes it back), its next periodic sample, and its rows as CSV lines (text that reads
/// back to the same f64, NaN and infinities included).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RecorderMark {
    columns: Vec<String>,
    trigger: Trigger,
    start: f64,
    next_k: u64,
    rows: Vec<String>,
}

/// A number as CSV writes it here: the shortest text that reads back to the same f64.
fn f64_field(v: &f64) -> String {
    format!("{v:?}")
}

/// One CSV line (without its newline), quoted as the csv crate quotes, for the row stream.
fn csv_line(fields: impl IntoIterator<Item = String>) -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    // Writing to memory cannot fail.
    let _ = w.write_record(fields);
    let bytes = w.into_inner().unwrap_or_default();
    String::from_utf8_lossy(&bytes)
        .trim_end_matches('\n')
        .to_string()
}
