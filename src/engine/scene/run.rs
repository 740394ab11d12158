//! Running a scene: segments between the recorders' due times, the checks made before a run,
//! the CPU stepper with its guards, the GPU run with a CPU replay of a failing step, progress
//! reports, and the recorders the runs feed.

use super::*;

/// Most steps one run of a fixed-step integrator may take (~1e5 s, a day, at 1 µs a step): a
/// longer run is refused with the numbers before it starts; split it into several runs.
pub const MAX_FIXED_STEPS_PER_RUN: f64 = 1e11;

impl Scene {
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
    /// before an error or interrupt are kept.
    pub fn run(&mut self, duration: f64, interrupted: &dyn Fn() -> bool) -> Result<()> {
        require_finite("duration", duration)?;
        if duration < 0.0 {
            return Err(invalid!(
                "duration must be >= 0 s, got {duration}; the dynamics cannot run backwards"
            ));
        }
        let t_end = self.time + duration;
        self.check_run(t_end)?;
        loop {
            // Stop where a recorder wants a row, so nothing is evaluated between rows.
            let segment_end = self
                .recorders
                .iter()
                .filter_map(|r| r.next_due(self.time))
                .fold(t_end, f64::min)
                .max(self.time);
            self.advance_to(segment_end, interrupted)?;
            let end_of_run = self.time >= t_end;
            self.fire_recorders(end_of_run, interrupted)?;
            if end_of_run {
                return Ok(());
            }
        }
    }

    /// What is refused before a run to `t_end` starts: a recorder the run cannot resolve or that
    /// would take more rows than [`crate::engine::recorder::MAX_ROWS_PER_RUN`], a fixed step that cannot
    /// advance the time, more than [`MAX_FIXED_STEPS_PER_RUN`] steps.
    pub(super) fn check_run(&self, t_end: f64) -> Result<()> {
        if t_end <= self.time {
            return Ok(());
        }
        for r in &self.recorders {
            r.check_run(self.time, t_end)?;
        }
        if let IntegratorSpec::Euler { dt } | IntegratorSpec::Rk4 { dt } = self.integrator() {
            let scale = self.time.abs().max(t_end.abs());
            crate::engine::recorder::require_resolvable(
                &format!("the step dt = {dt:e} s"),
                dt,
                scale,
                "use a larger step, or a new scene from time 0",
            )?;
            let steps = (t_end - self.time) / dt;
            if steps > MAX_FIXED_STEPS_PER_RUN {
                return Err(invalid!(
                    "this run would take {steps:.3e} steps of dt = {dt:e} s, more than the {MAX_FIXED_STEPS_PER_RUN:e} one run may take (days of computing); run a shorter time, split it into several runs, or use a larger step"
                ));
            }
        }
        Ok(())
    }

    pub(super) fn fire_recorders(
        &mut self,
        end_of_run: bool,
        interrupted: &dyn Fn() -> bool,
    ) -> Result<()> {
        let mut recorders = std::mem::take(&mut self.recorders);
        let result = recorders
            .iter_mut()
            .try_for_each(|r| r.fire(self, end_of_run, interrupted));
        self.recorders = recorders;
        result
    }

    /// Integrate to `t_end` with the guards (the loop of [`Scene::run`] without recorders), on the
    /// backend [`Scene::backend_info`] names.
    pub(super) fn advance_to(&mut self, t_end: f64, interrupted: &dyn Fn() -> bool) -> Result<()> {
        if self.time >= t_end {
            return Ok(());
        }
        if self.plan()?.0 {
            self.advance_gpu(t_end, interrupted)
        } else {
            self.advance_cpu(t_end, interrupted, u64::MAX)
        }
    }

