//! A [`Simulation`]: a [`Scene`] (state and settings) with what runs it: its recorders, the
//! workspace its runs keep (stepper, device buffers), a second one for probe runs, and the run
//! control (interrupt and progress) every run takes, probes included.
//!
//! A simulation reads as its scene (`Deref<Target = Scene>`: `sim.center(0)`, `sim.time()`);
//! settings change through [`Simulation::scene_mut`].

use super::advance::{advance_to, check_steps, Probe};
use super::checkpoint::Checkpoints;
use super::error::{invalid, require_finite, Result};
use super::observable::Observable;
use super::plan;
use super::recorder::{Recorder, Trigger};
use super::scene::Scene;
use super::stepping::{Interrupt, Look, Notice, Progress, RunControl, Workspace};
use nalgebra::Vector3;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Someone who watches a simulation as it runs (a live view): a [`Look`] at the scene between
/// steps, and told of the recorders' rows and of the runs' ends.
pub trait Watcher: Look {
    /// The recorders took rows (a run reached one's due time).
    fn recorded(&self, recorders: &[Recorder]);
    /// The watcher was just attached, or a run begins or ends (however it ends): the scene and
    /// the recorders as they are now, worth a look whatever the rate.
    fn settled(&self, scene: &Scene, recorders: &[Recorder]);
    /// The scene was changed between runs (a swimmer added, a box set): worth a look when one
    /// is due, since a script may make thousands of changes in a row. By default, a look now.
    fn changed(&self, scene: &Scene, recorders: &[Recorder]) {
        self.settled(scene, recorders);
    }
}

/// A scene and what runs it. See the [module docs](self).
#[derive(Default)]
pub struct Simulation {
    scene: Scene,
    recorders: Vec<Recorder>,
    workspace: Workspace,
    probes: Workspace,
    control: RunControl,
    /// Whether this simulation is being replaced: its recorders' files may be taken over.
    retiring: Arc<AtomicBool>,
    watcher: Option<Arc<dyn Watcher>>,
    /// Where and when runs write checkpoints, if they do.
    checkpoints: Option<Checkpoints>,
}

impl std::fmt::Debug for Simulation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Simulation")
            .field("scene", &self.scene)
            .field("recorders", &self.recorders)
            .field("workspace", &self.workspace)
            .field("probes", &self.probes)
            .field("control", &self.control)
            .field("retiring", &self.retiring)
            .field("watcher", &self.watcher.is_some())
            .field("checkpoints", &self.checkpoints)
            .finish()
    }
}

impl std::ops::Deref for Simulation {
    type Target = Scene;
    fn deref(&self) -> &Scene {
        &self.scene
    }
}

impl From<Scene> for Simulation {
    fn from(scene: Scene) -> Self {
        Simulation::new(scene)
    }
}

impl Simulation {
    /// A simulation of `scene`, with no recorders, never interrupted.
    pub fn new(scene: Scene) -> Self {
        Simulation {
            scene,
            ..Default::default()
        }
    }

    /// The scene: state and settings.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Change the scene's settings or swimmers.
    pub fn scene_mut(&mut self) -> &mut Scene {
        &mut self.scene
    }

    /// Put `scene` in place of this simulation's scene, keeping the recorders and the run
    /// control; returns the old scene.
    pub fn replace_scene(&mut self, scene: Scene) -> Scene {
        std::mem::replace(&mut self.scene, scene)
    }

    /// The scene, the rest dropped.
    pub fn into_scene(self) -> Scene {
        self.scene
    }

    /// Mark this simulation as being replaced (a shell input declares its variable anew) or no
    /// longer: while it is, a new writer on a file one of its recorders writes takes that file
    /// over, and the recorder writes it no more ([`super::files::Claim`]).
    pub fn set_retiring(&self, retiring: bool) {
        self.retiring.store(retiring, Ordering::SeqCst);
    }

