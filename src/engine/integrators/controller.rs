//! The adaptive step controller: one loop for every adaptive stepper (Dormand-Prince, ROS34PW2,
//! the suspension stepper). A stepper supplies its attempt (candidate state and error norm,
//! [`Adaptive`]); the controller runs attempt → guard → accept or reject → next step size
//! ([`step`]), with the step-size rule the stepper's order asks for ([`StepRule`]).
//!
//! Reject policy, the same for every stepper:
//! - an error norm above tolerance (or not finite) shrinks the step by the rule; after
//!   [`MAX_REJECTS`] attempts in a row, or once the step falls below [`step_floor`], the step
//!   fails (with [`tolerance_failure`] or [`stalled`]);
//! - a candidate within tolerance that fails a guard (NaN, overlapping spheres, a runaway spring)
//!   shrinks the step 4×: the step is crawling towards the event the guard refuses. It gives up
//!   with the guard's failure after [`MAX_REJECTS`] attempts or once the step no longer advances
//!   the time, and either way the next step starts from the last one tried;
//! - fixed steps (convergence studies) accept every error norm and are never shortened: a guard
//!   failure fails the step at once.

use super::system::{
    check_state, uniform_step, OdeSystem, Problem, Stats, StepFailure, MIN_RELATIVE_INTERVAL,
};

/// Consecutive rejected attempts after which a step is given up.
pub(crate) const MAX_REJECTS: u32 = 60;

/// What an attempt of one step says about its candidate.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Attempt {
    /// The error norm (≤ 1: within tolerance); the step-size rule reads it.
    pub err: f64,
    /// Whether the candidate meets the tolerance (the suspension stepper may accept a step
    /// whose few fast swimmers it refined).
    pub within: bool,
}

impl Attempt {
    /// The verdict of a plain error norm: within tolerance when finite and at most 1.
    pub fn of_norm(err: f64) -> Self {
        Attempt {
            err,
            within: err <= 1.0 && err.is_finite(),
        }
    }
}

/// A stepper the controller drives: its one-step formula with an error estimate.
pub(crate) trait Adaptive {
    /// The controller's state the stepper keeps between steps.
    fn controller(&mut self) -> &mut Controller;

    /// What a step from (t, y) needs before its first attempt (rates at the start, Jacobian).
    fn prepare(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        stats: &mut Stats,
    ) -> Result<(), StepFailure>;

    /// The step to try when none is known yet (after [`Adaptive::prepare`]).
    fn initial_step(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        t_end: f64,
        stats: &mut Stats,
    ) -> f64;

    /// Try a step of `h` from (t, y): the candidate state into [`Adaptive::candidate`].
    fn attempt(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        h: f64,
        stats: &mut Stats,
    ) -> Attempt;

    /// The candidate state of the last attempt (projected and guarded in place).
    fn candidate(&mut self) -> &mut [f64];

    /// The last attempt was accepted (a first-same-as-last method keeps its last stage).
    fn accepted(&mut self) {}
}

/// How the next step size follows from an attempt's error norm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum StepRule {
    /// Hairer's PI controller of the `DOPRI5` code, for an order-5 method with an embedded 4
    /// (*Solving ODEs I*, II.4): `previous` is the error norm of the last accepted step (at
    /// least 1e-4). After a rejection the next accepted step does not grow.
    Pi {
        /// The error norm of the last accepted step.
        previous: f64,
    },
    /// The elementary rule for an order-3 method with an embedded 2 (ROS34PW2): 0.9 err^(−1/3),
    /// within 0.2 and 5.
    Elementary,
}

/// The PI controller's constants: safety factor, the weight of the previous error, and a step
/// that shrinks at most 5× and grows at most 10× at once.
const SAFETY: f64 = 0.9;
const BETA: f64 = 0.04;
const FAC_MIN: f64 = 0.2;
const FAC_MAX: f64 = 10.0;

impl StepRule {
    /// The PI rule as it starts (no step accepted yet).
    pub const fn pi() -> Self {
        StepRule::Pi { previous: 1e-4 }
    }

    /// The elementary rule's factor for error norm `err`: 0.9 err^(−1/3) within 0.2 and 5.
    fn elementary(err: f64) -> f64 {
        if err.is_finite() && err > 0.0 {
            (0.9 * err.powf(-1.0 / 3.0)).clamp(0.2, 5.0)
        } else if err == 0.0 {
            5.0
        } else {
            0.2
        }
    }

