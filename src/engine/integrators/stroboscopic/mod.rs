//! Numerical stroboscopic averaging (after Calvo, Chartier, Murua & Sanz-Serna, "Numerical
//! stroboscopic averaging for ODEs and DAEs", Appl. Numer. Math. 61 (2011) 1077).
//!
//! A T-periodically forced system moves slowly from one period to the next: its stroboscopic map
//! Ψ: y(t) → y(t + T) is close to the identity. Short microscopic runs of whole periods sample Ψ,
//! and a macro integrator takes steps of many periods on the smooth flow those samples define.
//!
//! - **Slope.** The slope F(y) of the averaged flow at y is read off consecutive stroboscopic
//!   points y, Ψ(y), …, Ψ^d(y): the derivative at s = 0 of the polynomial through them at
//!   s = 0 … d periods (order d in T). The degree d (2 … [`MAX_DEGREE`]) is chosen at the start
//!   and at every step's end by comparing slopes of neighbouring degrees from the same points:
//!   the lowest whose error so estimated takes at most a tenth of the tolerance: a fixed low degree
//!   would leave close pairs with an error floor, its polynomial's truncation, whatever the
//!   tolerance (the book's design notes). A stage state y + H Σ a_j k_j is extrapolated
//!   from the step's start; its fast variables (the springs' lengths,
//!   [`OdeSystem::fast_variables`]) are extrapolated instead by their rates on the slow
//!   manifold (the derivative at 0 through their values at Ψ … Ψ^d of each earlier stage), which
//!   nothing left to relax pollutes. So a stage state lies next to the manifold, the fast motion has next to nothing
//!   to relax, and the macro flow is not stiff. Extrapolated with the slope itself, a spring's
//!   length would carry its own relaxation (a stiff mode under steps of many periods); left
//!   alone, an extrapolated turn stretches a dumbbell by ~ℓθ²/2 and the next stage fails the
//!   guards; set to the start state's length, a close pair errs many times more
//!   (tests/stroboscopic.rs; the factor is in the book's design notes).
//! - **Macro steps.** Dormand-Prince 5(4) (first-same-as-last: six new slopes a step) in whole
//!   periods, H = mT, so every macro state is a stroboscopic state of the same phase; every
//!   stage's Ψ starts at the step's own time. Fifth order rather than Bogacki-Shampine's third:
//!   at the same tolerance its steps span several times as many periods, so a step's samples
//!   (6d periods) buy more of them (the book's design notes). The error
//!   estimate is measured against the change the step makes (each 3-vector
//!   against the largest change of its kind among all swimmers: positions, or orientations, whose
//!   error turns the drift and so counts against the positions' change as well; orientations
//!   are measured across themselves, since along them lies a spring's length, a fast variable),
//!   not against absolute positions: `tol` is relative to the drift. A per-period round-off allowance
//!   keeps components that do not move from demanding the impossible.
//! - **Closing step.** A step that ends the run is first tried by Heun's method with Euler's
//!   embedded estimate: one new slope instead of six. A slow motion over a short run (a pair over
//!   100 periods changes its slope by far less than the tolerance) takes it; a rejection costs
//!   that one slope, Dormand-Prince takes the step as before, and Heun is not tried again until
//!   the next start (a motion too fast for it once is rarely slow enough later in the run).
//! - **Direct runs.** The start transient (whenever the state is not the one this stepper left:
//!   a fresh run, a changed phase, a loaded scene), a remainder of less than [`MIN_MACRO`] periods
//!   and the fraction of a period before `t_end` are integrated by the inner (microscopic)
//!   integrator itself, so a row between period multiples is a true microscopic state; so are
//!   stretches where macro steps fail at their shortest, counted in [`Stats`] and told, with
//!   why, by [`Stepper::report`].

use super::dopri5::{A, E};
use super::system::{check_state, Interrupt, OdeSystem, Problem, Stats, StepFailure, Stepper};

mod samples;

use samples::Samples;

/// Fewest periods a macro step spans: a step's samples cost 6 × d ≥ 12 periods of microscopic
/// work, so fewer are integrated directly.
pub const MIN_MACRO: u64 = 16;

/// The order in H of the error estimate relative to the change the step makes: the local error
/// of the embedded fourth-order solution is O(H⁵), the change O(H). The step controller scales
/// with its inverse.
const ESTIMATE_ORDER: f64 = 4.0;

/// Round-off allowance of the error estimate per period, relative to the size of a component
/// (positions: the swimmer length scale given; orientations: |b| or |N|). The differences of
/// stroboscopic points carry ~1e-16 of those sizes; 1e-15 per period leaves room and, against a
/// drift of ~1e-6 ℓ per period, limits the useful `tol` to ~1e-9.
const NOISE_PER_PERIOD: f64 = 1e-15;

