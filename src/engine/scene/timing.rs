//! The strokes' periods (one, common, shortest), the stiffest spring's rate, and the integrator a
//! scene takes: the one set, or the model's default for these swimmers.

use super::*;

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
/// relative to the drift: ten times [`dynamics::RK4_DEFAULT_DRIFT_ERROR`], so that auto's inner RK4,
/// which steps where its drift error is a tenth of tol, steps at exactly the direct step
/// 0.8/rate. Runs that cannot be averaged are then the direct RK4 runs bit for bit; a larger
/// inner step errs on the drift of pairs far apart (a swimmer's own stroke error does not shrink
/// with the interaction; the book, "Long runs").
pub const DEFAULT_AUTO_TOL: f64 = 1.1e-5;
/// The largest denominator q of a ratio ωᵢ/ω₀ = p/q that [`Scene::common_period`] recognises.
pub const MAX_PERIOD_DENOMINATOR: u64 = 64;
/// The longest common period [`Scene::common_period`] accepts, in periods of the slowest stroke.
pub const MAX_COMMON_PERIODS: f64 = 64.0;

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

fn lcm(a: u64, b: u64) -> u64 {
    a / gcd(a, b) * b
}

/// Default tolerance of the averaged model's adaptive integrator.
pub const DEFAULT_AVERAGED_RTOL: f64 = 1e-8;

/// Default tolerance of `suspension(tol)`, the averaged model's default for a suspension: the
/// loosest decade whose displacements stay well within 1e-3 (RMS, relative) of fine RK4 on a
/// suspension with steric contacts (the book, "Suspensions, boxes and fields").
pub const DEFAULT_SUSPENSION_TOL: f64 = 1e-3;

/// From this many swimmers an averaged scene counts as a suspension (whatever its settings).
pub const SUSPENSION_SWIMMERS: usize = 64;

impl Scene {
    /// The integrator in use (the model's default for this scene unless one was set).
    pub fn integrator(&self) -> IntegratorSpec {
        self.integrator.unwrap_or_else(|| self.default_integrator())
    }

    /// The model's default integrator for the swimmers of this scene.
    ///
    /// Spring and rigid-stroke models: `auto(tol)` at [`DEFAULT_AUTO_TOL`] (stroboscopic averaging
    /// over a common period, its inner method directly where averaging cannot help). On the gpu
    /// backend, which steps the explicit methods only, the spring model keeps RK4 at dt = 0.8/rate
    /// of the stiffest spring (see [`DEFAULT_MICRO_STEP_TIMES_RATE`]), at most 1/200 of the
    /// shortest period. Averaged: for a suspension ([`Scene::is_suspension`]) `suspension(tol)` at
    /// [`DEFAULT_SUSPENSION_TOL`], else dopri5, whose steps grow to a good fraction of a period
    /// (the averaged model is not stiff).
    pub fn default_integrator(&self) -> IntegratorSpec {
        if self.thermal.is_on() {
            return self.default_noisy_integrator();
        }
        match self.model {
            Model::Micro if self.backend == Backend::Gpu => IntegratorSpec::Rk4 {
                dt: self.default_micro_step(),
            },
            Model::Micro | Model::Rigid => IntegratorSpec::Auto {
                tol: DEFAULT_AUTO_TOL,
            },
            Model::Averaged if self.is_suspension() => IntegratorSpec::Suspension {
                tol: DEFAULT_SUSPENSION_TOL,
            },
            Model::Averaged => IntegratorSpec::Dopri5 {
                rtol: DEFAULT_AVERAGED_RTOL,
            },
        }
    }

    /// Whether the scene is a suspension of the averaged model: a periodic box, a cutoff, steric
    /// repulsion, or at least [`SUSPENSION_SWIMMERS`] swimmers. Its default is then
    /// `suspension(tol)`, whose error is each swimmer's own, where a pair's is the drift's.
    pub fn is_suspension(&self) -> bool {
        self.model == Model::Averaged
            && (self.periodic().is_some()
                || self.cutoff.is_some()
                || self.contacts.steric.is_some()
                || self.count() >= SUSPENSION_SWIMMERS)
    }

    /// The default with thermal noise: Euler-Maruyama. The spring model steps at
    /// [`DEFAULT_NOISY_STEP_TIMES_RATE`]/rate (a spring's stationary variance comes out high by the
    /// factor 1/(1 − rate·dt/2), 5%), at most 1/200 of the shortest period; the averaged model,
    /// which has no stroke inside a period, at 1/20 of the period. The rigid-stroke model keeps its
    /// default and refuses noise when it runs.
    fn default_noisy_integrator(&self) -> IntegratorSpec {
        let t_min = self.shortest_period();
        let dt = match self.model {
            Model::Micro => (DEFAULT_NOISY_STEP_TIMES_RATE / self.stiff_rate())
                .min(DEFAULT_MICRO_MAX_STEP_PER_PERIOD * t_min),
            Model::Averaged => t_min / 20.0,
            Model::Rigid => {
                return IntegratorSpec::Dopri5 {
                    rtol: DEFAULT_RIGID_RTOL,
                }
            }
        };
        IntegratorSpec::Euler {
            dt: if dt.is_finite() { dt } else { 1e-6 },
        }
    }