    /// The step after an accepted step `h` of error norm `err` (`rejected_before`: an attempt of
    /// this step was rejected).
    pub fn after_accept(&self, err: f64, h: f64, rejected_before: bool) -> f64 {
        match *self {
            StepRule::Pi { previous } => {
                let fac11 = err.powf(0.2 - BETA * 0.75);
                let fac =
                    (fac11 / previous.powf(BETA) / SAFETY).clamp(1.0 / FAC_MAX, 1.0 / FAC_MIN);
                let h_next = h / fac;
                if rejected_before {
                    h_next.min(h)
                } else {
                    h_next
                }
            }
            StepRule::Elementary => h * Self::elementary(err),
        }
    }

    /// The step to try after an attempt `h` rejected for its error norm `err`.
    pub fn after_reject(&self, err: f64, h: f64) -> f64 {
        match *self {
            StepRule::Pi { .. } => {
                let shrink = if err.is_finite() {
                    (err.powf(0.2 - BETA * 0.75) / SAFETY).min(1.0 / FAC_MIN)
                } else {
                    1.0 / FAC_MIN
                };
                h / shrink
            }
            StepRule::Elementary => h * Self::elementary(err).min(0.9),
        }
    }

    /// A step of error norm `err` was accepted.
    fn accepted(&mut self, err: f64) {
        if let StepRule::Pi { previous } = self {
            *previous = err.max(1e-4);
        }
    }
}

/// The controller's state a stepper keeps: its rule, the next step, or fixed steps.
#[derive(Debug, Clone)]
pub(crate) struct Controller {
    rule: StepRule,
    /// Fixed steps of at most this (no error control), for convergence-order studies.
    fixed: Option<f64>,
    /// The next step to try (s); `None` until the first is chosen.
    pub h: Option<f64>,
}

impl Controller {
    /// Adaptive steps by `rule`.
    pub fn adaptive(rule: StepRule) -> Self {
        Controller {
            rule,
            fixed: None,
            h: None,
        }
    }

    /// Fixed steps of at most `dt`: every attempt accepted, none shortened.
    pub fn fixed(rule: StepRule, dt: f64) -> Self {
        Controller {
            fixed: Some(dt),
            ..Controller::adaptive(rule)
        }
    }

    /// Whether the steps are fixed.
    pub fn is_fixed(&self) -> bool {
        self.fixed.is_some()
    }

    /// Forget the rule's memory of earlier steps (the state was changed from outside); the step
    /// size is kept.
    pub fn reset(&mut self, rule: StepRule) {
        self.rule = rule;
    }
}

/// Advance `y` from `t` towards `t_end` (never past it) by one accepted step of `stepper` and
/// return the new time; on `Err` the state is left as it was (see the module docs for the
/// reject policy).
pub(crate) fn step<A: Adaptive + ?Sized>(
    stepper: &mut A,
    sys: &mut dyn OdeSystem,
    t: f64,
    y: &mut [f64],
    t_end: f64,
    stats: &mut Stats,
) -> Result<f64, StepFailure> {
    stepper.prepare(sys, t, y, stats)?;
    let c = stepper.controller();
    let (fixed, rule) = (c.fixed, c.rule);
    let mut h = match (fixed, c.h) {
        (Some(dt), _) => uniform_step(t, t_end, dt).0,
        (None, Some(h)) => h,
        (None, None) => stepper.initial_step(sys, t, y, t_end, stats),
    };
    let fixed = fixed.is_some();
    let mut rejected_before = false;
    let mut rejects = 0;
    let scale = sys.time_scale();
    loop {
        let span = t_end - t;
        let (h_try, last) = if h >= span { (span, true) } else { (h, false) };
        let Attempt { err, within } = stepper.attempt(sys, t, y, h_try, stats);
        let t_new = if last { t_end } else { t + h_try };
        let accept = fixed || within;
        let guard = if accept {
            let candidate = stepper.candidate();
            sys.project(candidate);
            check_state(sys, t_new, candidate)
        } else {
            Ok(())
        };
        match (accept, guard) {
            (true, Ok(())) => {
                let h_next = rule.after_accept(err, h_try, rejected_before);
                // A step below the floor that the error estimate does not let grow never gets
                // anywhere (a start from a tiny step grows several times a step instead).
                if !fixed && !last && h_next <= h_try && step_too_small(h_next, t, scale) {
                    return Err(stalled(t_new, h_next, t, scale));
                }
                let c = stepper.controller();
                c.rule.accepted(err);
                // A step clipped to land on t_end says nothing about the natural step size.
                c.h = Some(if last && h_try < h {
                    h.max(h_next)
                } else {
                    h_next
                });
                y.copy_from_slice(stepper.candidate());
                stepper.accepted();
                stats.steps += 1;
                return Ok(t_new);
            }
            (true, Err(failure)) => {
                stats.rejected += 1;
                stats.rejected_by_guard += 1;
                rejects += 1;
                if fixed {
                    return Err(failure);
                }
                h = h_try * 0.25;
                // Crawling towards the event the guard refuses (spheres about to touch): stop
                // with it once the step no longer advances the time, or after MAX_REJECTS.
                if rejects >= MAX_REJECTS || step_too_small(h, t, scale) {
                    stepper.controller().h = Some(h_try);
                    return Err(failure);
                }
            }
            (false, _) => {
                stats.rejected += 1;
                rejects += 1;
                if rejects >= MAX_REJECTS {
                    return Err(tolerance_failure(t_new, h_try, MAX_REJECTS));
                }
                h = rule.after_reject(err, h_try);
                if step_too_small(h, t, scale) {
                    return Err(stalled(t_new, h, t, scale));
                }
            }
        }
        rejected_before = true;
    }
}

