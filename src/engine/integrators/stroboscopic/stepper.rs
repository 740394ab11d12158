//! The stroboscopic stepper: its state between steps, the direct runs (transient, remainders,
//! fallbacks) and the macro step loop with its step size in periods (see the module docs of
//! [`super`]).

use crate::engine::integrators::system::{
    Interrupt, OdeSystem, Problem, StateWatch, Stats, StepFailure, Stepper,
};

/// A slope of the averaged flow and the rates of the fast variables on the slow manifold.
pub(super) type Slope = (Vec<f64>, Vec<f64>);

/// Fewest periods a macro step spans: a step's samples cost 6 × d ≥ 12 periods of microscopic
/// work, so fewer are integrated directly.
pub const MIN_MACRO: u64 = 16;

/// The order in H of the error estimate relative to the change the step makes: the local error
/// of the embedded fourth-order solution is O(H⁵), the change O(H). The step controller scales
/// with its inverse.
const ESTIMATE_ORDER: f64 = 4.0;

/// Most periods integrated directly in one go before macro steps are tried again.
const MAX_DIRECT_PERIODS: u64 = 1024;

/// The stroboscopic averaging stepper (see the module docs).
pub struct Stroboscopic {
    pub(super) tol: f64,
    pub(super) period: f64,
    inner: Box<dyn Stepper>,
    /// Periods integrated directly after a start.
    transient: u32,
    /// A length scale for the positions' round-off allowance (m).
    pub(super) length: f64,
    /// The next macro step, in periods.
    h_periods: f64,
    /// Direct periods still to take after a start.
    pending_transient: u32,
    /// The (time, state) this stepper left: anything else is a start.
    left: Option<(f64, Vec<f64>)>,
    /// The slope at the state left (first same as last).
    slope: Option<Slope>,
    /// Macro steps of exactly this many periods, every step accepted (convergence studies).
    fixed: Option<u64>,
    /// Degree of the slopes' interpolating polynomial: the samples Ψ¹ … Ψ^degree a slope takes.
    pub(super) degree: usize,
    /// Periods to integrate directly when macro steps fail at the shortest length.
    direct_periods: u64,
    /// Asked between inner steps: a macro step spans many periods.
    interrupt: Option<Interrupt>,
    /// Shown the scene's state after each inner step of the direct periods (a live view).
    watch: Option<StateWatch>,
    /// The latest fall-back to direct integration: its time, why, and the periods integrated
    /// directly since the macro steps last succeeded.
    fallback: Option<Fallback>,
    /// Heun's closing step was refused since the start: the motion is not that slow, and it is
    /// not tried again.
    heun_refused: bool,
    /// `Stats::micro_periods` when the current series of macro step attempts began (the last
    /// accepted step, direct stretch or start): what rejected attempts have cost since.
    attempts_from: u64,
}

/// Macro steps that failed at their shortest length, and the direct integration that followed.
struct Fallback {
    /// When (s).
    time: f64,
    /// Why, in words.
    why: String,
    /// Periods integrated directly since then, until a macro step is accepted again.
    periods: u64,
}

impl Stroboscopic {
    /// A stepper of tolerance `tol` (relative to the drift) for a system of common period `period`
    /// (s), sampling the stroboscopic map with `inner` and integrating `transient` periods
    /// directly after a start (the fast motion settles onto the slow manifold). `length` (m)
    /// scales the positions' round-off allowance.
    pub fn new(
        tol: f64,
        period: f64,
        inner: Box<dyn Stepper>,
        transient: u32,
        length: f64,
    ) -> Self {
        Stroboscopic {
            tol,
            period,
            inner,
            transient,
            length,
            h_periods: f64::INFINITY,
            pending_transient: 0,
            left: None,
            slope: None,
            fixed: None,
            degree: 2,
            direct_periods: MIN_MACRO,
            interrupt: None,
            watch: None,
            fallback: None,
            heun_refused: false,
            attempts_from: 0,
        }
    }

    /// The fewest periods a macro step may span at the current degree and still pay for its
    /// samples: its six new slopes sample `degree` periods each, and a shorter step would cost
    /// more than integrating its periods directly.
    fn paying_periods(&self) -> u64 {
        (6 * self.degree as u64).max(MIN_MACRO)
    }

    /// Take macro steps of exactly `m` periods (≥ 1), accepting every step: for measuring the
    /// macro method's order, not for use.
    pub fn with_fixed_macro_steps(mut self, m: u64) -> Self {
        self.fixed = Some(m.max(1));
        self
    }

    /// Integrate `y` directly from `t` to `target` with the inner stepper; `watched`: `y` is the
    /// scene's own state (not a sample's), shown to the watch after every inner step.
    pub(super) fn direct(
        &mut self,
        sys: &mut dyn OdeSystem,
        mut t: f64,
        y: &mut [f64],
        target: f64,
        stats: &mut Stats,
        watched: bool,
    ) -> Result<f64, StepFailure> {
        self.inner.reset();
        let watch = self.watch.clone().filter(|_| watched);
        while t < target {
            self.stop_if_interrupted(t)?;
            t = self.inner.step(sys, t, y, target, stats)?;
            if let Some(w) = &watch {
                w(t, y);
            }
        }
        Ok(t)
    }

