//! Dormand-Prince 5(4) with embedded error estimate, FSAL, and Hairer's PI step-size controller
//! (Hairer, Nørsett & Wanner, *Solving ODEs I*, II.4 and the `DOPRI5` code).

use super::system::{
    check_state, fit, stalled, step_too_small, tolerance_failure, OdeSystem, Stats, StepFailure,
    Stepper,
};

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
const SAFETY: f64 = 0.9;
const BETA: f64 = 0.04;
/// A step may shrink at most 5× and grow at most 10× at once.
const FAC_MIN: f64 = 0.2;
const FAC_MAX: f64 = 10.0;
/// Consecutive rejected attempts after which the step is given up.
const MAX_REJECTS: u32 = 60;

/// Adaptive Dormand-Prince 5(4) with relative tolerance `rtol` (per component, against
/// [`OdeSystem::error_scale`]).
#[derive(Debug, Clone)]
pub struct Dopri5 {
    rtol: f64,
    /// Fixed step (no error control), for convergence-order studies.
    fixed: Option<f64>,
    h: Option<f64>,
    fac_old: f64,
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
            fixed: None,
            h: None,
            fac_old: 1e-4,
            fsal_valid: false,
            k: Default::default(),
            tmp: Vec::new(),
            y_new: Vec::new(),
            scale: Vec::new(),
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
    fn prepare(&mut self, sys: &mut dyn OdeSystem, t: f64, y: &[f64], stats: &mut Stats) {
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

    /// The Dormand-Prince 5th-order formula with fixed steps of at most `dt` and no error control.
    pub fn fixed_step(dt: f64) -> Self {
        Dopri5 {
            fixed: Some(dt),
            ..Dopri5::new(1.0)
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
    fn initial_step(
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

impl Stepper for Dopri5 {
    fn step(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &mut [f64],
        t_end: f64,
        stats: &mut Stats,
    ) -> Result<f64, StepFailure> {
        let n = y.len();
        self.prepare(sys, t, y, stats);
        let mut h = match (self.fixed, self.h) {
            (Some(dt), _) => super::system::uniform_step(t, t_end, dt).0,
            (None, Some(h)) => h,
            (None, None) => self.initial_step(sys, t, y, stats),
        };
        let mut rejected_last = false;
        let mut rejects = 0;
        let scale = sys.time_scale();
        loop {
            let span = t_end - t;
            let (h_try, last) = if h >= span { (span, true) } else { (h, false) };
            for s in 1..7 {
                for i in 0..n {
                    let mut acc = 0.0;
                    for (j, a) in A[s][..s].iter().enumerate() {
                        acc += a * self.k[j][i];
                    }
                    self.tmp[i] = y[i] + h_try * acc;
                }
                sys.rhs(t + C[s] * h_try, &self.tmp, &mut self.k[s]);
            }
            stats.rhs_evals += 6;
            // Stage 7 was evaluated at the 5th-order solution (A[6] = b), which is in tmp.
            self.y_new.copy_from_slice(&self.tmp);
            let err_norm = self.error_norm(h_try);
            let fac11 = err_norm.powf(0.2 - BETA * 0.75);
            let t_new = if last { t_end } else { t + h_try };
            let accept = self.fixed.is_some() || (err_norm <= 1.0 && err_norm.is_finite());
            let guard = if accept {
                sys.project(&mut self.y_new);
                check_state(sys, t_new, &self.y_new)
            } else {
                Ok(())
            };
            match (accept, guard) {
                (true, Ok(())) => {
                    let fac = (fac11 / self.fac_old.powf(BETA) / SAFETY)
                        .clamp(1.0 / FAC_MAX, 1.0 / FAC_MIN);
                    let mut h_next = h_try / fac;
                    if rejected_last {
                        h_next = h_next.min(h_try);
                    }
                    // A step below the floor that the error estimate does not let grow never
                    // gets anywhere (a start from a tiny step grows up to 10× a step instead).
                    if self.fixed.is_none()
                        && !last
                        && h_next <= h_try
                        && step_too_small(h_next, t, scale)
                    {
                        return Err(stalled(t_new, h_next, t, scale));
                    }
                    self.fac_old = err_norm.max(1e-4);
                    // A step clipped to land on t_end says nothing about the natural step size.
                    self.h = Some(if last && h_try < h {
                        h.max(h_next)
                    } else {
                        h_next
                    });
                    y.copy_from_slice(&self.y_new);
                    self.k.swap(0, 6);
                    stats.steps += 1;
                    return Ok(t_new);
                }
                (true, Err(failure)) => {
                    stats.rejected += 1;
                    stats.rejected_by_guard += 1;
                    rejects += 1;
                    if rejects >= MAX_REJECTS {
                        self.h = Some(h_try);
                        return Err(failure);
                    }
                    h = h_try * 0.25;
                    // Crawling towards the event the guard refuses (spheres about to touch):
                    // stop with it once the step no longer advances the time.
                    if step_too_small(h, t, scale) {
                        self.h = Some(h_try);
                        return Err(failure);
                    }
                }
                (false, _) => {
                    stats.rejected += 1;
                    rejects += 1;
                    if rejects >= MAX_REJECTS {
                        return Err(tolerance_failure(t_new, h_try, MAX_REJECTS));
                    }
                    let shrink = if err_norm.is_finite() {
                        (fac11 / SAFETY).min(1.0 / FAC_MIN)
                    } else {
                        1.0 / FAC_MIN
                    };
                    h = h_try / shrink;
                    if step_too_small(h, t, scale) {
                        return Err(stalled(t_new, h, t, scale));
                    }
                }
            }
            rejected_last = true;
        }
    }

    fn reset(&mut self) {
        self.fsal_valid = false;
        self.fac_old = 1e-4;
    }

    fn next_step(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        stats: &mut Stats,
    ) -> Option<f64> {
        if self.fixed.is_some() {
            return None;
        }
        if self.h.is_none() {
            self.prepare(sys, t, y, stats);
            self.h = Some(self.initial_step(sys, t, y, stats));
        }
        self.h
    }

    fn continue_with_step(&mut self, h: f64) {
        self.h = Some(h);
        self.fsal_valid = false;
    }
}
