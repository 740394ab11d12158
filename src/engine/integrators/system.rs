//! The contract between models and integrators.

use crate::engine::error::{invalid, Setting};
use nalgebra::{DMatrix, Vector3};
use serde::{Deserialize, Serialize};

/// A first-order system dy/dt = f(t, y) with the hooks the integrators need.
pub trait OdeSystem {
    /// Number of state components.
    fn dim(&self) -> usize;
    /// Evaluate the right-hand side f(t, y) into `dy`.
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]);
    /// Absolute size of each component that a relative tolerance refers to: an adaptive step is
    /// accepted when |error_i| ≲ rtol · scale_i.
    fn error_scale(&self, y: &[f64], scale: &mut [f64]);
    /// The time the dynamics unfold on (s): the shortest stroke period for the swimmer models.
    /// An adaptive step below [`MIN_RELATIVE_INTERVAL`] of it (or of t, whichever is longer)
    /// stops the run ([`step_too_small`](super::controller::step_too_small)): one such period would take more than 1e12 steps. 0
    /// (the default): steps are held to t alone.
    fn time_scale(&self) -> f64 {
        0.0
    }
    /// Check a freshly computed state (NaN, overlap, ...). `Err` rejects the step.
    fn check(&mut self, _t: f64, _y: &[f64]) -> Result<(), Problem> {
        Ok(())
    }
    /// Map a state back onto its manifold after a step (e.g. renormalise unit vectors).
    fn project(&self, _y: &mut [f64]) {}
    /// The fast variables of state `y` (a spring's length, one per swimmer), appended to `out`;
    /// none by default. Stroboscopic averaging extrapolates slow motion: it extrapolates these by
    /// their rates on the slow manifold and sets them ([`OdeSystem::set_fast_variables`]) in an
    /// extrapolated state, keeping it next to the manifold (a turn extrapolated linearly would
    /// stretch a dumbbell), so no period need relax it.
    fn fast_variables(&self, _y: &[f64], _out: &mut Vec<f64>) {}
    /// Give `y` the fast variables `fast`, keeping its slow ones (centres, directions).
    fn set_fast_variables(&self, _y: &mut [f64], _fast: &[f64]) {}
    /// Size of the diagonal blocks of the approximate Jacobian [`OdeSystem::jacobian_blocks`]
    /// offers (0: none; linearly implicit methods then treat the system as non-stiff).
    fn jacobian_block(&self) -> usize {
        0
    }
    /// The diagonal blocks of (an approximation to) ∂f/∂y at (t, y), row-major, one after another.
    /// The models put the stiff part there: each dumbbell's own spring, drag and hydrodynamics.
    fn jacobian_blocks(&mut self, _t: f64, _y: &[f64], _out: &mut [f64]) {}
    /// Whether f does not depend on t (linearly implicit methods then skip ∂f/∂t).
    fn autonomous(&self) -> bool {
        false
    }
    /// The sparse stiff part of ∂f/∂y at (t, y) for linearly implicit methods that take one
    /// (`suspension`): dense blocks on disjoint groups of state components (the swimmers of one
    /// cluster in steric contact), zero elsewhere. None by default.
    fn stiff_groups(&mut self, _t: f64, _y: &[f64]) -> GroupJacobian {
        GroupJacobian::default()
    }
    /// The norm of an adaptive step's error estimate `err`, for a step from `y` to `y_new` of
    /// size `h` whose rates at `y` were `f0`, at tolerance `tol`: ≤ 1 accepts the step. By
    /// default the RMS of err/(tol·scale) with [`OdeSystem::error_scale`] at `y`.
    fn step_error_norm(
        &self,
        y: &[f64],
        _y_new: &[f64],
        err: &[f64],
        _h: f64,
        _f0: &[f64],
        tol: f64,
    ) -> f64 {
        let mut scale = vec![0.0; y.len()];
        self.error_scale(y, &mut scale);
        let sum: f64 = err
            .iter()
            .zip(&scale)
            .map(|(e, s)| (e / (tol * s)).powi(2))
            .sum();
        (sum / y.len().max(1) as f64).sqrt()
    }
    /// The system as bodies that can be stepped apart (multirate methods); `None` by default.
    fn as_partitioned(&mut self) -> Option<&mut dyn Partitioned> {
        None
    }
    /// Thermal noise: the Itô system dy = f dt + B(t, y) dW. `None` (the default): deterministic.
    fn noise(&self) -> Option<Noise> {
        None
    }
    /// Add one step's stochastic increment to `y_new`, which holds the deterministic update:
    /// B(t, y)·dw for the Wiener increments `dw` (one per noise dimension, variance h each). A
    /// model whose state has a constraint (a unit orientation) applies it on the constraint.
    fn add_noise(
        &mut self,
        _t: f64,
        _y: &[f64],
        _dw: &[f64],
        _y_new: &mut [f64],
    ) -> Result<(), Problem> {
        Ok(())
    }
    /// The diffusion matrix B(t, y) (dim × noise dimension), for weak schemes that need its
    /// columns at several points.
    fn diffusion(&mut self, _t: f64, _y: &[f64], _b: &mut DMatrix<f64>) -> Result<(), Problem> {
        Err(Problem {
            swimmer: None,
            cause: "this model gives no diffusion matrix".into(),
            hint: "use euler(dt), Euler-Maruyama".into(),
            fixes: Vec::new(),
        })
    }
}

