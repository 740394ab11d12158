//! A continuum's runs: the kinetic ODE stepped by Dormand-Prince 5(4) up to the latest time a
//! continuum may hold.

use super::state::Continuum;
use crate::engine::error::{invalid, Result};
use crate::engine::integrators::{Horizon, Stepper};
use crate::engine::scene::MAX_TIME_IN_PERIODS;

impl Continuum {
    /// Ask `interrupt` between steps: when it answers true the run stops there, state kept.
    pub fn set_interrupt(&mut self, interrupt: Option<crate::engine::integrators::Interrupt>) {
        self.interrupt = interrupt;
    }

    /// Advance by `seconds`. Refused before it starts: a negative time, or an end past the
    /// latest time a continuum may hold ([`Continuum::horizon`]). On an error the state is the
    /// last accepted one.
    pub fn run(&mut self, seconds: f64) -> Result<()> {
        if seconds < 0.0 {
            return Err(invalid!(
                "a continuum runs for 0 s or more, got {seconds:e} s; the dynamics cannot run backwards"
            ));
        }
        let end = self.time + seconds;
        self.horizon().check(self.time, end)?;
        while self.time < end {
            if self.interrupt.as_ref().is_some_and(|stop| stop()) {
                return Err(crate::engine::error::EngineError::Interrupted { time: self.time });
            }
            match self.stepper.step(
                &mut self.kinetic,
                self.time,
                &mut self.state,
                end,
                &mut self.stats,
            ) {
                Ok(t) => self.time = t,
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
