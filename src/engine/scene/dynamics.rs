//! What the models say about a scene's current state: tensions and rates, and the right-hand
//! side ([`OdeSystem`]) of the chosen model that every run and query uses, all through the model
//! seam ([`SwimmerModel`], which reads the scene as a [`SceneView`]); the stepper for an
//! integrator, checked against the scene as it is at every run, by the integrator policy
//! (`integrators::policy`); and the cost notices a run gives when it starts.

use super::*;
use crate::engine::error::short;
use crate::engine::integrators::{
    auto_choice, check_noise, Facts, Stepper, Stroboscopic, Suspension,
};

impl Scene {
    /// Spring tension k0 (d − L) of swimmer `i` (N), or the constraint tension in the rigid-stroke
    /// model; positive when the spring pulls the spheres together.
    pub fn tension(&self, i: usize) -> Result<f64> {
        self.check_index(i)?;
        self.swimmer_model().tension(self, i)
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
        let spin = self.swimmer_model().spin(&vec3(&self.state, k + 3), w);
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

    /// The state vector (see [`crate::engine::model`]) and the base positions: for tests and savers.
    pub fn raw_state(&self) -> (&[f64], &[Vector3<f64>]) {
        (&self.state, &self.base)
    }

    /// The chosen model's right-hand side for the current settings (benchmarks and tests time and
    /// probe it). A wall beyond the reach of the swimmers now in the scene (set before them, or
    /// before a smaller one came) is refused here, where every run and rate starts.
    pub fn system(&self) -> Result<Box<dyn OdeSystem>> {
        self.check_boundary_reach()?;
        self.check_steric_range()?;
        self.swimmer_model().system(self)
    }

    /// In a box the steric range is at most half its shortest side, as the averaged model's
    /// cutoff is: beyond, every pair is within the range through some minimum image, all repel
    /// at once and the steps shrink to the step-size floor.
    fn check_steric_range(&self) -> Result<()> {
        let (Some(b), Some(st)) = (self.periodic(), self.contacts.steric) else {
            return Ok(());
        };
        let half = 0.5 * b.shortest();
        if st.range > half {
            return Err(invalid!(
                "the steric range {} m is longer than half the box's shortest side ({} m): every pair would repel through a minimum image; set a range up to {} m (a small fraction of a sphere radius is usual, such as 1e-7 m), or use a larger box",
                short(st.range),
                short(half),
                short(half)
            ));
        }
        Ok(())
    }

    /// What makes the next run far costlier than its length suggests, each as a notice of its
    /// kind with the fix: spectral Ewald sums chosen for a box of few spheres (its FFT grid is
    /// transformed six times a product whatever the number of spheres, while Beenakker's sums
    /// shrink as N^1.5; below [`SPECTRAL_COSTLY_BELOW`] spheres they cost 4× less or more); an
    /// averaged suspension's cutoff set to half the box, which leaves its neighbour lists no
    /// skin (every right-hand side rebuilds them).
    pub fn cost_notices(&self) -> Vec<(&'static str, EngineError)> {
        let model = self.swimmer_model();
        let mut out = model.cost_notices(self);
        let spheres = self.sphere_count();
        if model.ewald_method(self.ewald_method) == Some(EwaldMethod::Spectral)
            && spheres < SPECTRAL_COSTLY_BELOW
        {
            if let Ok(Some(e)) = self.ewald() {
                if let Some(g) = e.spectral() {
                    let [a, b, c] = g.grid();
                    out.push((
                        "spectral Ewald",
                        unsupported(
                            format!(
                                "this run will cost far more than its length suggests: spectral Ewald sums transform a {a}x{b}x{c} grid six times for every mobility product, whatever the number of spheres, and with {spheres} spheres Beenakker's sums (O(N^1.5), faster below {SPECTRAL_FROM_SPHERES} spheres) cost far less"
                            ),
                            &[Setting::EwaldMethod("auto"), Setting::EwaldMethod("beenakker")],
                        ),
                    ));
                }
            }
        }
        out
    }

    /// The averaged model's cutoff: the one set, or in a box its default (see
    /// [`crate::engine::averaged::cutoff_in`]).
    pub fn averaged_cutoff(&self) -> Result<Option<f64>> {
        crate::engine::averaged::cutoff_in(self.periodic(), self.cutoff)
    }

    /// The averaged equations describe identical strokes: ω, λ and ℓ must agree.
    pub(crate) fn check_averaged(&self) -> Result<()> {
        crate::engine::averaged::check_identical(&self.swimmers)
    }

    /// What the integrator policy reads of this scene.
    pub(crate) fn facts(&self) -> Facts {
        Facts {
            swimmers: self.count(),
            shortest_period: self.shortest_period(),
            stiff_rate: self.stiff_rate(),
            slowest_rate: self
                .swimmers
                .iter()
                .map(|d| d.relaxation_rate(self.mu))
                .fold(f64::INFINITY, f64::min),
        }
    }
}

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
        let transient = self.swimmer_model().settling_periods(self, period);
        let length = self.swimmers.iter().map(|d| d.ell).fold(0.0, f64::max);
        Ok(Box::new(Stroboscopic::new(
            tol,
            period,
            inner_stepper,
            transient,
            length,
        )))
    }

    /// What refuses integrator `spec` on the scene as it is now: thermal noise's refusals, and
    /// the model's (`suspension` outside the averaged model, stroboscopic averaging inside it).
    /// Every run asks, a cached stepper's too: the model, the temperature or the swimmers may
    /// have changed since it was built.
    pub(crate) fn check_integrator(&self, spec: IntegratorSpec) -> Result<()> {
        self.check_noise(spec)?;
        self.swimmer_model().check_integrator(spec)
    }

    /// What thermal noise refuses: the model's own refusal (the rigid-stroke model), then the
    /// policy's (deterministic integrators, Platen's scheme where the model has no diffusion
    /// matrix or it would cost too much, a dense factor too large).
    fn check_noise(&self, spec: IntegratorSpec) -> Result<()> {
        let th = self.thermal;
        if !th.is_on() {
            return Ok(());
        }
        let model = self.swimmer_model();
        if let Some(e) = model.refuses_noise(th.temperature) {
            return Err(e);
        }
        check_noise(
            spec,
            th.temperature,
            self.count(),
            || model.refuses_platen(spec),
            model.dense_noise_spheres(th.root, self.count()),
        )
    }

    /// What `auto(tol)` runs on this scene, and why (the policy's [`auto_choice`]): a suspension
    /// of the averaged model takes the suspension stepper, the averaged model dopri5; the spring
    /// and rigid-stroke models with a common period stroboscopic averaging, sampled by
    /// [`Scene::stroboscopic_inner`], and without one that inner method directly.
    pub fn auto_choice(&self, tol: f64) -> Result<(IntegratorSpec, String)> {
        let model = self.swimmer_model();
        auto_choice(
            tol,
            self.is_suspension(),
            |tol| model.auto_direct(tol),
            |tol| model.stroboscopic_inner(self, tol),
            || self.common_period(),
        )
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

    /// Stroboscopic averaging's inner integrator when none is named: the spring model's RK4 at
    /// the step of the tolerance (rosw where the springs are stiff), the rigid-stroke model's
    /// dopri5 (see each model's [`SwimmerModel::stroboscopic_inner`]).
    pub fn stroboscopic_inner(&self, tol: f64) -> IntegratorSpec {
        self.swimmer_model().stroboscopic_inner(self, tol)
    }
}