/// The failure of an adaptive step whose error estimate stayed above tolerance after `rejects`
/// reductions.
pub(crate) fn tolerance_failure(time: f64, h: f64, rejects: u32) -> StepFailure {
    StepFailure {
        time,
        problem: Problem {
            swimmer: None,
            cause: format!(
                "the error estimate stayed above tolerance after {rejects} step reductions (h = {h:e} s)"
            ),
            hint: "loosen the tolerance, or check the scene for NaN or nearly touching spheres"
                .into(),
            fixes: Vec::new(),
        },
    }
}

/// The shortest adaptive step (s) at time `t` of a system whose time scale is `scale`
/// ([`OdeSystem::time_scale`]): [`MIN_RELATIVE_INTERVAL`] of the longer of the two. Below it a
/// step no longer advances t measurably, or a period would take more than 1e12 steps: at t = 0
/// the time alone sets no floor, and a step the error estimate keeps that small would creep on
/// for ever.
pub(crate) fn step_floor(t: f64, scale: f64) -> f64 {
    MIN_RELATIVE_INTERVAL * t.abs().max(scale)
}

/// Whether an adaptive step `h` (s) at time `t` is below [`step_floor`]. An adaptive method that
/// shrinks its step there is crawling towards an event it cannot pass (two spheres about to
/// touch, where every larger step is refused by the contact guard), or its rates are far beyond
/// what the scene's time scale can carry; it stops with that event's error, or [`stalled`]'s,
/// instead of spinning for ever.
pub(crate) fn step_too_small(h: f64, t: f64, scale: f64) -> bool {
    h < step_floor(t, scale)
}

