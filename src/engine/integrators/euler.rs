//! Explicit (forward) Euler, first order; with thermal noise on, Euler-Maruyama (weak order 1).

use super::sde::{accept, wiener_increments};
use super::system::{fit, uniform_step, OdeSystem, Stats, StepFailure, Stepper};

/// Forward Euler with steps of at most `dt`: y ← y + h f(t, y), plus B(t, y)·ΔW when the system
/// has thermal noise (Euler-Maruyama; its stationary variance of a mode relaxing at rate κ is
/// biased by the factor 1/(1 − κh/2)).
#[derive(Debug, Clone)]
pub struct Euler {
    dt: f64,
    k: Vec<f64>,
    y_new: Vec<f64>,
    dw: Vec<f64>,
}

impl Euler {
    /// A stepper with maximum step `dt`.
    pub fn new(dt: f64) -> Self {
        Euler {
            dt,
            k: Vec::new(),
            y_new: Vec::new(),
            dw: Vec::new(),
        }
    }
}

impl Stepper for Euler {
    fn step(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &mut [f64],
        t_end: f64,
        stats: &mut Stats,
    ) -> Result<f64, StepFailure> {
        let n = y.len();
        fit(n, &mut [&mut self.k, &mut self.y_new]);
        let (h, last) = uniform_step(t, t_end, self.dt);
        sys.rhs(t, y, &mut self.k);
        stats.rhs_evals += 1;
        for i in 0..n {
            self.y_new[i] = y[i] + h * self.k[i];
        }
        let noise = sys.noise();
        if let Some(noise) = noise {
            wiener_increments(noise, stats.noisy_steps, h, &mut self.dw);
            sys.add_noise(t, y, &self.dw, &mut self.y_new)
                .map_err(|problem| StepFailure { time: t, problem })?;
        }
        let t_new = if last { t_end } else { t + h };
        accept(sys, t_new, &mut self.y_new, y, stats, noise.is_some())
    }
}
