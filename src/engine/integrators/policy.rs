//! The integrator policy: the defaults the models run, `auto`'s choice, stroboscopic averaging's
//! inner method and start transient, what thermal noise refuses, and the RK4 constants behind
//! them. The policy reads a scene through plain numbers ([`Facts`]) and each model's answers
//! (passed in by the caller), so it knows neither.

use super::{IntegratorSpec, MIN_MACRO};
use crate::engine::error::{invalid, unsupported, EngineError, Result, Setting};

/// The microscopic model's default RK4 step times the stiffest spring's relaxation rate. RK4 is
/// stable up to 2.785; at 0.8 the stroke-induced wobble of an isolated asymmetric dumbbell's R_H
/// closes to far below the Fig-1 drift each period, where a step near the stability bound would
/// leave a visible share of it (the measurement is in the book's design notes). The error falls
/// as dt⁵ (the book, "Integrators and accuracy").
pub const DEFAULT_MICRO_STEP_TIMES_RATE: f64 = 0.8;
/// With thermal noise the spring model's default Euler-Maruyama step times the stiffest spring's
/// relaxation rate: Euler-Maruyama overestimates a spring's length variance kT/k0 by 1/(1 − 0.05).
pub const DEFAULT_NOISY_STEP_TIMES_RATE: f64 = 0.1;
/// The default step never exceeds this fraction of the shortest period, so that soft springs
/// (small k0) still resolve the stroke.
pub const DEFAULT_MICRO_MAX_STEP_PER_PERIOD: f64 = 1.0 / 200.0;
/// Default tolerance of the rigid-stroke model's adaptive integrator (the book, "Integrators and accuracy").
pub const DEFAULT_RIGID_RTOL: f64 = 1e-7;
/// The tolerance of `auto(tol)`, the default of the spring and rigid-stroke models without noise,
/// relative to the drift: ten times [`RK4_DEFAULT_DRIFT_ERROR`], so that auto's inner RK4,
/// which steps where its drift error is a tenth of tol, steps at exactly the direct step
/// 0.8/rate. Runs that cannot be averaged are then the direct RK4 runs bit for bit; a larger
/// inner step errs on the drift of pairs far apart (a swimmer's own stroke error does not shrink
/// with the interaction; the book, "Long runs").
pub const DEFAULT_AUTO_TOL: f64 = 1.1e-5;
/// Default tolerance of the averaged model's adaptive integrator.
pub const DEFAULT_AVERAGED_RTOL: f64 = 1e-8;
/// Default tolerance of `suspension(tol)`, the averaged model's default for a suspension: the
/// loosest decade whose displacements stay well within 1e-3 (RMS, relative) of fine RK4 on a
/// suspension with steric contacts (the book, "Suspensions, boxes and fields").
pub const DEFAULT_SUSPENSION_TOL: f64 = 1e-3;

/// The relative drift error of the spring model's default RK4 step: the Fig-1 mirror pair over 100
/// periods from t = 0 against dopri5(1e-11), rounded up from its measurement (the book's design
/// notes).
pub const RK4_DEFAULT_DRIFT_ERROR: f64 = 1.1e-6;

/// The largest inner RK4 step of stroboscopic averaging, in units of 1/rate (rate = the stiffest
/// spring's k0(1/γ1 + 1/γ2)): RK4's stability bound on the negative real axis is 2.785 (the
/// hydrodynamic interaction slows the spring mode, so the true limit lies higher, as
/// `bench stability` shows: the book's design notes), so 2.5 keeps a tenth in hand. At tol 1e-3
/// the accuracy-bound step, 2.47/rate, is below it.
pub const RK4_STABLE_STEP_RATE: f64 = 2.5;

/// RK4 steps per period above which the springs count as stiff: `auto` and stroboscopic
/// averaging then sample with rosw, whose steps the springs do not limit.
pub const STIFF_STEPS_PER_PERIOD: f64 = 2e4;

/// The most swimmers Platen's scheme takes: it factors the 6S×6S mobility 4·6S + 1 times a step.
pub const PLATEN_MAX_SWIMMERS: usize = 16;

