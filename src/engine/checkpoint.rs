//! Checkpoints: a run that survives a kill. At regular times a simulation writes its scene and
//! every recorder's position (rows, next due sample) to one file, atomically; the same setup
//! started again finds the file and goes on from it, ending as an uninterrupted run would, bit
//! for bit, with the same rows.
//!
//! What makes the resumed run equal the uninterrupted one: the scene file holds every value a
//! run reads (state, time, the work counters that number the noise draws); a row is text that
//! reads back to the same f64; and at every checkpoint time the run's stepper starts afresh, in
//! the run that writes the checkpoint as in the run that reads it, so no step-size memory is
//! carried past a checkpoint that the file does not hold.
//!
//! A file is taken only by the setup that wrote it: the scene as it was when checkpoints were
//! asked for (its settings, swimmers and state then), the same schedule and the same recorders.
//! Anything else is refused, naming what differs and the fix (another path, or deleting it).

use super::error::{compact_numbers, invalid, Result};
use super::files::write_atomically;
use super::integrators::require_resolvable;
use super::recorder::{Recorder, RecorderMark, Trigger};
use super::scene::Scene;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// Version of the checkpoint file's layout.
pub const CHECKPOINT_FORMAT: u32 = 1;

/// The largest checkpoint file read back (bytes): a scene of 10^5 swimmers and a million rows.
pub const MAX_CHECKPOINT_BYTES: u64 = 1 << 30;

/// What the file says it is, so that another JSON file is not mistaken for a checkpoint.
const KIND: &str = "swimlab checkpoint";

/// A simulation's checkpoint schedule: where, from when and how often.
#[derive(Debug, Clone)]
pub struct Checkpoints {
    path: PathBuf,
    /// Time of the schedule's origin (s): checkpoint k is at start + k·interval, k ≥ 1.
    start: f64,
    interval: f64,
    /// The trigger the interval was resolved from (for messages).
    trigger: Trigger,
    /// Index of the next checkpoint.
    next_k: u64,
    /// The scene as it was when the schedule was set: what a resumed run must have built.
    setup: Value,
}

#[derive(Serialize, Deserialize)]
struct CheckpointFile {
    kind: String,
    format: u32,
    start: f64,
    interval: f64,
    trigger: Trigger,
    /// Index of the checkpoint this file holds.
    index: u64,
    setup: Value,
    scene: Value,
    recorders: Vec<RecorderMark>,
}

/// A checkpoint read back: the scene and recorders to go on from.
pub struct Resume {
    /// The scene at the checkpoint.
    pub scene: Scene,
    /// Every recorder's position and rows (read and checked), in the simulation's order.
    pub recorders: Vec<(RecorderMark, Vec<Vec<f64>>)>,
}

impl Checkpoints {
    /// A schedule of checkpoints to `path` on a periodic `trigger` (every n periods or t seconds)
    /// from the scene's time now.
    pub fn new(path: &Path, scene: &Scene, trigger: &Trigger) -> Result<Self> {
        if path.as_os_str().is_empty() {
            return Err(invalid!(
                "checkpoint: the path is empty; give a file such as \"out/run.checkpoint.json\""
            ));
        }
        trigger.validate()?;
        let interval = match trigger {
            Trigger::EveryPeriods(n) => n * scene.period()?,
            Trigger::EverySeconds(t) => *t,
            other => {
                return Err(invalid!(
                    "checkpoint: checkpoints are taken at regular times, not {}; give a number of periods, every_periods(n) or every_seconds(t)",
                    other.describe()
                ))
            }
        };
        require_resolvable(
            &format!("checkpoints {} (every {interval:e} s)", trigger.describe()),
            interval,
            scene.time(),
            "take checkpoints less often",
        )?;
        Ok(Checkpoints {
            path: path.to_path_buf(),
            start: scene.time(),
            interval,
            trigger: trigger.clone(),
            next_k: 1,
            setup: scene.to_json_value()?,
        })
    }

    /// The file written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Time of the next checkpoint (s).
    pub fn next_due(&self) -> f64 {
        self.start + self.next_k as f64 * self.interval
    }

    /// Write a checkpoint of `scene` and `recorders` if one is due at the scene's time (a run
    /// segment ended there); returns whether one was written. Checkpoints a run passed without
    /// stopping (none does: runs stop at each) are skipped, never written twice.
    pub fn take_if_due(&mut self, scene: &Scene, recorders: &[Recorder]) -> Result<bool> {
        let t = scene.time();
        if t < self.next_due() {
            return Ok(false);
        }
        let index = self.next_k;
        let now = scene.to_json_value()?;
        if let Some(what) = settings_difference(&self.setup, &now) {
            return Err(invalid!(
                "checkpoint {}: the scene's settings changed since checkpoint() was called (in {what}); a run that goes on from a checkpoint starts from the setup as it was then, so it would not make the change: set the scene up before asking for checkpoints, or take checkpoints in a scene of its own for each stage",
                self.path.display()
            ));
        }
        let file = CheckpointFile {
            kind: KIND.into(),
            format: CHECKPOINT_FORMAT,
            start: self.start,
            interval: self.interval,
            trigger: self.trigger.clone(),
            index,
            setup: self.setup.clone(),
            scene: now,
            recorders: recorders
                .iter()
                .map(Recorder::mark)
                .collect::<Result<_>>()?,
        };
        let text = serde_json::to_string(&file)
            .map_err(|e| invalid!("cannot serialise the checkpoint: {e}"))?;
        write_atomically(&self.path, |w| w.write_all(text.as_bytes()))?;
        while self.next_due() <= t {
            self.next_k += 1;
        }
        Ok(true)
    }

