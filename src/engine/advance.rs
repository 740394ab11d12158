//! Advancing a scene to a time on the backend its [`plan`] names, the checks made before, and
//! probe runs: the observables that compare now with one period later run a copy of the scene
//! there, with the run's interrupt and a workspace of their own.

use super::error::{invalid, EngineError, Result};
use super::integrators::{require_resolvable, Horizon};
use super::model::{vec3, STATE_PER_SWIMMER};
use super::plan::plan;
use super::scene::{Scene, MAX_TIME_IN_PERIODS};
use super::stepping::{advance_cpu, advance_gpu, RunControl, Workspace};
use nalgebra::Vector3;

/// Most steps one run of a fixed-step integrator may take (~1e5 s, a day, at 1 µs a step): a
/// longer run is refused with the numbers before it starts; split it into several runs.
pub const MAX_FIXED_STEPS_PER_RUN: f64 = 1e11;

/// Integrate `s` to `t_end` with the guards, on the backend [`plan`] names.
pub fn advance_to(
    s: &mut Scene,
    ws: &mut Workspace,
    control: &RunControl,
    t_end: f64,
) -> Result<()> {
    if s.time() >= t_end {
        return Ok(());
    }
    if plan(s)?.gpu {
        advance_gpu(s, ws, control, t_end)
    } else {
        advance_cpu(s, ws, control, t_end, u64::MAX)
    }
}

/// What is refused before a run of `s` to `t_end` starts, whatever the integrator: an end past
/// the latest time a scene may hold ([`Scene::latest_time`], which a saved scene could not be
/// loaded at); and of a fixed-step integrator, a step that cannot advance the time, or more than
/// [`MAX_FIXED_STEPS_PER_RUN`] steps.
pub fn check_steps(s: &Scene, t_end: f64) -> Result<()> {
    if t_end <= s.time() {
        return Ok(());
    }
    Horizon {
        holder: "a scene",
        latest: s.latest_time(),
        max_periods: MAX_TIME_IN_PERIODS,
        period: s.period().ok(),
        beyond: ", and a saved scene would not load",
        restart: "continue in a new scene from time 0",
    }
    .check(s.time(), t_end)?;
    if let Some(dt) = s.integrator().fixed_step() {
        let scale = s.time().abs().max(t_end.abs());
        require_resolvable(
            &format!("the step dt = {dt:e} s"),
            dt,
            scale,
            "use a larger step, or a new scene from time 0",
        )?;
        let steps = (t_end - s.time()) / dt;
        if steps > MAX_FIXED_STEPS_PER_RUN {
            return Err(invalid!(
                "this run would take {steps:.3e} steps of dt = {dt:e} s, more than the {MAX_FIXED_STEPS_PER_RUN:e} one run may take (days of computing); run a shorter time, split it into several runs, or use a larger step"
            ));
        }
    }
    Ok(())
}

/// Probe runs of one period on copies of a scene (the scene itself is never changed). Each starts
/// with a fresh stepper, as a new scene would; device buffers are kept from one probe to the next.
pub struct Probe<'a> {
    workspace: &'a mut Workspace,
    control: RunControl,
}

impl<'a> Probe<'a> {
    /// Probes stopped by `control`'s interrupt (its progress report is not told the copies' times).
    pub fn new(workspace: &'a mut Workspace, control: &RunControl) -> Self {
        Probe {
            workspace,
            control: control.for_probe(),
        }
    }

    /// A copy of `s` one common period later. An interrupt is reported at `s`'s own time (the
    /// copy's time means nothing to the user: `s` itself did not move).
    pub fn one_period_later(&mut self, s: &Scene) -> Result<Scene> {
        let mut copy = s.clone();
        let t_end = copy.time() + copy.period()?;
        self.workspace.forget_stepper();
        check_steps(&copy, t_end)
            .and_then(|()| advance_to(&mut copy, self.workspace, &self.control, t_end))
            .map_err(|e| match e {
                EngineError::Interrupted { .. } => EngineError::Interrupted { time: s.time() },
                other => other,
            })?;
        Ok(copy)
    }

    /// Every swimmer's swimming velocity (m/s): dR_H/dt of the averaged model; in the sphere
    /// models, whose centres oscillate within a stroke, R_H's displacement over the next period
    /// divided by T.
    pub fn center_velocities(&mut self, s: &Scene) -> Result<Vec<Vector3<f64>>> {
        let n = s.count();
        if s.swimmer_model().stroke_averaged() {
            let mut sys = s.system()?;
            let (state, _) = s.raw_state();
            let mut dy = vec![0.0; state.len()];
            sys.rhs(s.time(), state, &mut dy);
            return Ok((0..n).map(|i| vec3(&dy, STATE_PER_SWIMMER * i)).collect());
        }
        let period = s.period()?;
        let later = self.one_period_later(s)?;
        (0..n)
            .map(|i| Ok((later.displacement(i)? - s.displacement(i)?) / period))
            .collect()
    }
}
