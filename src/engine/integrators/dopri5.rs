//! Dormand-Prince 5(4) with embedded error estimate and FSAL, driven by the adaptive controller
//! with Hairer's PI step-size rule (Hairer, Nørsett & Wanner, *Solving ODEs I*, II.4 and the
//! `DOPRI5` code).

use super::controller::{self, Adaptive, Attempt, Controller, StepRule};
use super::system::{fit, OdeSystem, Stats, StepFailure, Stepper};

/// Stage times (the GPU backend takes the same tableau).
pub const C: [f64; 7] = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
/// Stage matrix; its last row is the fifth-order solution (first same as last).
pub const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [0.2, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];
/// Fifth-order solution minus embedded fourth-order one.
pub const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// Adaptive Dormand-Prince 5(4) with relative tolerance `rtol` (per component, against
/// [`OdeSystem::error_scale`]).
#[derive(Debug, Clone)]
pub struct Dopri5 {
    rtol: f64,
    control: Controller,
    fsal_valid: bool,
    k: [Vec<f64>; 7],
    tmp: Vec<f64>,
    y_new: Vec<f64>,
    scale: Vec<f64>,
}

impl Dopri5 {
    /// A stepper with relative tolerance `rtol`.
    pub fn new(rtol: f64) -> Self {
        Dopri5 {
            rtol,
            control: Controller::adaptive(StepRule::pi()),
            fsal_valid: false,
            k: Default::default(),
            tmp: Vec::new(),
            y_new: Vec::new(),
            scale: Vec::new(),
        }
    }

    /// The Dormand-Prince 5th-order formula with fixed steps of at most `dt` and no error control.
    pub fn fixed_step(dt: f64) -> Self {
        Dopri5 {
            control: Controller::fixed(StepRule::pi(), dt),
            ..Dopri5::new(1.0)
        }
    }

    fn norm(&self, v: &[f64]) -> f64 {
        let n = v.len().max(1) as f64;
        (v.iter()
            .zip(&self.scale)
            .map(|(x, s)| (x / (self.rtol * s)).powi(2))
            .sum::<f64>()
            / n)
            .sqrt()
    }

    /// Buffers sized to y, the error scale at y, and the rates at (t, y) in the first stage slot
    /// unless they are there already (first same as last).
    fn start(&mut self, sys: &mut dyn OdeSystem, t: f64, y: &[f64], stats: &mut Stats) {
        let [k1, k2, k3, k4, k5, k6, k7] = &mut self.k;
        fit(
            y.len(),
            &mut [
                k1,
                k2,
                k3,
                k4,
                k5,
                k6,
                k7,
                &mut self.tmp,
                &mut self.y_new,
                &mut self.scale,
            ],
        );
        sys.error_scale(y, &mut self.scale);
        if !self.fsal_valid {
            sys.rhs(t, y, &mut self.k[0]);
            stats.rhs_evals += 1;
            self.fsal_valid = true;
        }
    }

    /// RMS over components of (embedded error estimate)/(rtol · scale), from the stages in `k`.
    fn error_norm(&self, h: f64) -> f64 {
        let n = self.scale.len();
        let mut acc = 0.0;
        for i in 0..n {
            let e: f64 = h * E.iter().zip(&self.k).map(|(e, kj)| e * kj[i]).sum::<f64>();
            let r = e / (self.rtol * self.scale[i]);
            acc += r * r;
        }
        (acc / n.max(1) as f64).sqrt()
    }

    /// Hairer's starting step: a step whose Euler error is about the tolerance.
    fn hairer_step(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        stats: &mut Stats,
    ) -> f64 {
        let d0 = self.norm(y);
        let d1 = self.norm(&self.k[0]);
        let h0 = if d0 < 1e-5 || d1 < 1e-5 {
            1e-6
        } else {
            0.01 * d0 / d1
        };
        let h0 = h0.min(1e-3 / d1.max(1e-300));
        for i in 0..y.len() {
            self.tmp[i] = y[i] + h0 * self.k[0][i];
        }
        let [k0, k1, ..] = &mut self.k;
        sys.rhs(t + h0, &self.tmp, k1);
        stats.rhs_evals += 1;
        let diff: Vec<f64> = k1.iter().zip(k0.iter()).map(|(a, b)| a - b).collect();
        let d2 = self.norm(&diff) / h0;
        let h1 = if d1.max(d2) <= 1e-15 {
            (h0 * 1e-3).max(1e-6)
        } else {
            (0.01 / d1.max(d2)).powf(0.2)
        };
        (100.0 * h0).min(h1)
    }
}

impl Adaptive for Dopri5 {
    fn controller(&mut self) -> &mut Controller {
        &mut self.control
    }

    fn prepare(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        stats: &mut Stats,
    ) -> Result<(), StepFailure> {
        self.start(sys, t, y, stats);
        Ok(())
    }

    fn initial_step(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        _t_end: f64,
        stats: &mut Stats,
    ) -> f64 {
        self.hairer_step(sys, t, y, stats)
    }

    fn attempt(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        h: f64,
        stats: &mut Stats,
    ) -> Attempt {
        let n = y.len();
        for s in 1..7 {
            for i in 0..n {
                let mut acc = 0.0;
                for (j, a) in A[s][..s].iter().enumerate() {
                    acc += a * self.k[j][i];
                }
                self.tmp[i] = y[i] + h * acc;
            }
            sys.rhs(t + C[s] * h, &self.tmp, &mut self.k[s]);
        }
        stats.rhs_evals += 6;
        // Stage 7 was evaluated at the 5th-order solution (A[6] = b), which is in tmp.
        self.y_new.copy_from_slice(&self.tmp);
        Attempt::of_norm(self.error_norm(h))
    }

    fn candidate(&mut self) -> &mut [f64] {
        &mut self.y_new
    }

    fn accepted(&mut self) {
        self.k.swap(0, 6);
    }
}

impl Stepper for Dopri5 {
    fn step(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &mut [f64],
        t_end: f64,
        stats: &mut Stats,
    ) -> Result<f64, StepFailure> {
        controller::step(self, sys, t, y, t_end, stats)
    }

    fn reset(&mut self) {
        self.fsal_valid = false;
        self.control.reset(StepRule::pi());
    }

    fn next_step(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        stats: &mut Stats,
    ) -> Option<f64> {
        if self.control.is_fixed() {
            return None;
        }
        if self.control.h.is_none() {
            self.start(sys, t, y, stats);
            self.control.h = Some(self.hairer_step(sys, t, y, stats));
        }
        self.control.h
    }

    fn continue_with_step(&mut self, h: f64) {
        self.control.h = Some(h);
        self.fsal_valid = false;
    }
}