/// The scene as the models read it.
impl SceneView for Scene {
    fn swimmers(&self) -> &[Dumbbell] {
        &self.swimmers
    }

    fn base(&self) -> &[Vector3<f64>] {
        &self.base
    }

    fn state(&self) -> &[f64] {
        &self.state
    }

    fn time(&self) -> f64 {
        self.time
    }

    fn mu(&self) -> f64 {
        self.mu
    }

    fn mobility(&self) -> Mobility {
        self.mobility
    }

    fn coefficients(&self) -> Coefficients {
        self.coefficients
    }

    fn contacts(&self) -> Contacts {
        self.contacts
    }

    fn thermal(&self) -> Thermal {
        self.thermal
    }

    fn boundary(&self) -> &Boundary {
        &self.boundary
    }

    fn cutoff(&self) -> Option<f64> {
        self.cutoff
    }

    fn external(&self) -> ExternalForces {
        self.external
    }

    fn reach(&self) -> Reach {
        Scene::reach(self)
    }

    fn mobility_operator_by(&self, method: EwaldMethod) -> Result<Box<dyn MobilityOperator>> {
        Scene::mobility_operator_by(self, method)
    }

    fn ewald_method(&self) -> EwaldMethod {
        self.ewald_method
    }

    fn facts(&self) -> Facts {
        Scene::facts(self)
    }

    fn integrator(&self) -> IntegratorSpec {
        Scene::integrator(self)
    }

    fn on_gpu(&self) -> bool {
        self.backend == Backend::Gpu
    }

    fn crowded(&self) -> bool {
        Scene::crowded(self)
    }
}