/// A system of bodies (swimmers) with [`Partitioned::body_size`] state components each, that a
/// multirate method steps body by body: some bodies take shorter steps than others, reading the
/// states of the rest from an interpolation.
pub trait Partitioned: Sync {
    /// State components per body (the state is the bodies' blocks one after another).
    fn body_size(&self) -> usize;
    /// Each body's error of a step (its embedded estimate `err`, measured by `m`: relative to
    /// `m.tol` of the body's own motion, ≤ 1 within tolerance), for `bodies` (all when `None`),
    /// into `out` (one per body, indexed by body). `floor`: the motion scales below which a
    /// body's own motion is not taken, per unit of step; computed over all bodies when `None` on
    /// entry and left there.
    fn body_errors(
        &self,
        err: &[f64],
        m: &ErrorMeasure,
        bodies: Option<&[usize]>,
        floor: &mut Option<Vec<f64>>,
        out: &mut [f64],
    );
    /// Into `out`, the bodies (not in `bodies`, sorted, each once) whose states the rates of
    /// `bodies` read.
    fn partners(&self, bodies: &[usize], out: &mut Vec<usize>);
    /// The rates of `bodies` at state `y` into their blocks of `dy` (other blocks untouched), the
    /// states of the bodies `changed` having changed since the last evaluation (the others as
    /// then).
    fn rhs_bodies(
        &mut self,
        t: f64,
        y: &[f64],
        bodies: &[usize],
        changed: &[usize],
        dy: &mut [f64],
    );
    /// The stiff groups among `bodies` at `y`, or, when one of them would couple a body of
    /// `bodies` to one outside (a contact forming with a body stepped apart), the bodies of every
    /// such coupling, both ends, sorted.
    fn stiff_groups_of(
        &self,
        t: f64,
        y: &[f64],
        bodies: &[usize],
    ) -> Result<GroupJacobian, Vec<usize>>;
    /// Whether [`Partitioned::rates_shared`] can answer (else it always refuses).
    fn shares_rates(&self) -> bool {
        false
    }
    /// The rates of `bodies` at `y` into their blocks of `dy`, as [`Partitioned::rhs_bodies`]
    /// gives them, without changing the system (so on several threads at once): false, with
    /// `dy` untouched, when the states of `changed` need the system updated first.
    fn rates_shared(&self, y: &[f64], bodies: &[usize], changed: &[usize], dy: &mut [f64]) -> bool {
        let _ = (y, bodies, changed, dy);
        false
    }
    /// How much reading the bodies `sources` (sorted) at their states in `after` instead of
    /// `before` (`[before, after]`) changes the rates of `bodies`, each taken at its state in
    /// `before`: h times that change as an error of a step of `m.h` ([`Partitioned::body_errors`]'s
    /// measure, with its `floor`), into `out` (indexed by body).
    fn read_errors(
        &self,
        views: [&[f64]; 2],
        bodies: &[usize],
        sources: &[usize],
        m: &ErrorMeasure,
        floor: &[f64],
        out: &mut [f64],
    );
}