    /// Give the step up when the interrupt is set (the caller reports the interrupt).
    fn stop_if_interrupted(&self, t: f64) -> Result<(), StepFailure> {
        if self.interrupt.as_ref().is_some_and(|f| f()) {
            return Err(StepFailure {
                time: t,
                problem: Problem {
                    swimmer: None,
                    cause: "interrupted".into(),
                    hint: String::new(),
                    fixes: Vec::new(),
                },
            });
        }
        Ok(())
    }

    /// The motion is not slow enough for macro steps here: integrate periods directly, at least
    /// three times as many as the attempts since the last success sampled (so failed attempts
    /// add at most a third to the direct cost) and twice the last fallback's (from
    /// [`MIN_MACRO`], up to [`MAX_DIRECT_PERIODS`]), then try macro steps again.
    fn fall_back(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &mut [f64],
        t_end: f64,
        why: String,
        stats: &mut Stats,
    ) -> Result<f64, StepFailure> {
        let whole = self.whole_periods(t, t_end);
        self.h_periods = 2.0 * self.paying_periods() as f64;
        let wasted = stats.micro_periods.saturating_sub(self.attempts_from);
        let k = self.direct_periods.max(3 * wasted).min(whole);
        self.direct_periods = (2 * self.direct_periods).min(MAX_DIRECT_PERIODS);
        let mut trial = y.to_vec();
        self.psi(sys, t, &mut trial, k as u32, stats)?;
        y.copy_from_slice(&trial);
        stats.direct_fallbacks += 1;
        stats.fallback_periods += k;
        self.attempts_from = stats.micro_periods;
        match &mut self.fallback {
            Some(f) => {
                f.why = why;
                f.periods += k;
            }
            None => {
                self.fallback = Some(Fallback {
                    time: t,
                    why,
                    periods: k,
                })
            }
        }
        self.slope = None;
        Ok(self.leave(snap_to(t + k as f64 * self.period, t_end, self.period), y))
    }

    /// The whole periods from `t` to `t_end`.
    fn whole_periods(&self, t: f64, t_end: f64) -> u64 {
        ((t_end - t) / self.period + 1e-9).floor().max(0.0) as u64
    }

    fn leave(&mut self, t: f64, y: &[f64]) -> f64 {
        match &mut self.left {
            Some((lt, ly)) => {
                *lt = t;
                ly.clear();
                ly.extend_from_slice(y);
            }
            None => self.left = Some((t, y.to_vec())),
        }
        t
    }
}

