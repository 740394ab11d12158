//! Stepping a scene towards a time on one backend: the run control every run takes (interrupt and
//! progress), the workspace a run keeps between runs (the stepper, the device buffers), the CPU
//! stepper with its guards, and the GPU run with a CPU replay of a failing step.
//!
//! Which backend a run takes is decided above this module ([`super::plan`], [`super::advance`]):
//! the calibration of "auto" steps both backends through here.

use super::error::{invalid, unsupported, EngineError, Result, Setting};
use super::gpu::support::{self, GpuSteps};
use super::gpu::{AdaptiveSteps, GpuModel, GpuRun, Peek, RunOutcome, UniformSteps};
use super::integrators::{uniform_steps, IntegratorSpec, StateWatch, Stepper};
use super::model::DeviceKernel;
use super::scene::Scene;
use std::sync::Arc;

pub use super::integrators::Interrupt;

/// A run's progress report: called with the scene time after every CPU step and after every
/// device run segment, e.g. to draw a progress bar. It must be cheap.
pub type Progress = Arc<dyn Fn(f64) + Send + Sync>;

/// Something a run says while it goes on, in engine words with its fixes as settings (the
/// script layer shows them as script lines): a cost far beyond what the run's length suggests,
/// and why. The payload is an [`EngineError`] for its message and fixes; the run goes on.
pub type Notice = Arc<dyn Fn(&EngineError) + Send + Sync>;

/// Someone who looks at the scene while a run goes on (a live view): asked after every CPU step,
/// every inner step of a long step (stroboscopic averaging's direct periods) and every device
/// submission whether a look is due, which must be cheap (a view looks a few dozen times a
/// second, not every step); a device's state is read back only for a look.
pub trait Look: Send + Sync {
    /// Whether a look is due now.
    fn due(&self) -> bool;
    /// Look at the scene (after `due` said so).
    fn look(&self, s: &Scene);
    /// The run reached scene time `time`: hold it back (sleep) if it goes faster than it is
    /// watched.
    fn pace(&self, time: f64);
}

/// What every run takes besides the scene: whether to stop, whom to tell the time, whom to tell a
/// notice (each kind once a run) and who looks. The default never stops and tells no one.
#[derive(Clone, Default)]
pub struct RunControl {
    interrupt: Option<Interrupt>,
    progress: Option<Progress>,
    notice: Option<Notice>,
    watch: Option<Arc<dyn Look>>,
    /// The kinds of notice given since the run began.
    noticed: Arc<std::sync::Mutex<Vec<&'static str>>>,
    /// The run under way, shared by its segments.
    run: Arc<std::sync::Mutex<RunUnderWay>>,
}

/// What a run's segments share: its end (s), once said, and its collapse judge, once made.
#[derive(Default)]
struct RunUnderWay {
    end: Option<f64>,
    judge: Option<Arc<CollapseJudge>>,
}

impl std::fmt::Debug for RunControl {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RunControl")
            .field("interrupt", &self.interrupt.is_some())
            .field("progress", &self.progress.is_some())
            .field("notice", &self.notice.is_some())
            .field("watch", &self.watch.is_some())
            .finish()
    }
}

impl RunControl {
    /// Stop runs when `interrupt()` says so (`None`: never).
    pub fn set_interrupt(&mut self, interrupt: Option<Interrupt>) {
        self.interrupt = interrupt;
    }

    /// Report progress to `p` (`None`: no reports).
    pub fn set_progress(&mut self, p: Option<Progress>) {
        self.progress = p;
    }

    /// Tell `n` a run's notices (`None`: no one).
    pub fn set_notice(&mut self, n: Option<Notice>) {
        self.notice = n;
    }

    /// Show `w` the scene as runs go (`None`: no one looks).
    pub fn set_watch(&mut self, w: Option<Arc<dyn Look>>) {
        self.watch = w;
    }

    /// A run begins: every kind of notice may be given again.
    pub fn begin_run(&self) {
        if let Ok(mut k) = self.noticed.lock() {
            k.clear();
        }
        if let Ok(mut r) = self.run.lock() {
            *r = RunUnderWay::default();
        }
    }