/// How a step's error is measured against the motion: the step's length `h` (s), the rates `f0`
/// at its start, and the tolerance `tol`.
#[derive(Debug, Clone, Copy)]
pub struct ErrorMeasure<'a> {
    /// The step (s).
    pub h: f64,
    /// The rates at the step's start.
    pub f0: &'a [f64],
    /// The tolerance, relative to each body's own motion.
    pub tol: f64,
}

/// A block-sparse matrix: a dense square block on each of several disjoint groups of state
/// components, zero elsewhere (J = Σ_g P_gᵀ J_g P_g).
#[derive(Debug, Clone, Default)]
pub struct GroupJacobian {
    /// Each group: its state components and its block (row-major, components × components).
    pub groups: Vec<(Vec<usize>, Vec<f64>)>,
}

impl GroupJacobian {
    /// Whether it has no group (J = 0).
    pub fn is_empty(&self) -> bool {
        self.groups.is_empty()
    }

    /// `out` += J·v (only the groups' components change).
    pub fn add_product(&self, v: &[f64], out: &mut [f64]) {
        for (idx, block) in &self.groups {
            let m = idx.len();
            for (r, &i) in idx.iter().enumerate() {
                let row = &block[r * m..(r + 1) * m];
                out[i] += row.iter().zip(idx).map(|(a, &j)| a * v[j]).sum::<f64>();
            }
        }
    }

    /// The LU factors of I − c·J_g for every group.
    pub fn factor_shifted(&self, c: f64) -> Vec<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>> {
        self.groups
            .iter()
            .map(|(idx, block)| {
                let m = idx.len();
                DMatrix::from_fn(m, m, |r, q| {
                    f64::from(u8::from(r == q)) - c * block[r * m + q]
                })
                .lu()
            })
            .collect()
    }

    /// b ← (I − c·J)⁻¹ b with `lus` from [`GroupJacobian::factor_shifted`] (identity outside the
    /// groups). A singular block leaves NaN in its components (the step is then rejected).
    pub fn solve_shifted(
        &self,
        lus: &[nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>],
        b: &mut [f64],
    ) {
        for ((idx, _), lu) in self.groups.iter().zip(lus) {
            let mut x = nalgebra::DVector::from_iterator(idx.len(), idx.iter().map(|&i| b[i]));
            if !lu.solve_mut(&mut x) {
                x.fill(f64::NAN);
            }
            for (k, &i) in idx.iter().enumerate() {
                b[i] = x[k];
            }
        }
    }
}

/// The thermal noise of a system: its generator's seed and the number of independent Wiener
/// processes driving it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Noise {
    /// Seed of the counter-based generator ([`super::philox`]); its counter is the step count
    /// [`Stats::noisy_steps`].
    pub seed: u64,
    /// Number of independent Wiener processes.
    pub dim: usize,
}

/// What made a state unacceptable.
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    /// The swimmer concerned, if one can be named.
    pub swimmer: Option<usize>,
    /// What is wrong.
    pub cause: String,
    /// What to change.
    pub hint: String,
    /// Settings that would avoid it.
    pub fixes: Vec<crate::engine::error::Setting>,
}

/// How far from the origin a swimmer's centre may go (m, in each coordinate), for the guard the
/// swimmer models apply in [`OdeSystem::check`]: a step that takes a centre beyond it fails like
/// any other failed step. The scene sets it, with the words that say why it lies there (where
/// f64 stops resolving the spheres); unbounded by default.
#[derive(Debug, Clone, PartialEq)]
pub struct Reach {
    /// The largest |coordinate| of a centre (m).
    pub limit: f64,
    /// Why the limit lies there, in words for the message.
    pub why: String,
}

impl Default for Reach {
    fn default() -> Self {
        Reach {
            limit: f64::INFINITY,
            why: String::new(),
        }
    }
}

impl Reach {
    /// Swimmer `s`'s centre `c` within the limit, or the problem naming the coordinate beyond it.
    pub fn check(&self, s: usize, c: &Vector3<f64>) -> Result<(), Problem> {
        for (k, x) in ["x", "y", "z"].iter().zip(c.iter()) {
            if x.abs() > self.limit {
                return Err(Problem {
                    swimmer: Some(s),
                    cause: format!(
                        "the centre of swimmer {s} reached {k} = {x:e} m, beyond the {:e} m from the origin that positions may reach ({})",
                        self.limit, self.why
                    ),
                    hint: "start the swimmers nearer the origin, or run a shorter time".into(),
                    fixes: Vec::new(),
                });
            }
        }
        Ok(())
    }
}

