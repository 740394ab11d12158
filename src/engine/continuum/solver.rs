//! A continuum's runs: the kinetic ODE stepped by Dormand-Prince 5(4) up to the latest time a
//! continuum may hold, under the same run control as a scene's runs
//! ([`crate::engine::stepping::RunControl`]: the interrupt asked between steps, the progress
//! told the time after each).

use super::state::Continuum;
use crate::engine::error::{invalid, Result};
use crate::engine::integrators::{Horizon, Stepper};
use crate::engine::scene::MAX_TIME_IN_PERIODS;
use crate::engine::stepping::{Interrupt, Progress};

impl Continuum {
    /// Ask `interrupt` between steps: when it answers true the run stops there, state kept
    /// (`None`: never).
    pub fn set_interrupt(&mut self, interrupt: Option<Interrupt>) {
        self.control.set_interrupt(interrupt);
    }

    /// Report the continuum's time to `p` after every step of a run (`None`: no reports).
    pub fn set_progress(&mut self, p: Option<Progress>) {
        self.control.set_progress(p);
    }

    /// Advance by `seconds`. Refused before it starts: a negative time, or an end past the
    /// latest time a continuum may hold ([`Continuum::horizon`]). On an error the state is the
    /// last accepted one. Equivalent to:
    ///
    /// ```text
    /// end = time + seconds
    /// while time < end:
    ///     if interrupted(): stop with Interrupted (state and time of the last step kept)
    ///     take one Dormand-Prince step towards end (never past it), or stop with its failure
    ///     report the new time to the progress
    /// ```
    pub fn run(&mut self, seconds: f64) -> Result<()> {
        if seconds < 0.0 {
            return Err(invalid!(
                "a continuum runs for 0 s or more, got {seconds:e} s; the dynamics cannot run backwards"
            ));
        }
        let end = self.time + seconds;
        self.horizon().check(self.time, end)?;
        self.control.begin_run();
        while self.time < end {
            if self.control.interrupted() {
                return Err(crate::engine::error::EngineError::Interrupted { time: self.time });
            }
            match self.stepper.step(
                &mut self.kinetic,
                self.time,
                &mut self.state,
                end,
                &mut self.stats,
            ) {
                Ok(t) => {
                    self.time = t;
                    self.control.report(t);
                }
                Err(e) => {
                    return Err(invalid!(
                        "the continuum's time stepping failed at t = {:e} s: {}; a finer tolerance or a smaller amplitude may help",
                        self.time,
                        e.problem.cause
                    ))
                }
            }
        }
        Ok(())
    }

    /// The latest time a continuum may hold: [`MAX_TIME_IN_PERIODS`] of its stroke period, as a
    /// scene (it starts at its scene's time).
    pub fn horizon(&self) -> Horizon<'static> {
        Horizon {
            holder: "a continuum",
            latest: MAX_TIME_IN_PERIODS * self.period,
            max_periods: MAX_TIME_IN_PERIODS,
            period: Some(self.period),
            beyond: "",
            restart: "build a new continuum from a scene at time 0",
        }
    }

    /// Advance by `periods` stroke periods.
    pub fn run_periods(&mut self, periods: f64) -> Result<()> {
        self.run(periods * self.period)
    }
}