    /// A run to scene time `t_end` begins (its segments, between recorder rows, one run): every
    /// kind of notice may be given again, and its steps are judged once across its segments.
    pub fn begin_run_to(&self, t_end: f64) {
        self.begin_run();
        if let Ok(mut r) = self.run.lock() {
            r.end = Some(t_end);
        }
    }

    /// The collapse judge of the run under way, made at its first segment from `s` (to the
    /// run's end, else `t_end`).
    fn collapse_judge(&self, s: &Scene, t_end: f64) -> Arc<CollapseJudge> {
        let mut r = self.run.lock().unwrap_or_else(|e| e.into_inner());
        let end = r.end.unwrap_or(t_end);
        r.judge
            .get_or_insert_with(|| Arc::new(CollapseJudge::new(s, end)))
            .clone()
    }

    /// Give the notice `e` of kind `kind`, unless one of that kind was given in this run.
    pub fn notice(&self, kind: &'static str, e: &EngineError) {
        let Some(n) = &self.notice else { return };
        let fresh = self.noticed.lock().is_ok_and(|mut k| {
            let fresh = !k.contains(&kind);
            if fresh {
                k.push(kind);
            }
            fresh
        });
        if fresh {
            n(e);
        }
    }

    /// Whether the run should stop now.
    pub fn interrupted(&self) -> bool {
        self.interrupt.as_ref().is_some_and(|f| f())
    }

    /// Tell the progress report the scene time.
    pub fn report(&self, time: f64) {
        if let Some(p) = &self.progress {
            p(time);
        }
    }

    /// Show the watcher, if any, the scene as it is after a step, if a look is due.
    pub fn look(&self, s: &Scene) {
        if let Some(w) = &self.watch {
            if w.due() {
                w.look(s);
            }
            w.pace(s.time);
        }
    }

    /// The watch a stepper whose steps hold many inner steps shows the state inside them: the
    /// run's collapse `judge` counts them, and a copy of `s` (made now) takes the inner step's
    /// time and state when a look is due; `None` with neither a watcher nor a judge.
    fn inner_watch(&self, s: &Scene, judge: Option<Arc<CollapseJudge>>) -> Option<StateWatch> {
        if self.watch.is_none() && judge.is_none() {
            return None;
        }
        let w = self.watch.clone();
        let shadow = w.as_ref().map(|_| std::sync::Mutex::new(s.clone()));
        let control = self.clone();
        Some(Arc::new(move |t: f64, y: &[f64]| {
            if let Some(judge) = &judge {
                judge.step(t, &control);
            }
            let (Some(w), Some(shadow)) = (&w, &shadow) else {
                return;
            };
            if w.due() {
                let mut copy = shadow.lock().unwrap_or_else(|e| e.into_inner());
                if copy.state.len() == y.len() {
                    copy.time = t;
                    copy.state.copy_from_slice(y);
                    w.look(&copy);
                }
            }
            w.pace(t);
        }))
    }

    /// What a watched device run shows its state through between submissions: a copy of `s`
    /// (made now) takes the time, the steps and, when a look is due, the device's state.
    fn device_peek(&self, s: &Scene) -> Option<impl FnMut(f64, u64, &GpuRun)> {
        let w = self.watch.clone()?;
        let mut copy = s.clone();
        let steps0 = s.stats.steps;
        Some(move |t: f64, steps: u64, gpu: &GpuRun| {
            if w.due() && gpu.peek_state(&mut copy.state).is_ok() {
                copy.time = t;
                copy.stats.steps = steps0 + steps;
                w.look(&copy);
            }
            w.pace(t);
        })
    }

    /// The control of a probe run on a copy: the same interrupt, no progress and no watcher (the
    /// copy's time and state are not the run's).
    pub fn for_probe(&self) -> Self {
        RunControl {
            interrupt: self.interrupt.clone(),
            progress: None,
            notice: None,
            watch: None,
            noticed: Arc::default(),
            run: Arc::default(),
        }
    }
}

