//! What the models say about a scene's current state: tensions and rates, and
//! the right-hand side ([`OdeSystem`]) of the chosen model that every run and query uses.

use super::*;
use crate::engine::averaged::DEFAULT_SKIN_OF_CUTOFF;
use crate::engine::integrators::{Stepper, Stroboscopic, Suspension, MIN_MACRO};

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
            Model::Rigid => Ok(self.rigid_system()?.tensions(self.time, &self.state)[i]),
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

    /// Swimmer `i`'s diffusion as a rigid dumbbell of length ℓ at the scene's temperature, with
    /// the scene's mobility (all zero at 0 K): the averaged model's noise, and the long-time
    /// diffusion of a spring dumbbell's centre whose length fluctuates little about ℓ.
    pub fn rigid_diffusion(&self, i: usize) -> Result<crate::engine::thermal::RigidDiffusion> {
        self.check_index(i)?;
        let d = &self.swimmers[i];
        crate::engine::thermal::RigidDiffusion::new(
            d,
            d.ell,
            self.mu,
            self.mobility,
            self.thermal.kt(),
        )
    }

    /// The state vector (see [`super::model`]) and the base positions: for tests and savers.
    pub fn raw_state(&self) -> (&[f64], &[Vector3<f64>]) {
        (&self.state, &self.base)
    }

    /// The chosen model's right-hand side for the current settings (benchmarks and tests time and
    /// probe it). A wall beyond the reach of the swimmers now in the scene (set before them, or
    /// before a smaller one came) is refused here, where every run and rate starts.
    pub fn system(&self) -> Result<Box<dyn OdeSystem>> {
        self.check_boundary_reach()?;
        Ok(match self.model {
            Model::Micro => {
                let mut sys = MicroSystem::new(
                    &self.swimmers,
                    &self.base,
                    self.mu,
                    self.mobility,
                    self.contacts,
                );
                sys.set_thermal(self.thermal);
                sys.set_boundary(self.boundary, self.mobility_operator()?);
                sys.set_external(self.sphere_forces());
                sys.set_reach(self.reach());
                Box::new(sys)
            }
            Model::Rigid => {
                if self.contacts.steric.is_some() {
                    return Err(unsupported(
                        "steric repulsion is not available in the rigid-stroke model (its constraint solve takes dumbbell tensions only)",
                        &[Setting::Model("micro"), Setting::Model("averaged"), Setting::NoSteric],
                    ));
                }
                Box::new(self.rigid_system()?)
            }
            Model::Averaged => {
                self.check_averaged()?;
                self.check_averaged_open()?;
                let mut sys =
                    AveragedSystem::new(&self.swimmers, &self.base, self.coefficients, &self.state);
                sys.set_cutoff(self.averaged_cutoff()?);
                sys.set_periodic(self.periodic().copied());
                sys.set_contacts(self.contacts, self.mu);
                sys.set_thermal(self.thermal, &self.swimmers, self.mu, self.mobility)?;
                Box::new(sys)
            }
        })
    }

    /// The rigid-stroke model's system for the current settings (steric repulsion aside, which
    /// [`Scene::system`] refuses): the one every run and the tensions use.
    fn rigid_system(&self) -> Result<RigidSystem> {
        let mut sys = RigidSystem::new(
            &self.swimmers,
            &self.base,
            self.mu,
            self.mobility,
            self.contacts.allow_overlap,
        );
        // The constraint solve takes blocks, which are Beenakker's sums.
        sys.set_boundary(
            self.boundary,
            self.mobility_operator_by(EwaldMethod::Beenakker)?,
        );
        sys.set_external(self.sphere_forces());
        sys.set_reach(self.reach());
        Ok(sys)
    }

    /// What makes the next run far costlier than its length suggests, each as a notice of its
    /// kind with the fix: spectral Ewald sums chosen for a box of few spheres (its FFT grid is
    /// transformed six times a product whatever the number of spheres, while Beenakker's sums
    /// shrink as N²; below a quarter of the crossover they cost (700/N)² ≳ 16 times less); an
    /// averaged suspension's cutoff set to half the box, which leaves its neighbour lists no
    /// skin (every right-hand side rebuilds them).
    pub fn cost_notices(&self) -> Vec<(&'static str, EngineError)> {
        let mut out = Vec::new();
        if let (Model::Averaged, Some(b), Some(c)) = (self.model, self.periodic(), self.cutoff) {
            let half = 0.5 * b.shortest();
            if self.count() >= crate::engine::averaged::LIST_SWIMMERS && c >= half {
                out.push((
                    "cutoff without skin",
                    unsupported(
                        format!(
                            "this run will cost far more than its length suggests: the cutoff {c:e} m reaches half the box's shortest side, which leaves the neighbour lists of its {} swimmers no skin (pairs within the cutoff plus {:.0}% of it must meet one image), so every right-hand side rebuilds them; the box's default cutoff, {:.4e} m, keeps the skin, and the pairs it leaves out change the rates by far less than a suspension's tolerance",
                            self.count(),
                            100.0 * DEFAULT_SKIN_OF_CUTOFF,
                            half / (1.0 + DEFAULT_SKIN_OF_CUTOFF)
                        ),
                        &[Setting::NoCutoff],
                    ),
                ));
            }
        }
        let spheres = 2 * self.count();
        if self.model == Model::Micro
            && self.ewald_method == EwaldMethod::Spectral
            && spheres < SPECTRAL_FROM_SPHERES / 4
        {
            if let Ok(Some(e)) = self.ewald() {
                if let Some(g) = e.spectral() {
                    let [a, b, c] = g.grid();
                    out.push((
                        "spectral Ewald",
                        unsupported(
                            format!(
                                "this run will cost far more than its length suggests: spectral Ewald sums transform a {a}x{b}x{c} grid six times for every mobility product, whatever the number of spheres, and with {spheres} spheres Beenakker's sums (O(N^2), faster below {SPECTRAL_FROM_SPHERES} spheres) cost far less"
                            ),
                            &[Setting::EwaldMethod("auto"), Setting::EwaldMethod("beenakker")],
                        ),
                    ));
                }
            }
        }
        out
    }

    /// The averaged model's cutoff: the one set; in a box at most half its shortest side (a pair
    /// meets one image), and when none is set the longest that leaves the neighbour lists their
    /// skin within that half, L/2 / (1 + [`DEFAULT_SKIN_OF_CUTOFF`]) = 0.476 L. At L/2 itself
    /// the lists would have no skin and every right-hand side would rebuild them, tens of times
    /// the cost, for pair terms that change the rates by far less than a suspension's tolerance
    /// (the measurements are in the book's "Suspensions, boxes and fields").
    pub fn averaged_cutoff(&self) -> Result<Option<f64>> {
        let Some(b) = self.periodic() else {
            return Ok(self.cutoff);
        };
        let half = 0.5 * b.shortest();
        match self.cutoff {
            None => Ok(Some(half / (1.0 + DEFAULT_SKIN_OF_CUTOFF))),
            Some(c) if c <= half => Ok(Some(c)),
            Some(c) => Err(invalid!(
                "the averaged model's cutoff {c:e} m is longer than half the box's shortest side ({half:e} m): a pair would meet two images; set the cutoff to {half:e} m or less, or use a larger box"
            )),
        }
    }

    /// The averaged equations are those of swimmers in open space or a box, free of external
    /// forces: a solid boundary (a wall) or external forces are refused with the reason.
    pub(crate) fn check_averaged_open(&self) -> Result<()> {
        if self.geometry().solid() {
            return Err(unsupported(
                "the averaged model has no wall equations (its pair terms are open space's); long runs near a wall come from auto or stroboscopic averaging on the microscopic model",
                &[Setting::Model("micro"), Setting::Model("rigid"), Setting::NoWall],
            ));
        }
        if !self.external.is_none() {
            return Err(unsupported(
                "the averaged model has no external forces (its swimmers are force-free); the microscopic and rigid-stroke models take them",
                &[Setting::Model("micro"), Setting::Model("rigid")],
            ));
        }
        Ok(())
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
/// periods from t = 0 against dopri5(1e-11), rounded up from its measurement (the book's design
/// notes).
pub const RK4_DEFAULT_DRIFT_ERROR: f64 = 1.1e-6;

/// The largest inner RK4 step of stroboscopic averaging, in units of 1/rate (rate = the stiffest
/// spring's k0(1/γ1 + 1/γ2)): RK4's stability bound on the negative real axis is 2.785 (PHYSICS.md;
/// the hydrodynamic interaction slows the spring mode, so the true limit lies higher, as
/// `bench stability` shows: the book's design notes), so 2.5 keeps a tenth in hand. At tol 1e-3 the accuracy-bound step, 2.47/rate, is below it.
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

impl Scene {
    /// What a stepper for `spec` was built from besides the spec: a cached one is reused only
    /// while this stays (and [`Scene::check_integrator`] passes). Direct methods take nothing
    /// from the scene; stroboscopic averaging and `auto` take the swimmers' count, the model, μ,
    /// the common period, the RK4 step and whether the scene is a suspension (`auto`'s choice).
    pub(crate) fn stepper_key(&self, spec: IntegratorSpec) -> Vec<u64> {
        match spec {
            IntegratorSpec::Stroboscopic { .. } | IntegratorSpec::Auto { .. } => vec![
                self.count() as u64,
                self.model as u64,
                self.mu.to_bits(),
                self.common_period().map_or(0, f64::to_bits),
                self.default_micro_step().to_bits(),
                u64::from(self.is_suspension()),
            ],
            _ => Vec::new(),
        }
    }

    /// A fresh stepper for `spec` on this scene. Stroboscopic averaging needs the common period,
    /// the slowest spring relaxation (how many periods settle the springs after a start) and a
    /// length scale.
    pub(crate) fn stepper(&self, spec: IntegratorSpec) -> Result<Box<dyn Stepper>> {
        self.check_integrator(spec)?;
        if let Some(st) = spec.build() {
            return Ok(st);
        }
        if let IntegratorSpec::Auto { tol } = spec {
            return self.stepper(self.auto_choice(tol)?.0);
        }
        if let IntegratorSpec::Suspension { tol } = spec {
            // The first step: one stroke period (the controller takes it from there).
            return Ok(Box::new(Suspension::new(tol, self.shortest_period())));
        }
        let IntegratorSpec::Stroboscopic { tol, inner } = spec else {
            return Err(invalid!("{spec} has no stepper"));
        };
        let period = self.common_period()?;
        let inner = inner
            .map(IntegratorSpec::from)
            .unwrap_or_else(|| self.stroboscopic_inner(tol));
        let inner_stepper = inner
            .build()
            .ok_or_else(|| invalid!("the inner integrator {inner} must be a direct method"))?;
        // Periods integrated directly after a start, for the springs to settle from L(0).
        let transient = match self.model {
            // Twice the e-foldings at the isolated rate: the hydrodynamic interaction slows a
            // spring's mode, by less than that factor (bench stability; the book's design notes).
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
            transient,
            length,
        )))
    }

    /// What refuses integrator `spec` on the scene as it is now: thermal noise's refusals,
    /// `suspension` outside the averaged model, stroboscopic averaging inside it. Every run asks,
    /// a cached stepper's too: the model, the temperature or the swimmers may have changed since
    /// it was built.
    pub(crate) fn check_integrator(&self, spec: IntegratorSpec) -> Result<()> {
        self.check_noise(spec)?;
        match spec {
            IntegratorSpec::Suspension { .. } if self.model != Model::Averaged => Err(unsupported(
                format!("{spec} is the averaged model's method for suspensions: the {} model's springs or strokes have no steric-contact structure for it to use", self.model.name()),
                &[Setting::Model("averaged"), Setting::DefaultIntegrator],
            )),
            IntegratorSpec::Stroboscopic { .. } if self.model == Model::Averaged => Err(unsupported(
                "stroboscopic averaging is for the spring and rigid-stroke models: the averaged model is averaged already",
                &[Setting::Model("micro"), Setting::Model("rigid"), Setting::DefaultIntegrator],
            )),
            _ => Ok(()),
        }
    }

    /// What thermal noise refuses: the rigid-stroke model, deterministic integrators, and Platen's
    /// scheme where it has no diffusion matrix or would cost too much.
    fn check_noise(&self, spec: IntegratorSpec) -> Result<()> {
        let th = self.thermal;
        if !th.is_on() {
            return Ok(());
        }
        let t = th.temperature;
        if self.model == Model::Rigid {
            return Err(unsupported(
                format!("thermal noise (temperature {t} K) is not available in the rigid-stroke model: Brownian motion under a rigid constraint needs the metric (Fixman) drift, which changes the equilibrium this model would sample"),
                &[Setting::Model("micro"), Setting::Model("averaged"), Setting::NoNoise],
            ));
        }
        if !spec.takes_noise() {
            return Err(unsupported(
                format!("{spec} is a deterministic method and cannot carry thermal noise (temperature {t} K): a Brownian path is nowhere smooth, which adaptive error control and stroboscopic averaging assume, so the noise needs a stochastic scheme"),
                &[Setting::NoiseIntegrator, Setting::DefaultIntegrator, Setting::NoNoise],
            ));
        }
        if let IntegratorSpec::Platen { .. } = spec {
            if self.model == Model::Averaged {
                return Err(unsupported(
                    format!("{spec} needs the diffusion matrix at shifted states, and the averaged model turns its orientations on the unit sphere instead"),
                    &[Setting::NoiseIntegrator, Setting::DefaultIntegrator],
                ));
            }
            if self.count() > PLATEN_MAX_SWIMMERS {
                return Err(invalid!(
                    "{spec} factors the mobility at 4m + 1 states a step (m = 6 per swimmer), a cost growing as the swimmer count to the 4th power; it takes at most {PLATEN_MAX_SWIMMERS} swimmers, this scene has {}: use euler(dt) with a smaller step",
                    self.count()
                ));
            }
        }
        let spheres = 2 * self.count();
        if self.model == Model::Micro
            && th.root.dense_for(spheres)
            && spheres > CHOLESKY_LIMIT_SPHERES
        {
            return Err(invalid!(
                "the dense Cholesky factor of {spheres} spheres needs a {0}x{0} matrix ({1:.1} GB) and O(N^3) work every step; use the Lanczos square root (noise root \"lanczos\" or \"auto\")",
                3 * spheres,
                (3 * spheres) as f64 * (3 * spheres) as f64 * 8e-9
            ));
        }
        Ok(())
    }

    /// What `auto(tol)` runs on this scene, and why. The averaged model: dopri5 a hundred times
    /// tighter than `tol`, never looser than its default (it is not stiff). The spring and rigid-stroke models with a common
    /// period: stroboscopic averaging, sampled by [`Scene::stroboscopic_inner`] (runs of fewer
    /// than [`MIN_MACRO`] periods, the start transient and rows between period multiples take
    /// that inner method directly); without one, the inner method directly. Springs so stiff
    /// that RK4 would take more than [`STIFF_STEPS_PER_PERIOD`] steps a period take rosw.
    pub fn auto_choice(&self, tol: f64) -> Result<(IntegratorSpec, String)> {
        if self.is_suspension() {
            return Ok((
                IntegratorSpec::Suspension { tol },
                "a suspension of the averaged model: each swimmer's error held to tol of its own displacement, steric contacts implicit, a few fast swimmers stepped apart".into(),
            ));
        }
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
                let default = if self.integrator_is_default() {
                    format!(" (the {} model's default)", self.model.name())
                } else {
                    String::new()
                };
                format!("{spec}{default} runs {chosen}: {why}")
            }
            IntegratorSpec::Suspension { .. } if self.integrator_is_default() => format!(
                "{spec}: the {} model's default for a suspension (a box, a cutoff, steric repulsion or at least {} swimmers): each swimmer's error held to tol of its own displacement over a step, steric contacts implicit, a few fast swimmers (a contact, a close pair) stepped apart with steps of their own",
                self.model.name(),
                super::SUSPENSION_SWIMMERS
            ),
            _ if self.integrator_is_default() => {
                format!("{spec}: the {} model's default", self.model.name())
            }
            _ => format!("{spec}: as set"),
        })
    }

    /// Stroboscopic averaging's inner integrator when none is named. The spring model: RK4 (a
    /// fixed step keeps the sampled map smooth in the state) at the step whose drift error is a
    /// tenth of `tol`: RK4's error falls as dt⁴ from [`RK4_DEFAULT_DRIFT_ERROR`] at the default
    /// step, and the step stays below [`RK4_STABLE_STEP_RATE`]/rate and 1/100 of the period. The
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
                    let t_min = self.shortest_period();
                    (dt0 * f)
                        .min(RK4_STABLE_STEP_RATE / self.stiff_rate())
                        .min(t_min / 100.0)
                        .max(dt0)
                };
                IntegratorSpec::Rk4 { dt }
            }
        }
    }

    /// RK4 steps per shortest period at the stability-bounded step [`RK4_STABLE_STEP_RATE`]/rate.
    fn stiff_steps_per_period(&self) -> f64 {
        let t_min = self.shortest_period();
        t_min * self.stiff_rate() / RK4_STABLE_STEP_RATE
    }
}