    /// Stop runs (and probes) at a step boundary when `interrupt()` says so (`None`: never).
    pub fn set_interrupt(&mut self, interrupt: Option<Interrupt>) {
        self.control.set_interrupt(interrupt);
    }

    /// Report progress to `p` during runs (`None`: no reports).
    pub fn set_progress(&mut self, p: Option<Progress>) {
        self.control.set_progress(p);
    }

    /// Tell `n` what a run says while it goes on: a cost far beyond what its length suggests,
    /// and why (`None`: no one).
    pub fn set_notice(&mut self, n: Option<Notice>) {
        self.control.set_notice(n);
    }

    /// Let `w` watch the runs (`None`: no one): it is shown the scene now, and then as runs go.
    /// A simulation has one watcher; a new one replaces it.
    pub fn set_watcher(&mut self, w: Option<Arc<dyn Watcher>>) {
        self.control
            .set_watch(w.clone().map(|w| w as Arc<dyn Look>));
        if let Some(w) = &w {
            w.settled(&self.scene, &self.recorders);
        }
        self.watcher = w;
    }

    /// Show the watcher, if any, the scene as it is now, whatever the rate.
    pub fn show_watcher(&self) {
        if let Some(w) = &self.watcher {
            w.settled(&self.scene, &self.recorders);
        }
    }

    /// Tell the watcher, if any, that the scene was changed between runs (a swimmer added, a box
    /// set): a view draws it without waiting for the next run, at its own rate.
    pub fn show_change(&self) {
        if let Some(w) = &self.watcher {
            w.changed(&self.scene, &self.recorders);
        }
    }

    /// Whether a watcher watches the runs.
    pub fn watched(&self) -> bool {
        self.watcher.is_some()
    }

    // ----- running -------------------------------------------------------------------------

    /// Advance the scene by `duration` seconds. Equivalent to:
    ///
    /// ```text
    /// t_end = time + duration
    /// while time < t_end:
    ///     if interrupted(): stop with Interrupted (state and time of the last step kept)
    ///     take one step of the integrator towards t_end (never past it)
    ///     if the new state has NaN/inf, overlapping spheres or a runaway spring:
    ///         adaptive: retry with a smaller step; fixed-step: stop with StepFailed
    ///         (swimmer, time, cause), keeping the last good state
    ///     time = new time
    ///     for each recorder due at this time (steps end exactly on due times): take a row
    /// ```
    /// Recorders also take a row at the end of the run if their trigger is "at end". Rows taken
    /// before an error or interrupt are kept. A run whose cost will be far beyond what its length
    /// suggests says so when it starts (a notice, [`Scene::cost_notices`]), and so does stroboscopic
    /// averaging when it falls back to direct integration. A [`Watcher`] is shown the scene when
    /// the run begins, after every step, when recorders take rows, and when the run ends.
    pub fn run(&mut self, duration: f64) -> Result<()> {
        require_finite("duration", duration)?;
        if duration < 0.0 {
            return Err(invalid!(
                "duration must be >= 0 s, got {duration}; the dynamics cannot run backwards"
            ));
        }
        self.run_watched_to(self.scene.time() + duration)
    }

    /// Advance the scene until its time is `t_end` (s), as [`Simulation::run`] does; a time the
    /// scene has reached already runs nothing and takes no row (so that a script that runs to
    /// absolute times goes on where a checkpoint left it).
    pub fn run_to(&mut self, t_end: f64) -> Result<()> {
        require_finite("the end time", t_end)?;
        if t_end <= self.scene.time() {
            return Ok(());
        }
        self.run_watched_to(t_end)
    }

    /// The run to `t_end`, the watcher (if any) shown the scene as it begins and as it ends.
    fn run_watched_to(&mut self, t_end: f64) -> Result<()> {
        let Some(w) = self.watcher.clone() else {
            return self.run_unwatched_to(t_end);
        };
        w.settled(&self.scene, &self.recorders);
        let outcome = self.run_unwatched_to(t_end);
        w.settled(&self.scene, &self.recorders);
        outcome
    }