/// What a run keeps for the next one: the stepper (an adaptive one remembers its step size) and
/// the device buffers of the last GPU run, reused while the scene's size and method stay.
#[derive(Default)]
pub struct Workspace {
    /// The stepper, with the spec and the scene key ([`Scene::stepper_key`]) it was built for.
    stepper: Option<(IntegratorSpec, Vec<u64>, Box<dyn Stepper>)>,
    gpu: Option<GpuRun>,
}

impl std::fmt::Debug for Workspace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Workspace")
            .field("stepper", &self.stepper.as_ref().map(|(spec, ..)| spec))
            .field("gpu", &self.gpu.is_some())
            .finish()
    }
}

impl Workspace {
    /// Forget the stepper, so the next run starts as a fresh one does (device buffers are kept:
    /// they hold no state between runs).
    pub fn forget_stepper(&mut self) {
        self.stepper = None;
    }

    /// What the stepper of the last run did that its name does not say ([`Stepper::report`]),
    /// if that stepper was one for `spec`.
    pub fn stepper_report(&self, spec: IntegratorSpec) -> Option<String> {
        self.stepper
            .as_ref()
            .filter(|(s, _, _)| *s == spec)
            .and_then(|(_, _, st)| st.report())
    }

    /// The cached stepper, reset, if it was built for `spec` and the scene key `key`; else a new
    /// one for the scene. Either way `spec` must suit the scene as it is now (a cached stepper
    /// was built for the scene as it was: another model, no noise).
    fn take_stepper(
        &mut self,
        s: &Scene,
        spec: IntegratorSpec,
        key: &[u64],
    ) -> Result<Box<dyn Stepper>> {
        s.check_integrator(spec)?;
        match self.stepper.take() {
            Some((cached, cached_key, mut st)) if cached == spec && cached_key == key => {
                st.reset();
                Ok(st)
            }
            _ => s.stepper(spec),
        }
    }
}

/// How long a CPU run goes before it is judged whether its steps have collapsed
/// ([`Scene::collapsed_steps`]): long enough that the pace is its steady one.
const COLLAPSE_LOOK: std::time::Duration = std::time::Duration::from_secs(2);

/// Counts a CPU run's steps (a stepper's inner ones where it shows them) and judges once, after
/// [`COLLAPSE_LOOK`], whether they have collapsed; if so the run's control gives the notice.
struct CollapseJudge {
    started: std::time::Instant,
    from: f64,
    t_end: f64,
    period: f64,
    /// What may hold the steps short ([`Scene::collapse_cause`]), taken when the run starts.
    cause: crate::engine::scene::CollapseCause,
    steps: std::sync::atomic::AtomicU64,
    judged: std::sync::atomic::AtomicBool,
}

impl CollapseJudge {
    fn new(s: &Scene, t_end: f64) -> Self {
        CollapseJudge {
            started: std::time::Instant::now(),
            from: s.time,
            t_end,
            period: s.shortest_period(),
            cause: s.collapse_cause(),
            steps: Default::default(),
            judged: Default::default(),
        }
    }

    /// A step reached scene time `now`.
    fn step(&self, now: f64, control: &RunControl) {
        use std::sync::atomic::Ordering;
        let steps = self.steps.fetch_add(1, Ordering::Relaxed) + 1;
        if self.judged.load(Ordering::Relaxed) {
            return;
        }
        let wall = self.started.elapsed();
        if wall < COLLAPSE_LOOK || self.judged.swap(true, Ordering::Relaxed) {
            return;
        }
        let span = (self.from, now, self.t_end);
        if let Some(note) = Scene::collapsed_steps(self.period, span, steps, wall, &self.cause) {
            control.notice("collapsed steps", &note);
        }
    }
}