/// A slope of the averaged flow and the rates of the fast variables on the slow manifold.
type Slope = (Vec<f64>, Vec<f64>);

/// base + h Σ_j a_j v_j, component by component.
fn extrapolate(base: &[f64], h: f64, a: &[f64], vs: &[Vec<f64>]) -> Vec<f64> {
    (0..base.len())
        .map(|i| base[i] + h * a.iter().zip(vs).map(|(aj, v)| aj * v[i]).sum::<f64>())
        .collect()
}

/// Most periods integrated directly in one go before macro steps are tried again.
const MAX_DIRECT_PERIODS: u64 = 1024;

/// Highest degree of a slope's interpolating polynomial (samples a slope may take).
pub const MAX_DEGREE: usize = 6;

/// The share of the tolerance a slope's own error may take (in the macro error norm).
const SLOPE_ERROR_SHARE: f64 = 0.1;

/// The stroboscopic averaging stepper (see the module docs).
pub struct Stroboscopic {
    tol: f64,
    period: f64,
    inner: Box<dyn Stepper>,
    /// Periods integrated directly after a start.
    transient: u32,
    /// A length scale for the positions' round-off allowance (m).
    length: f64,
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
    degree: usize,
    /// Periods to integrate directly when macro steps fail at the shortest length.
    direct_periods: u64,
    /// Asked between inner steps: a macro step spans many periods.
    interrupt: Option<Interrupt>,
    /// The latest fall-back to direct integration: its time, why, and the periods integrated
    /// directly since the macro steps last succeeded.
    fallback: Option<Fallback>,
    /// Heun's closing step was refused since the start: the motion is not that slow, and it is
    /// not tried again.
    heun_refused: bool,
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
            fallback: None,
            heun_refused: false,
        }
    }

    /// Take macro steps of exactly `m` periods (≥ 1), accepting every step: for measuring the
    /// macro method's order, not for use.
    pub fn with_fixed_macro_steps(mut self, m: u64) -> Self {
        self.fixed = Some(m.max(1));
        self
    }

    /// Integrate `y` directly from `t` to `target` with the inner stepper.
    fn direct(
        &mut self,
        sys: &mut dyn OdeSystem,
        mut t: f64,
        y: &mut [f64],
        target: f64,
        stats: &mut Stats,
    ) -> Result<f64, StepFailure> {
        self.inner.reset();
        while t < target {
            self.stop_if_interrupted(t)?;
            t = self.inner.step(sys, t, y, target, stats)?;
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

    /// `periods` stroboscopic periods of `y` from the phase of time `t` (the run's own time is not
    /// changed: Ψ depends on the phase only).
    fn psi(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &mut [f64],
        periods: u32,
        stats: &mut Stats,
    ) -> Result<(), StepFailure> {
        for k in 0..periods {
            let (a, b) = (t + k as f64 * self.period, t + (k + 1) as f64 * self.period);
            self.direct(sys, a, y, b, stats)?;
            stats.micro_periods += 1;
        }
        Ok(())
    }

    /// The slope of the averaged flow at `y` (phase of `t`) from the stroboscopic points y, Ψ(y),
    /// …, Ψ^d(y), d = the current degree: the derivative at 0 of the polynomial through them
    /// (order d in T); and the fast variables' rates on the slow manifold, the derivative at 0 of
    /// the polynomial through their values at Ψ … Ψ^d, free of whatever y's own fast variables had
    /// to relax.
    fn slope_at(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        stats: &mut Stats,
    ) -> Result<Slope, StepFailure> {
        let s = self.samples(sys, t, y, self.degree, stats)?;
        Ok(s.slope(self.period, self.degree))
    }

    /// [`Stroboscopic::slope_at`] that also chooses the degree. The slope of degree d − 1 differs
    /// from that of degree d by about its own error (the series in T/τ, τ the slow time, converges
    /// fast: each degree gains a large factor; the book's design notes). The degree is the lowest,
    /// from one below the current one, whose slope's error so estimated stays within a tenth of
    /// the tolerance in the macro error norm (relative to the drift); the slope returned is the
    /// better one of the pair. Up to [`MAX_DEGREE`].
    fn probed_slope(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        stats: &mut Stats,
    ) -> Result<Slope, StepFailure> {
        let lowest = self.degree.saturating_sub(1).max(2);
        let mut s = self.samples(sys, t, y, lowest + 1, stats)?;
        loop {
            let d = s.diffs.len();
            let (hi, below) = (s.slope(self.period, d), s.slope(self.period, d - 1));
            let y_next: Vec<f64> = y
                .iter()
                .zip(&hi.0)
                .map(|(v, k)| v + self.period * k)
                .collect();
            let diff: Vec<f64> =
                hi.0.iter()
                    .zip(&below.0)
                    .map(|(a, b)| self.period * (a - b))
                    .collect();
            if self.error_norm(y, &y_next, &diff, 1) <= SLOPE_ERROR_SHARE || d > MAX_DEGREE {
                self.degree = d - 1;
                return Ok(hi);
            }
            self.sample(sys, t, &mut s, stats)?;
        }
    }

    /// The first `n` stroboscopic points of `y`.
    fn samples(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        n: usize,
        stats: &mut Stats,
    ) -> Result<Samples, StepFailure> {
        let mut s = Samples::new(y);
        for _ in 0..n {
            self.sample(sys, t, &mut s, stats)?;
        }
        Ok(s)
    }

    /// One more stroboscopic point of `s`.
    fn sample(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        s: &mut Samples,
        stats: &mut Stats,
    ) -> Result<(), StepFailure> {
        // Ψ depends on the phase only: each period starts at the phase of t.
        self.psi(sys, t, &mut s.z, 1, stats)?;
        s.diffs
            .push(s.z.iter().zip(&s.y).map(|(a, b)| a - b).collect());
        let mut fast = Vec::new();
        sys.fast_variables(&s.z, &mut fast);
        s.fast.push(fast);
        Ok(())
    }

    /// Max over 3-vectors of |err| / (tol · largest change of that kind + round-off allowance).
    ///
    /// An orientation vector's part along itself is its length: in the spring model the spring's
    /// length, a fast variable that the stages and the solution take from their rates on the slow
    /// manifold ([`OdeSystem::set_fast_variables`]), never from the slopes; in the rigid-stroke
    /// model the norm of a unit vector, which the projection restores. So errors and changes of
    /// orientations are measured across them only. Along them, a stage's length set a little off
    /// the manifold relaxes within the first sample period, and that jump, which says nothing
    /// about the slow flow, would otherwise enter every slope of the orientation and, against a
    /// small tolerance times a slow turn, fail every degree check and every macro step.
    fn error_norm(&self, y: &[f64], y_new: &[f64], err: &[f64], m: u64) -> f64 {
        let blocks = y.len() / 3;
        let vec3 = |v: &[f64], b: usize| [v[3 * b], v[3 * b + 1], v[3 * b + 2]];
        let norm = |s: [f64; 3]| (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
        // Block b of v; an orientation block without its part along y's orientation.
        let part = |v: &[f64], b: usize| {
            let s = vec3(v, b);
            if b.is_multiple_of(2) {
                return s;
            }
            let o = vec3(y, b);
            let o2 = o[0] * o[0] + o[1] * o[1] + o[2] * o[2];
            if o2 == 0.0 {
                return s;
            }
            let along = (s[0] * o[0] + s[1] * o[1] + s[2] * o[2]) / o2;
            [
                s[0] - along * o[0],
                s[1] - along * o[1],
                s[2] - along * o[2],
            ]
        };
        let mut change = [0.0f64; 2];
        let mut size = [self.length, 0.0f64];
        let diff: Vec<f64> = y_new.iter().zip(y).map(|(a, b)| a - b).collect();
        for b in 0..blocks {
            change[b % 2] = change[b % 2].max(norm(part(&diff, b)));
            if b % 2 == 1 {
                size[1] = size[1].max(norm(vec3(y, b)));
            }
        }
        // An orientation error δ turns the drift by δ/|b|: it is measured against the larger of
        // the orientations' own change and the positions' change scaled to |b|.
        let moved = [change[0], change[1].max(change[0] * size[1] / self.length)];
        let allowance = |c: usize| self.tol * moved[c] + m as f64 * NOISE_PER_PERIOD * size[c];
        (0..blocks)
            .map(|b| norm(part(err, b)) / allowance(b % 2))
            .fold(0.0, f64::max)
    }

    /// One macro step of `m` periods from (t, y): the new state, its slope and the error norm,
    /// or `None` when a stage state failed a guard (the step is then too long).
    fn macro_step(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        k1: &Slope,
        m: u64,
        stats: &mut Stats,
    ) -> Option<(Vec<f64>, Slope, f64)> {
        let h = m as f64 * self.period;
        let n = y.len();
        // The fast variables (springs' lengths) of the stage states are extrapolated by their
        // rates on the slow manifold, the rest of the state by the slopes.
        let mut fast0 = Vec::new();
        sys.fast_variables(y, &mut fast0);
        let mut ks: Vec<Vec<f64>> = vec![k1.0.to_vec()];
        let mut fast_rates: Vec<Vec<f64>> = vec![k1.1.to_vec()];
        for row in 1..6 {
            let a = &A[row][..row];
            let mut z = extrapolate(y, h, a, &ks);
            sys.set_fast_variables(&mut z, &extrapolate(&fast0, h, a, &fast_rates));
            let (k, r) = self.slope_at(sys, t, &z, stats).ok()?;
            ks.push(k);
            fast_rates.push(r);
        }
        // The last row is the solution (first same as last): its slope starts the next step.
        let mut y_new = extrapolate(y, h, &A[6][..6], &ks);
        sys.project(&mut y_new);
        sys.set_fast_variables(&mut y_new, &extrapolate(&fast0, h, &A[6][..6], &fast_rates));
        check_state(sys, t + h, &y_new).ok()?;
        let k_new = self.probed_slope(sys, t, &y_new, stats).ok()?;
        let err: Vec<f64> = (0..n)
            .map(|i| {
                h * E
                    .iter()
                    .zip(ks.iter().chain([&k_new.0]))
                    .map(|(ej, k)| ej * k[i])
                    .sum::<f64>()
            })
            .collect();
        let e = self.error_norm(y, &y_new, &err, m);
        Some((y_new, k_new, e))
    }

    /// The closing step of `m` periods from (t, y) by Heun's method with Euler's embedded: one
    /// new slope, at the Euler stage y + H k1, instead of Dormand-Prince's six; the new state and
    /// the error norm (of the Euler solution, H/2 |k2 − k1|, so the second-order state carried
    /// is measured conservatively), or `None` when the stage failed a guard.
    fn heun_step(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        k1: &Slope,
        m: u64,
        stats: &mut Stats,
    ) -> Option<(Vec<f64>, f64)> {
        let h = m as f64 * self.period;
        let mut fast0 = Vec::new();
        sys.fast_variables(y, &mut fast0);
        let mut z = extrapolate(y, h, &[1.0], std::slice::from_ref(&k1.0));
        sys.set_fast_variables(
            &mut z,
            &extrapolate(&fast0, h, &[1.0], std::slice::from_ref(&k1.1)),
        );
        let (k2, r2) = self.slope_at(sys, t, &z, stats).ok()?;
        let half = [0.5, 0.5];
        let mut y_new = extrapolate(y, h, &half, &[k1.0.clone(), k2.clone()]);
        sys.project(&mut y_new);
        sys.set_fast_variables(
            &mut y_new,
            &extrapolate(&fast0, h, &half, &[k1.1.clone(), r2]),
        );
        check_state(sys, t + h, &y_new).ok()?;
        let err: Vec<f64> = k2
            .iter()
            .zip(&k1.0)
            .map(|(b, a)| 0.5 * h * (b - a))
            .collect();
        let e = self.error_norm(y, &y_new, &err, m);
        Some((y_new, e))
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
            // First try the whole run in one macro step: a slow motion takes it, and a rejection
            // costs one step's samples.
            self.h_periods = f64::INFINITY;
        }
        let whole = ((t_end - t) / period + 1e-9).floor().max(0.0) as u64;
        let min_macro = self.fixed.unwrap_or(MIN_MACRO);
        // A time within rounding of t_end is t_end.
        let snap = |t_new: f64| {
            if (t_end - t_new).abs() <= 1e-9 * period {
                t_end
            } else {
                t_new
            }
        };
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
            let t_new = self.direct(sys, t, &mut trial, target, stats)?;
            stats.micro_periods += periods;
            if transient {
                self.pending_transient -= 1;
            }
            y.copy_from_slice(&trial);
            self.slope = None;
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
                        return Ok(self.leave(snap(t + m as f64 * period), y));
                    }
                    _ => {
                        stats.rejected += 1;
                        self.heun_refused = true;
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
                    if m == MIN_MACRO || rejects > 20 {
                        // The motion is not slow at this tolerance: periods directly, as many
                        // as the last fallback's twice (from MIN_MACRO), so the rejected macro
                        // steps' samples cost at most about as much as the direct periods.
                        self.h_periods = 2.0 * MIN_MACRO as f64;
                        let k = self.direct_periods.min(whole);
                        self.direct_periods = (2 * self.direct_periods).min(MAX_DIRECT_PERIODS);
                        let mut trial = y.to_vec();
                        self.psi(sys, t, &mut trial, k as u32, stats)?;
                        y.copy_from_slice(&trial);
                        stats.direct_fallbacks += 1;
                        stats.fallback_periods += k;
                        let why = if m == MIN_MACRO {
                            format!("{why}, the shortest a macro step may be")
                        } else {
                            format!("{rejects} macro steps in a row were rejected; the last: {why}")
                        };
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
                        return Ok(self.leave(snap(t + k as f64 * period), y));
                    }
                    self.h_periods = m as f64 * shrink;
                }
            }
        }
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