impl Stepper for Stroboscopic {
    fn step(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &mut [f64],
        t_end: f64,
        stats: &mut Stats,
    ) -> Result<f64, StepFailure> {
        let period = self.period;
        let started = !matches!(&self.left, Some((lt, ly)) if *lt == t && ly.as_slice() == &*y);
        if started {
            self.pending_transient = self.transient;
            self.slope = None;
            self.degree = 2;
            self.direct_periods = MIN_MACRO;
            self.heun_refused = false;
            self.attempts_from = stats.micro_periods;
            // First try the whole run in one macro step: a slow motion takes it, and a rejection
            // costs one step's samples.
            self.h_periods = f64::INFINITY;
        }
        let whole = self.whole_periods(t, t_end);
        let min_macro = self.fixed.unwrap_or(MIN_MACRO);
        // A time within rounding of t_end is t_end.
        let snap = |t_new: f64| snap_to(t_new, t_end, period);
        // Direct: the transient a period at a time; a run or remainder too short for a macro step
        // (and the last fraction of a period) in one go to its end, as the inner method alone
        // would step it.
        if self.pending_transient > 0 || whole < min_macro {
            let transient = self.pending_transient > 0 && whole >= 1;
            let (target, periods) = if transient {
                (snap(t + period), 1)
            } else {
                (t_end, whole)
            };
            let mut trial = y.to_vec();
            // The scene's own periods, run directly: a live view may watch them.
            let t_new = self.direct(sys, t, &mut trial, target, stats, true)?;
            stats.micro_periods += periods;
            if transient {
                self.pending_transient -= 1;
            }
            y.copy_from_slice(&trial);
            self.slope = None;
            self.attempts_from = stats.micro_periods;
            return Ok(self.leave(t_new, y));
        }
        let k1 = match self.slope.take() {
            Some(k) => k,
            None => self.probed_slope(sys, t, y, stats)?,
        };
        let mut rejects = 0;
        loop {
            let m = match self.fixed {
                Some(m) => m,
                None => (self.h_periods.min(whole as f64).floor() as u64).clamp(MIN_MACRO, whole),
            };
            // A step too short to pay for its samples is not tried (Heun's closing step, one
            // slope, may still be); its periods are integrated directly.
            let paying = self.paying_periods();
            let too_short = |st: &Self| {
                format!(
                    "they would be shorter than the {paying} periods they sample ({m} asked for, slopes of degree {}), so would not pay",
                    st.degree
                )
            };
            let heun_next = m == whole && !self.heun_refused;
            // Dormand-Prince over the rest of the run would sample `paying` periods to save the
            // other m − paying, and a rejection would waste them all: once Heun's closing step
            // was refused, it is tried only where it would save at least as many as it samples.
            let closing = || {
                format!(
                    "Heun's closing step was rejected, and a Dormand-Prince step over the {m} periods left would sample {paying} of them to save at most {}",
                    m.saturating_sub(paying)
                )
            };
            if self.fixed.is_none() && !heun_next {
                if m < paying {
                    let why = too_short(self);
                    return self.fall_back(sys, t, y, t_end, why, stats);
                }
                if m == whole && m < 2 * paying {
                    let why = closing();
                    return self.fall_back(sys, t, y, t_end, why, stats);
                }
            }
            // A step that ends the run first tries Heun's method: a slow motion over a short run
            // takes it at the price of one slope, where a rejection costs that slope only, once
            // a run.
            if m == whole && self.fixed.is_none() && !self.heun_refused {
                match self.heun_step(sys, t, y, &k1, m, stats) {
                    Some((y_new, e)) if e <= 1.0 => {
                        y.copy_from_slice(&y_new);
                        // The next step, if any, probes its own slope.
                        self.slope = None;
                        self.direct_periods = MIN_MACRO;
                        stats.macro_steps += 1;
                        self.fallback = None;
                        self.attempts_from = stats.micro_periods;
                        return Ok(self.leave(snap(t + m as f64 * period), y));
                    }
                    _ => {
                        stats.rejected += 1;
                        self.heun_refused = true;
                        if m < 2 * paying {
                            let why = if m < paying {
                                too_short(self)
                            } else {
                                closing()
                            };
                            return self.fall_back(sys, t, y, t_end, why, stats);
                        }
                    }
                }
            }
            let attempt = self.macro_step(sys, t, y, &k1, m, stats);
            match attempt {
                Some((y_new, k4, e)) if e <= 1.0 || self.fixed.is_some() => {
                    let t_new = snap(t + m as f64 * period);
                    let grow = if e > 0.0 {
                        (0.9 * e.powf(-1.0 / ESTIMATE_ORDER)).clamp(0.2, 5.0)
                    } else {
                        5.0
                    };
                    self.h_periods = (m as f64 * grow).max(MIN_MACRO as f64);
                    y.copy_from_slice(&y_new);
                    self.slope = Some(k4);
                    self.direct_periods = MIN_MACRO;
                    stats.macro_steps += 1;
                    self.fallback = None;
                    self.attempts_from = stats.micro_periods;
                    return Ok(self.leave(t_new, y));
                }
                outcome => {
                    self.stop_if_interrupted(t)?;
                    stats.rejected += 1;
                    let (shrink, why) = match outcome {
                        Some((_, _, e)) if e.is_finite() => (
                            (0.9 * e.powf(-1.0 / ESTIMATE_ORDER)).clamp(0.2, 0.9),
                            format!("a macro step of {m} periods had an error estimate of {e:.3} times the tolerance"),
                        ),
                        _ => {
                            stats.rejected_by_guard += 1;
                            (
                                0.25,
                                format!("a stage state of a macro step of {m} periods failed a guard (NaN, overlapping spheres or a runaway spring)"),
                            )
                        }
                    };
                    rejects += 1;
                    if m <= paying || rejects > 20 {
                        let why = if m <= paying {
                            format!("{why}, and a shorter step would not pay for its samples")
                        } else {
                            format!("{rejects} macro steps in a row were rejected; the last: {why}")
                        };
                        return self.fall_back(sys, t, y, t_end, why, stats);
                    }
                    self.h_periods = m as f64 * shrink;
                }
            }
        }
    }

    fn watches_inside(&self) -> bool {
        true
    }

    fn set_watch(&mut self, watch: Option<StateWatch>) {
        self.watch = watch;
    }

    fn set_interrupt(&mut self, interrupt: Option<Interrupt>) {
        self.interrupt = interrupt;
    }

    fn report(&self) -> Option<String> {
        let f = self.fallback.as_ref()?;
        Some(format!(
            "from t = {:.6e} s macro steps fail ({}): the motion is not slow enough for tol {:e} there, so the run integrates it directly with the inner method, {} periods so far, each as costly as a sample period; a looser tol lets macro steps through",
            f.time, f.why, self.tol, f.periods
        ))
    }

    fn reset(&mut self) {
        // Kept: the step size and the slope of the state left; `step` restarts (transient and
        // all) only if it is handed another state.
    }
}

/// `t_new`, or `t_end` where it lies within rounding of it (a billionth of a `period`).
fn snap_to(t_new: f64, t_end: f64, period: f64) -> f64 {
    if (t_end - t_new).abs() <= 1e-9 * period {
        t_end
    } else {
        t_new
    }
}