/// The most spheres a dense Cholesky factor of the mobility is made for (a 12,288² matrix, 1.2 GB).
pub const CHOLESKY_LIMIT_SPHERES: usize = 4096;

/// e^-37 ≈ 1e-16: a spring mode relaxed this many e-foldings is gone to round-off.
const RELAXED_E_FOLDINGS: f64 = 37.0;

/// What the policy reads of a scene: plain numbers, so that it knows no scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Facts {
    /// The number of swimmers.
    pub swimmers: usize,
    /// The shortest stroke period (s); infinite without swimmers.
    pub shortest_period: f64,
    /// The largest spring relaxation rate k0 (1/γ1 + 1/γ2) (1/s); 0 without swimmers.
    pub stiff_rate: f64,
    /// The smallest spring relaxation rate (1/s); infinite without swimmers.
    pub slowest_rate: f64,
}

impl Facts {
    /// The spring model's default RK4 step (s): [`DEFAULT_MICRO_STEP_TIMES_RATE`]/rate of the
    /// stiffest spring, at most [`DEFAULT_MICRO_MAX_STEP_PER_PERIOD`] of the shortest period.
    pub fn rk4_step(&self) -> f64 {
        let dt = (DEFAULT_MICRO_STEP_TIMES_RATE / self.stiff_rate)
            .min(DEFAULT_MICRO_MAX_STEP_PER_PERIOD * self.shortest_period);
        if dt.is_finite() {
            dt
        } else {
            1e-6
        }
    }

    /// The spring model's Euler-Maruyama step with thermal noise (s, before
    /// [`noisy_euler`]'s fallback): [`DEFAULT_NOISY_STEP_TIMES_RATE`]/rate (a spring's stationary
    /// variance comes out high by the factor 1/(1 − rate·dt/2), 5%), at most
    /// [`DEFAULT_MICRO_MAX_STEP_PER_PERIOD`] of the shortest period.
    pub fn noisy_spring_step(&self) -> f64 {
        (DEFAULT_NOISY_STEP_TIMES_RATE / self.stiff_rate)
            .min(DEFAULT_MICRO_MAX_STEP_PER_PERIOD * self.shortest_period)
    }

    /// RK4 steps per shortest period at the stability-bounded step [`RK4_STABLE_STEP_RATE`]/rate.
    pub fn stiff_steps_per_period(&self) -> f64 {
        self.shortest_period * self.stiff_rate / RK4_STABLE_STEP_RATE
    }

    /// Whether the springs are so stiff that RK4 would take more than
    /// [`STIFF_STEPS_PER_PERIOD`] steps a period.
    pub fn stiff(&self) -> bool {
        self.stiff_steps_per_period() > STIFF_STEPS_PER_PERIOD
    }

    /// Stroboscopic averaging's inner RK4 at the step whose drift error is a tenth of `tol`: RK4's
    /// error falls as dt⁴ from [`RK4_DEFAULT_DRIFT_ERROR`] at the default step, and the step stays
    /// below [`RK4_STABLE_STEP_RATE`]/rate and 1/100 of the period (a fixed step keeps the sampled
    /// map smooth in the state).
    pub fn rk4_inner(&self, tol: f64) -> IntegratorSpec {
        let dt0 = self.rk4_step();
        let f = (0.1 * tol / RK4_DEFAULT_DRIFT_ERROR).powf(0.25);
        let dt = if f < 1.0 {
            dt0 * f
        } else {
            (dt0 * f)
                .min(RK4_STABLE_STEP_RATE / self.stiff_rate)
                .min(self.shortest_period / 100.0)
                .max(dt0)
        };
        IntegratorSpec::Rk4 { dt }
    }

    /// Periods integrated directly after a start of stroboscopic averaging over `period` (s),
    /// for the springs to settle from L(0): twice the e-foldings at the slowest isolated rate
    /// (the hydrodynamic interaction slows a spring's mode, by less than that factor: bench
    /// stability, the book's design notes).
    pub fn spring_settling_periods(&self, period: f64) -> u32 {
        (2.0 * RELAXED_E_FOLDINGS / (self.slowest_rate * period))
            .ceil()
            .clamp(1.0, 1e4) as u32
    }
}

