//! The classic fourth-order Runge-Kutta method.

use super::system::{check_state, fit, uniform_step, OdeSystem, Stats, StepFailure, Stepper};

/// Classic RK4 with steps of at most `dt`.
#[derive(Debug, Clone)]
pub struct Rk4 {
    dt: f64,
    k: [Vec<f64>; 4],
    tmp: Vec<f64>,
}

impl Rk4 {
    /// A stepper with maximum step `dt`.
    pub fn new(dt: f64) -> Self {
        Rk4 {
            dt,
            k: Default::default(),
            tmp: Vec::new(),
        }
    }
}

impl Stepper for Rk4 {
    fn step(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &mut [f64],
        t_end: f64,
        stats: &mut Stats,
    ) -> Result<f64, StepFailure> {
        let n = y.len();
        let [k1, k2, k3, k4] = &mut self.k;
        fit(n, &mut [k1, k2, k3, k4, &mut self.tmp]);
        let (h, last) = uniform_step(t, t_end, self.dt);
        let [k1, k2, k3, k4] = &mut self.k;
        let tmp = &mut self.tmp;
        sys.rhs(t, y, k1);
        for i in 0..n {
            tmp[i] = y[i] + 0.5 * h * k1[i];
        }
        sys.rhs(t + 0.5 * h, tmp, k2);
        for i in 0..n {
            tmp[i] = y[i] + 0.5 * h * k2[i];
        }
        sys.rhs(t + 0.5 * h, tmp, k3);
        for i in 0..n {
            tmp[i] = y[i] + h * k3[i];
        }
        sys.rhs(t + h, tmp, k4);
        stats.rhs_evals += 4;
        for i in 0..n {
            tmp[i] = y[i] + h / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
        }
        sys.project(tmp);
        let t_new = if last { t_end } else { t + h };
        check_state(sys, t_new, tmp)?;
        y.copy_from_slice(tmp);
        stats.steps += 1;
        Ok(t_new)
    }
}
