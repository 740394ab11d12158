//! The strokes' periods (one, common, shortest), the stiffest spring's rate, and the integrator a
//! scene takes: the one set, or the model's default for these swimmers (each model's, by the
//! integrator policy's constants in `integrators::policy`).

use super::*;
pub use crate::engine::integrators::DEFAULT_AUTO_TOL;

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
        let model = self.swimmer_model();
        if self.thermal.is_on() {
            return model.default_noisy_integrator(self);
        }
        model.default_integrator(self)
    }

    /// Whether the scene is a suspension of the averaged model: a periodic box, a cutoff, steric
    /// repulsion, or at least [`SUSPENSION_SWIMMERS`] swimmers. Its default is then
    /// `suspension(tol)`, whose error is each swimmer's own, where a pair's is the drift's.
    pub fn is_suspension(&self) -> bool {
        self.swimmer_model().stroke_averaged() && self.crowded()
    }

    /// Whether the scene is crowded: a periodic box, a cutoff, steric repulsion, or at least
    /// [`SUSPENSION_SWIMMERS`] swimmers.
    pub(super) fn crowded(&self) -> bool {
        self.periodic().is_some()
            || self.cutoff.is_some()
            || self.contacts.steric.is_some()
            || self.count() >= SUSPENSION_SWIMMERS
    }

    /// The microscopic model's default RK4 step for these swimmers (s): 0.8/rate of the stiffest
    /// spring, at most 1/200 of the shortest period.
    pub fn default_micro_step(&self) -> f64 {
        self.facts().rk4_step()
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