/// Step `s` to `t_end` on the CPU with the guards, taking at most `max_steps` steps; a run whose
/// steps have collapsed says so after [`COLLAPSE_LOOK`].
pub fn advance_cpu(
    s: &mut Scene,
    ws: &mut Workspace,
    control: &RunControl,
    t_end: f64,
    max_steps: u64,
) -> Result<()> {
    let mut sys = s.system()?;
    let spec = s.integrator();
    let key = s.stepper_key(spec);
    let mut stepper = ws.take_stepper(s, spec, &key)?;
    stepper.set_interrupt(control.interrupt.clone());
    // A fixed step is the user's choice, not a collapse.
    let judge = spec
        .fixed_step()
        .is_none()
        .then(|| control.collapse_judge(s, t_end));
    if stepper.watches_inside() {
        stepper.set_watch(control.inner_watch(s, judge.clone()));
    }
    let mut outcome = Ok(());
    let mut taken = 0;
    let fallbacks = s.stats.direct_fallbacks;
    while s.time < t_end && taken < max_steps {
        taken += 1;
        if control.interrupted() {
            outcome = Err(EngineError::Interrupted { time: s.time });
            break;
        }
        match stepper.step(sys.as_mut(), s.time, &mut s.state, t_end, &mut s.stats) {
            Ok(t) => {
                s.time = t;
                control.report(s.time);
                control.look(s);
                if let Some(judge) = judge.as_ref().filter(|_| !stepper.watches_inside()) {
                    judge.step(s.time, control);
                }
                if s.stats.direct_fallbacks > fallbacks {
                    if let Some(why) = stepper.report() {
                        control.notice(
                            "direct fallback",
                            &EngineError::Invalid(format!("{spec}: {why}")),
                        );
                    }
                }
            }
            // A long step given up on the interrupt.
            Err(_) if control.interrupted() => {
                outcome = Err(EngineError::Interrupted { time: s.time });
                break;
            }
            Err(f) => {
                let problem = s.explain_failure(f.problem);
                outcome = Err(EngineError::StepFailed {
                    time: f.time,
                    last_good: s.time,
                    swimmer: problem.swimmer,
                    cause: problem.cause,
                    hint: problem.hint,
                    fixes: problem.fixes,
                });
                break;
            }
        }
    }
    // The copy the watch holds is let go.
    stepper.set_watch(None);
    ws.stepper = Some((spec, key, stepper));
    outcome
}

/// Step `s` to `t_end` on the GPU, taking the steps the CPU stepper takes: uniform ones, or
/// dopri5's adaptive ones (error norm, accept/reject and the next step decided on the device).
/// A step whose state fails a guard on the device is replayed on the CPU, which either reports
/// it exactly as the CPU backend does or (a borderline case decided differently by rounding)
/// takes it.
pub fn advance_gpu(
    s: &mut Scene,
    ws: &mut Workspace,
    control: &RunControl,
    t_end: f64,
) -> Result<()> {
    let (steps, tableau) = support::tableau(&s.integrator()).map_err(|e| invalid!("{e}"))?;
    let model = match s.swimmer_model().device_kernel() {
        Ok(DeviceKernel::Springs) => GpuModel::Micro {
            mu: s.mu(),
            mobility: s.mobility(),
        },
        Ok(DeviceKernel::Averaged) => {
            s.check_averaged()?;
            GpuModel::Averaged {
                coefficients: s.coefficients(),
            }
        }
        Err((who, _)) => return Err(invalid!("{who} runs on the CPU only")),
    };
    let mut run = match ws.gpu.take() {
        Some(r) if r.fits(model, s.count(), &tableau) => r,
        _ => GpuRun::new(super::gpu::device()?, model, s.count(), tableau.clone())?,
    };
    let result = match steps {
        GpuSteps::Fixed(dt) => uniform_on_gpu(s, ws, control, t_end, &mut run, dt),
        GpuSteps::Adaptive(rtol) => adaptive_on_gpu(s, ws, control, t_end, &mut run, rtol),
    };
    ws.gpu = Some(run);
    result
}

/// A device run that failed as a whole (lost device, out of memory).
fn device_failed(e: EngineError, s: &Scene) -> EngineError {
    unsupported(
        format!(
            "the GPU run failed: {e}; the scene keeps its state at t = {:.6e} s",
            s.time
        ),
        &[Setting::Backend("cpu")],
    )
}