    fn run_unwatched_to(&mut self, t_end: f64) -> Result<()> {
        self.check_run(t_end)?;
        self.control.begin_run_to(t_end);
        if t_end > self.scene.time() {
            for (kind, note) in self.scene.cost_notices() {
                self.control.notice(kind, &note);
            }
        }
        loop {
            // Stop where a recorder wants a row, so nothing is evaluated between rows.
            let now = self.scene.time();
            let segment_end = self
                .recorders
                .iter()
                .filter_map(|r| r.next_due(now))
                .chain(self.checkpoints.as_ref().map(Checkpoints::next_due))
                .fold(t_end, f64::min)
                .max(now);
            advance_to(
                &mut self.scene,
                &mut self.workspace,
                &self.control,
                segment_end,
            )?;
            let end_of_run = self.scene.time() >= t_end;
            self.fire_recorders(end_of_run)?;
            self.take_checkpoint()?;
            if end_of_run {
                return Ok(());
            }
        }
    }

    /// Write a checkpoint if one is due now; its stepper then starts afresh, as a run resumed
    /// from the checkpoint does.
    fn take_checkpoint(&mut self) -> Result<()> {
        let Some(c) = &mut self.checkpoints else {
            return Ok(());
        };
        if c.take_if_due(&self.scene, &self.recorders)? {
            self.workspace.forget_stepper();
        }
        Ok(())
    }

    /// From now on, write a checkpoint to `path` on the periodic `trigger` (every n periods or
    /// t seconds of scene time from now, see [`super::checkpoint`]); if `path` holds a checkpoint of this setup (this scene
    /// as it is now, the same trigger, the same recorders), go on from it: the scene and every
    /// recorder's rows become the checkpoint's (CSV streams written anew with those rows), and
    /// its time is returned. Trajectories are refused: their frames cannot be taken back.
    pub fn checkpoint(&mut self, path: &std::path::Path, trigger: &Trigger) -> Result<Option<f64>> {
        for r in &self.recorders {
            r.check_resumable()?;
        }
        let mut c = Checkpoints::new(path, &self.scene, trigger)?;
        let resumed = match c.resume(&self.recorders)? {
            None => None,
            Some(saved) => {
                // Every mark was read and checked before any recorder changes.
                for (r, (m, rows)) in self.recorders.iter_mut().zip(saved.recorders) {
                    r.resume_from(&m, rows, Some(self.retiring.clone()))?;
                }
                self.scene = saved.scene;
                self.workspace.forget_stepper();
                self.show_watcher();
                Some(self.scene.time())
            }
        };
        self.checkpoints = Some(c);
        Ok(resumed)
    }

    /// The checkpoint schedule's file, if runs write checkpoints.
    pub fn checkpoint_path(&self) -> Option<&std::path::Path> {
        self.checkpoints.as_ref().map(Checkpoints::path)
    }

    /// Advance by `n` stroke periods (requires a common ω).
    pub fn run_periods(&mut self, n: f64) -> Result<()> {
        require_finite("periods", n)?;
        if n < 0.0 {
            return Err(invalid!("the number of periods must be >= 0, got {n}"));
        }
        let t = self.scene.period()?;
        self.run(n * t)
    }

    /// What is refused before a run to `t_end` starts: a recorder the run cannot resolve or that
    /// would take more rows than [`super::recorder::MAX_ROWS_PER_RUN`], and the integrator's own
    /// refusals ([`check_steps`]).
    fn check_run(&self, t_end: f64) -> Result<()> {
        if t_end <= self.scene.time() {
            return Ok(());
        }
        for r in &self.recorders {
            r.check_run(self.scene.time(), t_end)?;
        }
        check_steps(&self.scene, t_end)
    }

    fn fire_recorders(&mut self, end_of_run: bool) -> Result<()> {
        let mut probe = Probe::new(&mut self.probes, &self.control);
        let fired = self
            .recorders
            .iter_mut()
            .try_for_each(|r| r.fire(&self.scene, end_of_run, &mut probe));
        if let Some(w) = &self.watcher {
            w.recorded(&self.recorders);
        }
        fired
    }

