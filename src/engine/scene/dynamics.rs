//! What the models say about a scene's current state: tensions and rates, and
//! the right-hand side ([`OdeSystem`]) of the chosen model that every run and query uses.

use super::*;
use crate::engine::integrators::{Stepper, Stroboscopic, MIN_MACRO};

impl Scene {
    /// Spring tension k0 (d − L) of swimmer `i` (N), or the constraint tension in the rigid-stroke
    /// model; positive when the spring pulls the spheres together.
    pub fn tension(&self, i: usize) -> Result<f64> {
        self.check_index(i)?;
        match self.model {
            Model::Micro => {
                let d = &self.swimmers[i];
                Ok(d.k0 * (self.length(i)? - d.rest_length(self.time)))
            }
            Model::Rigid => {
                let mut sys = RigidSystem::new(
                    &self.swimmers,
                    &self.base,
                    self.mu,
                    self.mobility,
                    self.contacts.allow_overlap,
                );
                Ok(sys.tensions(self.time, &self.state)[i])
            }
            Model::Averaged => Err(unsupported(
                format!("tension({i}) does not exist in the averaged model (it has no springs)"),
                &[Setting::Model("micro"), Setting::Model("rigid")],
            )),
        }
    }

    /// Right-hand side at the current state: (dR_H/dt in m/s, dN/dt in 1/s) of swimmer `i`.
    pub fn rates(&self, i: usize) -> Result<(Vector3<f64>, Vector3<f64>)> {
        self.check_index(i)?;
        let mut sys = self.system()?;
        let mut dy = vec![0.0; self.state.len()];
        sys.rhs(self.time, &self.state, &mut dy);
        let k = STATE_PER_SWIMMER * i;
        let v = vec3(&dy, k);
        let w = vec3(&dy, k + 3);
        let spin = match self.model {
            Model::Averaged | Model::Rigid => w,
            Model::Micro => {
                let b = vec3(&self.state, k + 3);
                let n = b.normalize();
                (w - n * n.dot(&w)) / b.norm()
            }
        };
        Ok((v, spin))
    }

    /// The state vector (see [`super::model`]) and the base positions: for tests and savers.
    pub fn raw_state(&self) -> (&[f64], &[Vector3<f64>]) {
        (&self.state, &self.base)
    }

    pub(crate) fn system(&self) -> Result<Box<dyn OdeSystem>> {
        Ok(match self.model {
            Model::Micro => Box::new(MicroSystem::new(
                &self.swimmers,
                &self.base,
                self.mu,
                self.mobility,
                self.contacts,
            )),
            Model::Rigid => {
                if self.contacts.steric.is_some() {
                    return Err(unsupported(
                        "steric repulsion is not available in the rigid-stroke model (its constraint solve takes dumbbell tensions only)",
                        &[Setting::Model("micro"), Setting::Model("averaged"), Setting::NoSteric],
                    ));
                }
                Box::new(RigidSystem::new(
                    &self.swimmers,
                    &self.base,
                    self.mu,
                    self.mobility,
                    self.contacts.allow_overlap,
                ))
            }
            Model::Averaged => {
                self.check_averaged()?;
                let mut sys =
                    AveragedSystem::new(&self.swimmers, &self.base, self.coefficients, &self.state);
                sys.set_cutoff(self.cutoff);
                sys.set_contacts(self.contacts, self.mu);
                Box::new(sys)
            }
        })
    }

    /// The averaged equations describe identical strokes: ω, λ and ℓ must agree.
    pub(crate) fn check_averaged(&self) -> Result<()> {
        if let Some(first) = self.swimmers.first() {
            for (i, d) in self.swimmers.iter().enumerate() {
                if d.omega != first.omega || d.lambda != first.lambda || d.ell != first.ell {
                    return Err(unsupported(
                        format!("the averaged model needs equal omega, lambda and ell for all swimmers (swimmer {i} differs from swimmer 0)"),
                        &[Setting::Model("micro")],
                    ));
                }
            }
        }
        Ok(())
    }
}

/// The relative drift error of the spring model's default RK4 step: the Fig-1 mirror pair over 100
/// periods from t = 0 against dopri5(1e-11), measured 1.06e-6 (halving the step: 5.7e-8, the
/// dt⁴ of RK4).
pub const RK4_DEFAULT_DRIFT_ERROR: f64 = 1.1e-6;

/// RK4 steps per period above which the springs count as stiff: `auto` and stroboscopic
/// averaging then sample with rosw, whose steps the springs do not limit.
pub const STIFF_STEPS_PER_PERIOD: f64 = 2e4;

/// e^-37 ≈ 1e-16: a spring mode relaxed this many e-foldings is gone to round-off.
const RELAXED_E_FOLDINGS: f64 = 37.0;

impl Scene {
    /// What a stepper for `spec` was built from besides the spec: a cached one is reused only
    /// while this stays. Direct methods take nothing from the scene; stroboscopic averaging and
    /// `auto` take the swimmers' count, the model, μ, the common period and the RK4 step.
    pub(crate) fn stepper_key(&self, spec: IntegratorSpec) -> Vec<u64> {
        match spec {
            IntegratorSpec::Stroboscopic { .. } | IntegratorSpec::Auto { .. } => vec![
                self.count() as u64,
                self.model as u64,
                self.mu.to_bits(),
                self.common_period().map_or(0, f64::to_bits),
                self.default_micro_step().to_bits(),
            ],
            _ => Vec::new(),
        }
    }