    /// The microscopic model's default RK4 step for these swimmers (s): 0.8/rate of the stiffest
    /// spring, at most 1/200 of the shortest period.
    pub fn default_micro_step(&self) -> f64 {
        let t_min = self.shortest_period();
        let dt = (DEFAULT_MICRO_STEP_TIMES_RATE / self.stiff_rate())
            .min(DEFAULT_MICRO_MAX_STEP_PER_PERIOD * t_min);
        if dt.is_finite() {
            dt
        } else {
            1e-6
        }
    }

    /// Whether the integrator is the model's default.
    pub fn integrator_is_default(&self) -> bool {
        self.integrator.is_none()
    }

    /// Set the integrator; `None` returns to the model's default.
    pub fn set_integrator(&mut self, spec: Option<IntegratorSpec>) {
        self.integrator = spec;
    }

    /// Swimmer 0, whose stroke the periods are measured against; an error without swimmers.
    fn first_swimmer(&self) -> Result<&Dumbbell> {
        self.swimmers.first().ok_or_else(|| {
            unsupported(
                "the scene has no swimmers, so no period",
                &[Setting::AddSwimmer],
            )
        })
    }

    /// The common stroke period 2π/ω; an error if the swimmers' ω differ or there are none.
    pub fn period(&self) -> Result<f64> {
        let first = self.first_swimmer()?;
        if let Some((i, d)) = self
            .swimmers
            .iter()
            .enumerate()
            .find(|(_, d)| d.omega != first.omega)
        {
            return Err(invalid!(
                "the swimmers have different omega (swimmer 0: {} 1/s, swimmer {i}: {} 1/s), so there is no common period; use run(seconds) instead",
                first.omega,
                d.omega
            ));
        }
        Ok(first.period())
    }

    /// The common period of all strokes (s): 2π/ω when the ω agree; when they differ but are
    /// commensurate (every ratio ωᵢ/ω₀ a fraction p/q with q ≤ [`MAX_PERIOD_DENOMINATOR`], to 1e-12),
    /// the least common multiple of the periods, if at most [`MAX_COMMON_PERIODS`] of the longest.
    pub fn common_period(&self) -> Result<f64> {
        let first = self.first_swimmer()?;
        let w0 = first.omega;
        let mut q_lcm: u64 = 1;
        let mut fractions = Vec::with_capacity(self.swimmers.len());
        for (i, d) in self.swimmers.iter().enumerate() {
            let r = d.omega / w0;
            let Some((p, q)) = (1..=MAX_PERIOD_DENOMINATOR).find_map(|q| {
                let p = (r * q as f64).round();
                ((p * w0 / q as f64 - d.omega).abs() <= 1e-12 * d.omega && p >= 1.0)
                    .then_some((p as u64, q))
            }) else {
                return Err(invalid!(
                    "swimmer {i} strokes at omega = {} 1/s against swimmer 0's {w0} 1/s, a ratio that is no fraction p/q with q <= {MAX_PERIOD_DENOMINATOR}, so the strokes have no common period; give the swimmers commensurate omega, or use an integrator other than stroboscopic",
                    d.omega
                ));
            };
            q_lcm = lcm(q_lcm, q);
            fractions.push((p, q));
        }
        // ωᵢ = ω₀ nᵢ / Q with integer nᵢ; the common frequency is ω₀ gcd(nᵢ) / Q.
        let g = fractions.iter().map(|(p, q)| p * (q_lcm / q)).fold(0, gcd);
        let t = 2.0 * std::f64::consts::PI * q_lcm as f64 / (w0 * g as f64);
        let longest = self
            .swimmers
            .iter()
            .map(Dumbbell::period)
            .fold(0.0, f64::max);
        if t > MAX_COMMON_PERIODS * longest * (1.0 + 1e-12) {
            return Err(invalid!(
                "the strokes' common period is {t:e} s, {:.0} times the longest stroke: stroboscopic samples that long gain nothing; give the swimmers simpler omega ratios, or use an integrator other than stroboscopic",
                t / longest
            ));
        }
        Ok(t)
    }

    /// The shortest stroke period of the swimmers (s); infinite without swimmers.
    pub fn shortest_period(&self) -> f64 {
        crate::engine::swimmer::shortest_period(&self.swimmers)
    }

    /// The largest spring relaxation rate k0 (1/γ1 + 1/γ2) in the scene (1/s): the stiffness.
    pub fn stiff_rate(&self) -> f64 {
        self.swimmers
            .iter()
            .map(|d| d.relaxation_rate(self.mu))
            .fold(0.0, f64::max)
    }
}