    /// What the integrator in use runs on this scene ([`Scene::integrator_info`]), and what the
    /// last run's stepper did that its name does not say (stroboscopic averaging that fell back
    /// to direct integration, and why).
    pub fn integrator_info(&self) -> Result<String> {
        let info = self.scene.integrator_info()?;
        Ok(
            match self.workspace.stepper_report(self.scene.integrator()) {
                Some(r) => format!("{info}; in the last run: {r}"),
                None => info,
            },
        )
    }

    /// Which backend the next run uses and why (see [`plan::backend_info`]).
    pub fn backend_info(&self) -> Result<String> {
        plan::backend_info(&self.scene)
    }

    // ----- measuring and recording ---------------------------------------------------------

    /// The value of `o` now; a probe (`delta_q`, ...) runs a copy a period ahead, stopped by the
    /// run control's interrupt.
    pub fn measure(&mut self, o: &Observable) -> Result<Vec<f64>> {
        o.measure(
            &self.scene,
            &mut Probe::new(&mut self.probes, &self.control),
        )
    }

    /// Every swimmer's swimming velocity (m/s); see [`Probe::center_velocities`].
    pub fn center_velocities(&mut self) -> Result<Vec<Vector3<f64>>> {
        Probe::new(&mut self.probes, &self.control).center_velocities(&self.scene)
    }

    /// Start recording `observables` on `trigger` (periodic triggers take their first row now);
    /// returns the recorder's id.
    pub fn record(&mut self, observables: Vec<Observable>, trigger: Trigger) -> Result<usize> {
        let mut probe = Probe::new(&mut self.probes, &self.control);
        let r = Recorder::start(&self.scene, observables, trigger, &mut probe)?;
        Ok(self.add_recorder(r))
    }

    /// Write the scene's spheres to the trajectory file `path` (`.xyz` or `.pvd`, see
    /// [`super::trajectory`]) on `trigger`, frame by frame as runs go; returns the id of the
    /// recorder that writes it (its rows are the frames' times).
    pub fn trajectory(&mut self, path: &std::path::Path, trigger: Trigger) -> Result<usize> {
        trigger.validate()?;
        if let Some(c) = self.checkpoint_path() {
            return Err(invalid!(
                "a trajectory cannot be written in a run that takes checkpoints ({}): its frames written after the last checkpoint would be written again when the run goes on from it; write the trajectory in a scene of its own (a copy), or record rows with s.record",
                c.display()
            ));
        }
        let t = super::trajectory::Trajectory::create(path, Some(self.retiring.clone()))?;
        let mut probe = Probe::new(&mut self.probes, &self.control);
        let r = Recorder::start_trajectory(&self.scene, t, trigger, &mut probe)?;
        Ok(self.add_recorder(r))
    }

    /// Attach a recorder made elsewhere; returns its id.
    pub fn add_recorder(&mut self, r: Recorder) -> usize {
        self.recorders.push(r);
        self.recorders.len() - 1
    }

    /// A recorder by id.
    pub fn recorder(&self, id: usize) -> Result<&Recorder> {
        self.recorders
            .get(id)
            .ok_or_else(|| invalid!("recorder {id} does not belong to this scene"))
    }

    /// Stream the rows of recorder `id` to `path` as CSV from now on (see [`Recorder::stream_csv`]).
    pub fn stream_csv(&mut self, id: usize, path: &std::path::Path) -> Result<()> {
        let retiring = self.retiring.clone();
        self.recorder_mut(id)?.stream_csv(path, Some(retiring))
    }

    /// A recorder by id, to change (e.g. to stream its rows).
    pub fn recorder_mut(&mut self, id: usize) -> Result<&mut Recorder> {
        self.recorders
            .get_mut(id)
            .ok_or_else(|| invalid!("recorder {id} does not belong to this scene"))
    }
}