    /// The checkpoint in this schedule's file, if there is one, checked against this schedule
    /// and `recorders` (the setup's); the schedule then goes on after it.
    pub fn resume(&mut self, recorders: &[Recorder]) -> Result<Option<Resume>> {
        let path = self.path.clone();
        let shown = path.display();
        let fix = "give checkpoint() another path, or delete the file to start afresh";
        let text = match std::fs::metadata(&path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(invalid!("checkpoint: cannot read {shown}: {e}")),
            Ok(m) if !m.is_file() => {
                return Err(invalid!("checkpoint: {shown} is not a file; {fix}"))
            }
            Ok(m) if m.len() > MAX_CHECKPOINT_BYTES => {
                return Err(invalid!(
                    "checkpoint: {shown} holds {} bytes, more than the {MAX_CHECKPOINT_BYTES} a checkpoint may; {fix}",
                    m.len()
                ))
            }
            Ok(_) => std::fs::read_to_string(&path)
                .map_err(|e| invalid!("checkpoint: cannot read {shown}: {e}; {fix}"))?,
        };
        let value: Value = serde_json::from_str(&text)
            .ok()
            .filter(|v: &Value| v.get("kind").and_then(Value::as_str) == Some(KIND))
            .ok_or_else(|| invalid!("checkpoint: {shown} is not a swimlab checkpoint; {fix}"))?;
        let format = value.get("format").and_then(Value::as_u64);
        if format != Some(u64::from(CHECKPOINT_FORMAT)) {
            return Err(invalid!(
                "checkpoint: {shown} has format {}, this swimlab reads format {CHECKPOINT_FORMAT}; {fix}",
                format.map_or("none".to_string(), |f| f.to_string())
            ));
        }
        let file: CheckpointFile = serde_json::from_value(value)
            .map_err(|e| invalid!("checkpoint: {shown} is damaged ({e}); {fix}"))?;
        if let Some(what) = first_difference(&file.setup, &self.setup) {
            return Err(invalid!(
                "checkpoint: {shown} was written by another setup: the scene when checkpoints were asked for differs in {what}; {fix}"
            ));
        }
        if file.start != self.start || file.interval != self.interval {
            return Err(invalid!(
                "checkpoint: {shown} was written {} from t = {} s, this run asks {} from t = {} s; {fix}",
                file.trigger.describe(),
                compact_numbers(&file.start.to_string()),
                self.trigger.describe(),
                compact_numbers(&self.start.to_string())
            ));
        }
        if file.recorders.len() != recorders.len() {
            return Err(invalid!(
                "checkpoint: {shown} holds {} recorders, this scene has {}; create the same recorders before checkpoint(), or {fix}",
                file.recorders.len(),
                recorders.len()
            ));
        }
        let rows = file
            .recorders
            .iter()
            .zip(recorders)
            .enumerate()
            .map(|(i, (m, r))| {
                r.rows_of(m)
                    .map_err(|e| invalid!("checkpoint: {shown}, recorder {i}: {e}; {fix}"))
            })
            .collect::<Result<Vec<_>>>()?;
        if let Some(what) = settings_difference(&file.setup, &file.scene) {
            return Err(invalid!(
                "checkpoint: {shown} holds a scene whose settings differ from its setup's (in {what}), which no run makes: the file was edited or damaged; {fix}"
            ));
        }
        let scene = Scene::from_json_value(file.scene)
            .map_err(|e| invalid!("checkpoint: {shown}: {e}; {fix}"))?;
        if file.index == 0 || scene.time() != self.start + file.index as f64 * self.interval {
            return Err(invalid!(
                "checkpoint: {shown} holds a scene at t = {:e} s, not at its checkpoint {}'s time: the file was edited or damaged; {fix}",
                scene.time(),
                file.index
            ));
        }
        self.next_k = file.index.saturating_add(1);
        Ok(Some(Resume {
            scene,
            recorders: file.recorders.into_iter().zip(rows).collect(),
        }))
    }
}

/// The fields of a scene file that runs change: everything else is the setup's.
const RUN_FIELDS: &[&str] = &["state", "time", "stats", "origins"];

/// The fields other than [`RUN_FIELDS`] in which two scene files differ, in words, if any.
fn settings_difference(setup: &Value, now: &Value) -> Option<String> {
    let strip = |v: &Value| {
        let mut v = v.clone();
        if let Some(m) = v.get_mut("scene").and_then(Value::as_object_mut) {
            for k in RUN_FIELDS {
                m.remove(*k);
            }
        }
        v
    };
    first_difference(&strip(setup), &strip(now))
}

/// The top-level fields of two scene files that differ, in words (`"base", "state"`), if any.
fn first_difference(saved: &Value, now: &Value) -> Option<String> {
    if saved == now {
        return None;
    }
    let (Some(a), Some(b)) = (
        saved.get("scene").and_then(Value::as_object),
        now.get("scene").and_then(Value::as_object),
    ) else {
        return Some("its file format".into());
    };
    let mut keys: Vec<&String> = a.keys().chain(b.keys()).collect();
    keys.sort();
    keys.dedup();
    let differ: Vec<String> = keys
        .into_iter()
        .filter(|k| a.get(*k) != b.get(*k))
        .map(|k| format!("\"{k}\""))
        .collect();
    Some(if differ.is_empty() {
        "its file format".into()
    } else {
        differ.join(", ")
    })
}