/// Euler-Maruyama at step `dt` (s), or 1e-6 s where `dt` is not finite (no swimmers).
pub fn noisy_euler(dt: f64) -> IntegratorSpec {
    IntegratorSpec::Euler {
        dt: if dt.is_finite() { dt } else { 1e-6 },
    }
}

/// What `auto(tol)` runs, and why: the suspension stepper for a suspension of the averaged
/// model; else the model's own direct method where it has one (`direct`: the averaged model is
/// not stiff); else stroboscopic averaging over the common period, sampled by the model's inner
/// method (runs of fewer than [`MIN_MACRO`] periods, the start transient and rows between period
/// multiples take that inner method directly), and without a common period the inner method
/// directly.
pub fn auto_choice(
    tol: f64,
    suspension: bool,
    direct: impl FnOnce(f64) -> Option<(IntegratorSpec, String)>,
    inner: impl FnOnce(f64) -> IntegratorSpec,
    common_period: impl FnOnce() -> Result<f64>,
) -> Result<(IntegratorSpec, String)> {
    if suspension {
        return Ok((
            IntegratorSpec::Suspension { tol },
            "a suspension of the averaged model: each swimmer's error held to tol of its own displacement, steric contacts implicit, a few fast swimmers stepped apart".into(),
        ));
    }
    if let Some(chosen) = direct(tol) {
        return Ok(chosen);
    }
    let inner = inner(tol);
    Ok(match common_period() {
        Ok(t) => (
            IntegratorSpec::Stroboscopic {
                tol,
                inner: Some(inner.try_into()?),
            },
            format!("stroboscopic averaging over the common period {t:.6e} s, sampled by {inner}; runs of fewer than {MIN_MACRO} periods, the start transient and rows between period multiples run {inner} directly"),
        ),
        Err(e) => (inner, format!("{inner} directly, without averaging: {e}")),
    })
}

/// What thermal noise at `temperature` (K) refuses of integrator `spec` beyond what the model
/// itself refuses: a deterministic integrator, Platen's scheme where the model has no diffusion
/// matrix for it (`platen_refused`) or for more than [`PLATEN_MAX_SWIMMERS`] swimmers, and a dense
/// Cholesky factor of more than [`CHOLESKY_LIMIT_SPHERES`] spheres (`dense_spheres`: the spheres
/// whose mobility the noise factors densely, if it does).
pub fn check_noise(
    spec: IntegratorSpec,
    temperature: f64,
    swimmers: usize,
    platen_refused: impl FnOnce() -> Option<EngineError>,
    dense_spheres: Option<usize>,
) -> Result<()> {
    let t = temperature;
    if !spec.takes_noise() {
        return Err(unsupported(
            format!("{spec} is a deterministic method and cannot carry thermal noise (temperature {t} K): a Brownian path is nowhere smooth, which adaptive error control and stroboscopic averaging assume, so the noise needs a stochastic scheme"),
            &[Setting::NoiseIntegrator, Setting::DefaultIntegrator, Setting::NoNoise],
        ));
    }
    if let IntegratorSpec::Platen { .. } = spec {
        if let Some(e) = platen_refused() {
            return Err(e);
        }
        if swimmers > PLATEN_MAX_SWIMMERS {
            return Err(invalid!(
                "{spec} factors the mobility at 4m + 1 states a step (m = 6 per swimmer), a cost growing as the swimmer count to the 4th power; it takes at most {PLATEN_MAX_SWIMMERS} swimmers, this scene has {swimmers}: use euler(dt) with a smaller step"
            ));
        }
    }
    if let Some(spheres) = dense_spheres.filter(|n| *n > CHOLESKY_LIMIT_SPHERES) {
        return Err(invalid!(
            "the dense Cholesky factor of {spheres} spheres needs a {0}x{0} matrix ({1:.1} GB) and O(N^3) work every step; use the Lanczos square root (noise root \"lanczos\" or \"auto\")",
            3 * spheres,
            (3 * spheres) as f64 * (3 * spheres) as f64 * 8e-9
        ));
    }
    Ok(())
}