    /// [`Scene::advance_to`] on the GPU: uniform steps as the CPU stepper takes them. A step whose
    /// state fails a guard on the device is replayed on the CPU, which either reports it exactly
    /// as the CPU backend does or (a borderline case decided differently by rounding) takes it.
    pub(super) fn advance_gpu(&mut self, t_end: f64, interrupted: &dyn Fn() -> bool) -> Result<()> {
        let (dt, tableau) =
            backend::gpu_tableau(&self.integrator()).map_err(|e| invalid!("{e}"))?;
        let model = match self.model {
            Model::Micro => GpuModel::Micro {
                mu: self.mu,
                mobility: self.mobility,
            },
            Model::Averaged => {
                self.check_averaged()?;
                GpuModel::Averaged {
                    coefficients: self.coefficients,
                }
            }
            Model::Rigid => return Err(invalid!("the rigid-stroke model runs on the CPU only")),
        };
        let mut run = match self.gpu.take() {
            Some(r) if r.fits(model, self.count(), &tableau) => r,
            _ => GpuRun::new(model, self.count(), tableau.clone()).map_err(|e| invalid!("{e}"))?,
        };
        let stages = tableau.stages() as u64;
        let result = loop {
            if self.time >= t_end {
                break Ok(());
            }
            let (n, h) = uniform_steps(self.time, t_end, dt);
            let t0 = self.time;
            let outcome = run.run(
                &self.swimmers,
                &self.base,
                &mut self.state,
                UniformSteps { t0, h, count: n },
                interrupted,
            );
            let done = match outcome {
                Err(e) => {
                    break Err(unsupported(
                        format!(
                            "the GPU run failed: {e}; the scene keeps its state at t = {:.6e} s",
                            self.time
                        ),
                        &[Setting::Backend("cpu")],
                    ))
                }
                Ok(RunOutcome::Done) => n,
                Ok(RunOutcome::Failed { steps_done })
                | Ok(RunOutcome::Interrupted { steps_done }) => steps_done,
            };
            self.time = if done == n {
                t_end
            } else {
                t0 + done as f64 * h
            };
            self.stats.steps += done;
            self.stats.rhs_evals += done * stages + 1;
            self.report();
            match outcome {
                Ok(RunOutcome::Interrupted { .. }) => {
                    break Err(EngineError::Interrupted { time: self.time })
                }
                Ok(RunOutcome::Failed { .. }) => {
                    // One step on the CPU: the same step, checked by the same guards.
                    if let Err(e) = self.advance_cpu(t_end, interrupted, 1) {
                        break Err(e);
                    }
                }
                _ => {}
            }
        };
        self.gpu = Some(run);
        result
    }

    /// [`Scene::advance_to`] on the CPU, taking at most `max_steps` steps.
    pub(super) fn advance_cpu(
        &mut self,
        t_end: f64,
        interrupted: &dyn Fn() -> bool,
        max_steps: u64,
    ) -> Result<()> {
        let mut sys = self.system()?;
        let spec = self.integrator();
        let mut stepper = match self.stepper.take() {
            Some((cached, mut st)) if cached == spec => {
                st.reset();
                st
            }
            _ => spec.build(),
        };
        let mut outcome = Ok(());
        let mut taken = 0;
        while self.time < t_end && taken < max_steps {
            taken += 1;
            if interrupted() {
                outcome = Err(EngineError::Interrupted { time: self.time });
                break;
            }
            match stepper.step(
                sys.as_mut(),
                self.time,
                &mut self.state,
                t_end,
                &mut self.stats,
            ) {
                Ok(t) => {
                    self.time = t;
                    self.report();
                }
                Err(f) => {
                    outcome = Err(EngineError::StepFailed {
                        time: f.time,
                        last_good: self.time,
                        swimmer: f.problem.swimmer,
                        cause: f.problem.cause,
                        hint: f.problem.hint,
                        fixes: f.problem.fixes,
                    });
                    break;
                }
            }
        }
        self.stepper = Some((spec, stepper));
        outcome
    }

    /// Report progress to `p` during runs (`None`: no reports).
    pub fn set_progress(&mut self, p: Option<Progress>) {
        self.progress = p;
    }

    /// Tell the progress report the current time.
    pub(super) fn report(&self) {
        if let Some(p) = &self.progress {
            p(self.time);
        }
    }

    /// Take over the recorders of `old`, which this scene replaces.
    pub fn adopt_recorders(&mut self, old: Scene) {
        self.recorders = old.recorders;
    }

    /// Attach a recorder; returns its id.
    pub fn add_recorder(&mut self, r: Recorder) -> usize {
        self.recorders.push(r);
        self.recorders.len() - 1
    }

    /// A recorder by id, to change (e.g. to stream its rows).
    pub fn recorder_mut(&mut self, id: usize) -> Result<&mut Recorder> {
        self.recorders
            .get_mut(id)
            .ok_or_else(|| invalid!("recorder {id} does not belong to this scene"))
    }

    /// A recorder by id.
    pub fn recorder(&self, id: usize) -> Result<&Recorder> {
        self.recorders
            .get(id)
            .ok_or_else(|| invalid!("recorder {id} does not belong to this scene"))
    }

    /// Advance by `n` stroke periods (requires a common ω).
    pub fn run_periods(&mut self, n: f64, interrupted: &dyn Fn() -> bool) -> Result<()> {
        require_finite("periods", n)?;
        if n < 0.0 {
            return Err(invalid!("the number of periods must be >= 0, got {n}"));
        }
        let t = self.period()?;
        self.run(n * t, interrupted)
    }
}