/// Uniform steps of `dt` on the device.
fn uniform_on_gpu(
    s: &mut Scene,
    ws: &mut Workspace,
    control: &RunControl,
    t_end: f64,
    run: &mut GpuRun,
    dt: f64,
) -> Result<()> {
    let stages = run.stages() as u64;
    let interrupted = || control.interrupted();
    loop {
        if s.time >= t_end {
            return Ok(());
        }
        let (n, h) = uniform_steps(s.time, t_end, dt);
        let t0 = s.time;
        let mut peek = control.device_peek(s);
        let outcome = run.run(
            &s.swimmers,
            &s.base,
            &mut s.state,
            UniformSteps { t0, h, count: n },
            &interrupted,
            peek.as_mut().map(|p| p as Peek<'_>),
        );
        let outcome = outcome.map_err(|e| device_failed(e, s))?;
        let done = match outcome {
            RunOutcome::Done => n,
            RunOutcome::Failed { steps_done } | RunOutcome::Interrupted { steps_done } => {
                steps_done
            }
        };
        s.time = if done == n {
            t_end
        } else {
            t0 + done as f64 * h
        };
        s.stats.steps += done;
        s.stats.rhs_evals += done * stages + 1;
        control.report(s.time);
        control.look(s);
        match outcome {
            RunOutcome::Interrupted { .. } => {
                return Err(EngineError::Interrupted { time: s.time })
            }
            // One step on the CPU: the same step, checked by the same guards.
            RunOutcome::Failed { .. } => advance_cpu(s, ws, control, t_end, 1)?,
            RunOutcome::Done => {}
        }
    }
}

/// Adaptive steps at `rtol` on the device. The CPU stepper (cached in the workspace as for a CPU
/// run, and reset as a CPU run resets it) keeps the step size between runs and gives the first
/// one; the device takes the steps; a failing step is replayed on the CPU from the step size it
/// began with.
fn adaptive_on_gpu(
    s: &mut Scene,
    ws: &mut Workspace,
    control: &RunControl,
    t_end: f64,
    run: &mut GpuRun,
    rtol: f64,
) -> Result<()> {
    let spec = s.integrator();
    let key = s.stepper_key(spec);
    let mut sys = s.system()?;
    let mut stepper = ws.take_stepper(s, spec, &key)?;
    let mut scale = vec![0.0; s.state.len()];
    sys.error_scale(&s.state, &mut scale);
    let stages = run.stages() as u64 - 1;
    let interrupted = || control.interrupted();
    let result = loop {
        if s.time >= t_end {
            break Ok(());
        }
        let Some(h) = stepper.next_step(sys.as_mut(), s.time, &s.state, &mut s.stats) else {
            break Err(invalid!("{spec} takes no adaptive steps"));
        };
        let mut peek = control.device_peek(s);
        let report = run.run_adaptive(
            &s.swimmers,
            &s.base,
            &mut s.state,
            AdaptiveSteps {
                t0: s.time,
                t_end,
                h,
                rtol,
                scale: &scale,
            },
            &interrupted,
            peek.as_mut().map(|p| p as Peek<'_>),
        );
        let report = match report {
            Ok(r) => r,
            Err(e) => break Err(device_failed(e, s)),
        };
        s.time = report.t;
        s.stats.steps += report.steps;
        s.stats.rejected += report.rejected;
        s.stats.rhs_evals += stages * (report.steps + report.rejected) + 1;
        stepper.continue_with_step(report.h);
        control.report(s.time);
        control.look(s);
        match report.outcome {
            RunOutcome::Interrupted { .. } => break Err(EngineError::Interrupted { time: s.time }),
            RunOutcome::Failed { .. } => {
                // The failing step on the CPU, from the step size it began with.
                ws.stepper = Some((spec, key.clone(), stepper));
                let replay = advance_cpu(s, ws, control, t_end, 1);
                stepper = match ws.stepper.take() {
                    Some((_, _, st)) => st,
                    None => s.stepper(spec)?,
                };
                if let Err(e) = replay {
                    break Err(e);
                }
            }
            RunOutcome::Done => {}
        }
    };
    ws.stepper = Some((spec, key, stepper));
    result
}