/// A step that could not be completed; the caller's state is unchanged.
#[derive(Debug, Clone, PartialEq)]
pub struct StepFailure {
    /// Time of the rejected state.
    pub time: f64,
    /// Why it was rejected.
    pub problem: Problem,
}

/// Work counters of a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Stats {
    /// Accepted steps.
    pub steps: u64,
    /// Rejected step attempts (error too large or bad state).
    pub rejected: u64,
    /// Right-hand-side evaluations.
    pub rhs_evals: u64,
    /// Of the rejected attempts, those whose state failed a guard (NaN, overlap, runaway spring).
    #[serde(default)]
    pub rejected_by_guard: u64,
    /// Accepted macro steps of stroboscopic averaging (saved only when non-zero).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub macro_steps: u64,
    /// Microscopic periods stroboscopic averaging integrated (samples, transients, remainders).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub micro_periods: u64,
    /// Steps of bodies taken apart inside a multirate method's steps (`suspension`'s refined
    /// swimmers; saved only when non-zero).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub refined_steps: u64,
    /// Steps taken with thermal noise; also the noise generator's counter, so that a run split in
    /// two, or saved and loaded between, draws the same noise (saved only when non-zero).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub noisy_steps: u64,
    /// Times stroboscopic averaging's macro steps failed at their shortest length, or would have
    /// been too short to pay for their samples, and it integrated directly instead (saved only
    /// when non-zero).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub direct_fallbacks: u64,
    /// Periods those fallbacks integrated directly (saved only when non-zero).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub fallback_periods: u64,
}

fn is_zero(n: &u64) -> bool {
    *n == 0
}

/// Asked at step boundaries whether a run should stop (e.g. after Ctrl-C). It must be cheap.
pub type Interrupt = std::sync::Arc<dyn Fn() -> bool + Send + Sync>;

/// Shown the time and state inside a long step (stroboscopic averaging's direct periods), as a
/// live view is shown the scene between steps. It must be cheap: it decides itself whether to
/// read the state.
pub type StateWatch = std::sync::Arc<dyn Fn(f64, &[f64]) + Send + Sync>;

/// One time-stepping method.
pub trait Stepper: Send + Sync {
    /// Advance `y` from `t` towards `t_end` (never past it) and return the new time. On `Err` the
    /// state `y` is left as it was.
    fn step(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &mut [f64],
        t_end: f64,
        stats: &mut Stats,
    ) -> Result<f64, StepFailure>;

    /// Forget anything cached about the previous state (call when the state was changed from outside).
    fn reset(&mut self) {}

    /// A stepper whose one step is long (many periods) asks `interrupt` inside it and gives the
    /// step up, state unchanged, with a failure; the caller, seeing the interrupt set, reports
    /// the interrupt. Steppers of one short step ignore it (their caller asks between steps).
    fn set_interrupt(&mut self, _interrupt: Option<Interrupt>) {}

    /// Whether one step may hold many inner steps of the physical state worth watching one by
    /// one (stroboscopic averaging's direct periods): such a stepper takes a [`StateWatch`].
    fn watches_inside(&self) -> bool {
        false
    }

    /// Show `watch` the time and state after each inner step of the physical state (`None`: no
    /// one); steppers whose steps are short ignore it (their caller looks between steps).
    fn set_watch(&mut self, _watch: Option<StateWatch>) {}

    /// An adaptive method's next step from (t, y), its starting step computed if it has none
    /// (which may evaluate the right-hand side); `None` for a method of fixed steps. Another
    /// backend (the GPU) takes the steps from there.
    fn next_step(
        &mut self,
        _sys: &mut dyn OdeSystem,
        _t: f64,
        _y: &[f64],
        _stats: &mut Stats,
    ) -> Option<f64> {
        None
    }

    /// Go on with `h` as the next step, after another backend took the steps before (the state
    /// changed outside: nothing cached about it is kept).
    fn continue_with_step(&mut self, _h: f64) {}