    /// A fresh stepper for `spec` on this scene. Stroboscopic averaging needs the common period,
    /// the slowest spring relaxation (how many periods relax the fast motion) and a length scale.
    pub(crate) fn stepper(&self, spec: IntegratorSpec) -> Result<Box<dyn Stepper>> {
        if let Some(st) = spec.build() {
            return Ok(st);
        }
        if let IntegratorSpec::Auto { tol } = spec {
            return self.stepper(self.auto_choice(tol)?.0);
        }
        let IntegratorSpec::Stroboscopic { tol, inner } = spec else {
            return Err(invalid!("{spec} has no stepper"));
        };
        if self.model == Model::Averaged {
            return Err(unsupported(
                "stroboscopic averaging is for the spring and rigid-stroke models: the averaged model is averaged already",
                &[Setting::Model("micro"), Setting::Model("rigid"), Setting::DefaultIntegrator],
            ));
        }
        let period = self.common_period()?;
        let inner = inner
            .map(IntegratorSpec::from)
            .unwrap_or_else(|| self.stroboscopic_inner(tol));
        let inner_stepper = inner
            .build()
            .ok_or_else(|| invalid!("the inner integrator {inner} must be a direct method"))?;
        let relax = match self.model {
            // The hydrodynamic interaction slows a spring's mode (bench stability: by < 2×).
            Model::Micro => {
                let slowest = self
                    .swimmers
                    .iter()
                    .map(|d| d.relaxation_rate(self.mu))
                    .fold(f64::INFINITY, f64::min);
                (2.0 * RELAXED_E_FOLDINGS / (slowest * period))
                    .ceil()
                    .clamp(1.0, 1e4) as u32
            }
            Model::Rigid | Model::Averaged => 0,
        };
        let length = self.swimmers.iter().map(|d| d.ell).fold(0.0, f64::max);
        Ok(Box::new(Stroboscopic::new(
            tol,
            period,
            inner_stepper,
            relax,
            relax,
            length,
        )))
    }

    /// What `auto(tol)` runs on this scene, and why. The averaged model: dopri5 a hundred times
    /// tighter than `tol`, never looser than its default (it is not stiff). The spring and rigid-stroke models with a common
    /// period: stroboscopic averaging, sampled by [`Scene::stroboscopic_inner`] (runs of fewer
    /// than [`MIN_MACRO`] periods, the start transient and rows between period multiples take
    /// that inner method directly); without one, the inner method directly. Springs so stiff
    /// that RK4 would take more than [`STIFF_STEPS_PER_PERIOD`] steps a period take rosw.
    pub fn auto_choice(&self, tol: f64) -> Result<(IntegratorSpec, String)> {
        if self.model == Model::Averaged {
            let rtol = (tol * 1e-2).clamp(1e-13, DEFAULT_AVERAGED_RTOL);
            return Ok((
                IntegratorSpec::Dopri5 { rtol },
                "the averaged model is not stiff: dopri5 at a hundredth of tol, never looser than its default".into(),
            ));
        }
        let inner = self.stroboscopic_inner(tol);
        Ok(match self.common_period() {
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

    /// What the integrator in use runs on this scene: `auto(tol)`'s choice and its reason, or
    /// the integrator itself.
    pub fn integrator_info(&self) -> Result<String> {
        let spec = self.integrator();
        Ok(match spec {
            IntegratorSpec::Auto { tol } => {
                let (chosen, why) = self.auto_choice(tol)?;
                format!("{spec} runs {chosen}: {why}")
            }
            _ if self.integrator_is_default() => {
                format!("{spec}: the {} model's default", self.model.name())
            }
            _ => format!("{spec}: as set"),
        })
    }

    /// Stroboscopic averaging's inner integrator when none is named. The spring model: RK4 (a
    /// fixed step keeps the sampled map smooth in the state) at the step whose drift error is a
    /// tenth of `tol`: RK4's error falls as dt⁴ from [`RK4_DEFAULT_DRIFT_ERROR`] at the default
    /// step, and the step stays below 2.0/rate (stability: 2.785) and 1/100 of the period. The
    /// rigid-stroke model: dopri5 a hundred times tighter than `tol` (its step choice makes the
    /// map only piecewise smooth, at the level of its tolerance).
    pub fn stroboscopic_inner(&self, tol: f64) -> IntegratorSpec {
        match self.model {
            Model::Rigid => IntegratorSpec::Dopri5 {
                rtol: (tol * 1e-2).clamp(1e-12, DEFAULT_RIGID_RTOL),
            },
            Model::Micro if self.stiff_steps_per_period() > STIFF_STEPS_PER_PERIOD => {
                IntegratorSpec::Rosw {
                    rtol: (tol * 1e-2).clamp(1e-12, 1e-6),
                }
            }
            Model::Micro | Model::Averaged => {
                let dt0 = self.default_micro_step();
                let f = (0.1 * tol / RK4_DEFAULT_DRIFT_ERROR).powf(0.25);
                let dt = if f < 1.0 {
                    dt0 * f
                } else {
                    let t_min = self
                        .swimmers
                        .iter()
                        .map(Dumbbell::period)
                        .fold(f64::INFINITY, f64::min);
                    (dt0 * f)
                        .min(2.0 / self.stiff_rate())
                        .min(t_min / 100.0)
                        .max(dt0)
                };
                IntegratorSpec::Rk4 { dt }
            }
        }
    }

    /// RK4 steps per shortest period at the stability-bounded step 2.0/rate.
    fn stiff_steps_per_period(&self) -> f64 {
        let t_min = self
            .swimmers
            .iter()
            .map(Dumbbell::period)
            .fold(f64::INFINITY, f64::min);
        t_min * self.stiff_rate() / 2.0
    }
}