/// The error of an adaptive method whose error estimate held its step `h` at time `time` below
/// [`step_floor`] of the start time `t` and the time scale `scale`.
pub(crate) fn stalled(time: f64, h: f64, t: f64, scale: f64) -> StepFailure {
    let floor = step_floor(t, scale);
    let basis = if scale > t.abs() {
        format!("{MIN_RELATIVE_INTERVAL:e} of the stroke period {scale:.6e} s: one period would take more than {:e} steps", 1.0 / MIN_RELATIVE_INTERVAL)
    } else {
        format!("what f64 can advance the time by at t = {t:.6e} s")
    };
    StepFailure {
        time,
        problem: Problem {
            swimmer: None,
            cause: format!(
                "the step fell to {h:.3e} s, below {floor:.3e} s ({basis}), to keep the error estimate within tolerance"
            ),
            hint: "loosen the tolerance, or check the scene for NaN or nearly touching spheres"
                .into(),
            fixes: Vec::new(),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// dy/dt = −y whose guard refuses every state past `refuse_after` (s); time scale 1 s.
    struct Decay {
        refuse_after: f64,
    }

    impl OdeSystem for Decay {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) {
            dy[0] = -y[0];
        }
        fn error_scale(&self, _y: &[f64], scale: &mut [f64]) {
            scale[0] = 1.0;
        }
        fn time_scale(&self) -> f64 {
            1.0
        }
        fn check(&mut self, t: f64, _y: &[f64]) -> Result<(), Problem> {
            if t > self.refuse_after {
                return Err(Problem {
                    swimmer: None,
                    cause: "refused".into(),
                    hint: String::new(),
                    fixes: Vec::new(),
                });
            }
            Ok(())
        }
    }

    /// Euler steps of dy/dt = −y whose error norm is always `err`.
    struct Stub {
        control: Controller,
        err: f64,
        y_new: Vec<f64>,
    }

    impl Stub {
        fn new(control: Controller, err: f64) -> Self {
            Stub {
                control,
                err,
                y_new: vec![0.0],
            }
        }
    }

    impl Adaptive for Stub {
        fn controller(&mut self) -> &mut Controller {
            &mut self.control
        }
        fn prepare(
            &mut self,
            _sys: &mut dyn OdeSystem,
            _t: f64,
            _y: &[f64],
            _stats: &mut Stats,
        ) -> Result<(), StepFailure> {
            Ok(())
        }
        fn initial_step(
            &mut self,
            _sys: &mut dyn OdeSystem,
            _t: f64,
            _y: &[f64],
            _t_end: f64,
            _stats: &mut Stats,
        ) -> f64 {
            0.1
        }
        fn attempt(
            &mut self,
            _sys: &mut dyn OdeSystem,
            _t: f64,
            y: &[f64],
            h: f64,
            _stats: &mut Stats,
        ) -> Attempt {
            self.y_new[0] = y[0] * (1.0 - h);
            Attempt::of_norm(self.err)
        }
        fn candidate(&mut self) -> &mut [f64] {
            &mut self.y_new
        }
    }

    /// A fixed step that fails a guard fails at once, the state unchanged: never shortened;
    /// and a fixed step is accepted whatever its error norm.
    #[test]
    fn a_fixed_step_is_never_shortened() {
        for rule in [StepRule::pi(), StepRule::Elementary] {
            let mut st = Stub::new(Controller::fixed(rule, 0.1), 1e3);
            let mut y = [1.0];
            let mut stats = Stats::default();
            let mut sys = Decay { refuse_after: 0.0 };
            let failure = step(&mut st, &mut sys, 0.0, &mut y, 1.0, &mut stats);
            assert_eq!(failure.unwrap_err().time, 0.1);
            assert_eq!(y, [1.0]);
            assert_eq!((stats.rejected_by_guard, stats.steps), (1, 0));
            let mut sys = Decay { refuse_after: 1.0 };
            assert_eq!(
                step(&mut st, &mut sys, 0.0, &mut y, 1.0, &mut stats),
                Ok(0.1)
            );
            assert_eq!(y, [0.9]);
        }
    }

    /// A guard that gives up leaves the next step at the last one tried, whatever the rule.
    #[test]
    fn a_guard_giving_up_keeps_the_last_step_tried() {
        for rule in [StepRule::pi(), StepRule::Elementary] {
            let mut st = Stub::new(Controller::adaptive(rule), 0.5);
            let mut y = [1.0];
            let mut stats = Stats::default();
            let mut sys = Decay { refuse_after: 0.0 };
            assert!(step(&mut st, &mut sys, 0.0, &mut y, 1.0, &mut stats).is_err());
            let h = st.control.h.expect("a step was kept");
            // The last step tried is the first whose quarter falls below the floor (1e-12 s).
            assert!((1e-12..4e-12).contains(&h), "{h:e}");
            assert_eq!(stats.rejected, stats.rejected_by_guard);
            assert_eq!(y, [1.0]);
        }
    }

    /// An error norm that never meets the tolerance fails after MAX_REJECTS attempts, or once
    /// the step falls below the floor.
    #[test]
    fn a_tolerance_never_met_fails() {
        let mut st = Stub::new(Controller::adaptive(StepRule::Elementary), 1.5);
        let mut stats = Stats::default();
        let f = step(
            &mut st,
            &mut Decay { refuse_after: 9.0 },
            0.0,
            &mut [1.0],
            1.0,
            &mut stats,
        );
        let cause = f.unwrap_err().problem.cause;
        assert!(cause.contains("after 60 step reductions"), "{cause}");
        assert_eq!(stats.rejected, u64::from(MAX_REJECTS));
        let mut st = Stub::new(Controller::adaptive(StepRule::pi()), f64::NAN);
        let f = step(
            &mut st,
            &mut Decay { refuse_after: 9.0 },
            0.0,
            &mut [1.0],
            1.0,
            &mut stats,
        );
        let cause = f.unwrap_err().problem.cause;
        assert!(cause.contains("the step fell to"), "{cause}");
    }

    /// The rules' arithmetic: the PI rule does not grow a step right after a rejection; the
    /// elementary rule grows at most 5× and shrinks a rejected step at least to 0.9 of it.
    #[test]
    fn the_step_rules() {
        let pi = StepRule::pi();
        assert!(pi.after_accept(1e-3, 1.0, false) > 1.0);
        assert_eq!(pi.after_accept(1e-3, 1.0, true), 1.0);
        assert_eq!(pi.after_reject(f64::NAN, 1.0), 0.2);
        let e = StepRule::Elementary;
        assert_eq!(e.after_accept(0.0, 1.0, false), 5.0);
        assert_eq!(e.after_reject(0.5, 1.0), 0.9);
        assert_eq!(e.after_reject(f64::INFINITY, 1.0), 0.2);
    }
}