    /// What this stepper did that its name does not say, in words (stroboscopic averaging that
    /// fell back to direct integration, and why); `None` when there is nothing to add.
    fn report(&self) -> Option<String> {
        None
    }
}

/// Size every scratch buffer of a stepper to the state's length (allocates only when it grows).
pub(crate) fn fit(n: usize, buffers: &mut [&mut Vec<f64>]) {
    for b in buffers {
        b.resize(n, 0.0);
    }
}

/// ∂f/∂t at (t, y) into `ft` by a forward difference over 1e-7 of the time and step scale `h`
/// (W-methods need only an approximation), given `f0` = f(t, y); one right-hand side.
pub(crate) fn time_derivative(
    sys: &mut dyn OdeSystem,
    t: f64,
    y: &[f64],
    h: f64,
    f0: &[f64],
    ft: &mut [f64],
    stats: &mut Stats,
) {
    let dt_probe = 1e-7 * (t.abs() + h).max(1e-12);
    sys.rhs(t + dt_probe, y, ft);
    stats.rhs_evals += 1;
    for (d, f) in ft.iter_mut().zip(f0) {
        *d = (*d - f) / dt_probe;
    }
}

/// Step size of a fixed-step method: the largest h ≤ dt that divides the remaining span evenly, so
/// a run ends exactly at `t_end`. Returns (h, is_last).
pub(crate) fn uniform_step(t: f64, t_end: f64, dt: f64) -> (f64, bool) {
    let (n, h) = uniform_steps(t, t_end, dt);
    (h, n <= 1)
}

/// The number of steps of at most `dt` that a fixed-step method takes from `t` to `t_end`, and
/// their size (the first step of [`uniform_step`]'s sequence).
pub fn uniform_steps(t: f64, t_end: f64, dt: f64) -> (u64, f64) {
    let span = t_end - t;
    // The 1e-9 slack keeps span = k·dt from turning into k+1 steps through rounding.
    let n = (span / dt - 1e-9).ceil().max(1.0);
    (n as u64, span / n)
}

/// Finite-value guard shared by all steppers, applied before the model's own check. It sees the
/// new state only, so its hint names the usual cause (a step beyond an explicit method's
/// stability limit, which grows the state without bound) without blaming any one part of the
/// model; the scene adds what it can tell from its settings (see `Scene::explain_failure`).
pub(crate) fn check_state(sys: &mut dyn OdeSystem, t: f64, y: &[f64]) -> Result<(), StepFailure> {
    if let Some(i) = y.iter().position(|v| !v.is_finite()) {
        return Err(StepFailure {
            time: t,
            problem: Problem {
                swimmer: None,
                cause: format!("state component {i} became NaN or infinite"),
                hint: "use a smaller time step (an explicit step beyond its stability limit grows the state without bound) or an adaptive integrator"
                    .into(),
                fixes: vec![Setting::StableStep, Setting::DefaultIntegrator],
            },
        });
    }
    sys.check(t, y)
        .map_err(|problem| StepFailure { time: t, problem })
}

/// The finest interval (a step, a recorder's period) relative to the times it is used at: below
/// this, consecutive steps or due times can no longer be told apart in f64.
pub const MIN_RELATIVE_INTERVAL: f64 = 1e-12;

/// [`OdeSystem::time_scale`] of a system whose dynamics unfold on `period` (s): the period, or 0
/// (no scale: steps held to t alone) where it is not finite, as a scene without swimmers has it.
pub fn time_scale_of(period: f64) -> f64 {
    if period.is_finite() {
        period
    } else {
        0.0
    }
}

/// Refuse an interval `dt` (s) that f64 cannot tell apart at times of size `scale` (s): below
/// [`MIN_RELATIVE_INTERVAL`] of them, consecutive due times or steps round to the same time.
/// `what` names the interval (with its value) in the message, `fix` says what to change.
pub fn require_resolvable(
    what: &str,
    dt: f64,
    scale: f64,
    fix: &str,
) -> crate::engine::error::Result<()> {
    let floor = MIN_RELATIVE_INTERVAL * scale.abs();
    if dt > 0.0 && dt >= floor {
        return Ok(());
    }
    Err(invalid!(
        "{what} cannot be resolved at t = {scale:e} s, so it cannot advance the time: f64 tells times apart only down to ~{floor:e} s there; {fix}"
    ))
}
