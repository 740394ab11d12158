//! A scene: the swimmers, the fluid, the model that moves them, and the integrator. This is the
//! engine's single entry point for the script layer.

use super::averaged::AveragedSystem;
use super::backend::{self, Backend};
use super::contacts::{Contacts, Steric};
use super::error::{
    invalid, require_finite, require_positive, unsupported, EngineError, Result, Setting,
};
use super::gpu::{GpuModel, GpuRun, RunOutcome, UniformSteps};
use super::integrators::{uniform_steps, IntegratorSpec, OdeSystem, Stats, Stepper};
use super::micro::MicroSystem;
use super::mobility::Mobility;
use super::model::{set_vec3, vec3, Coefficients, Model, STATE_PER_SWIMMER};
use super::recorder::Recorder;
use super::rigid::RigidSystem;
use super::swimmer::{unit_direction, Dumbbell};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

mod save;
pub use save::{MAX_TIME_IN_PERIODS, SAVE_FORMAT};

/// Water at room temperature (Pa s), the paper's μ.
pub const DEFAULT_MU: f64 = 1e-3;

/// The microscopic model's default RK4 step times the stiffest spring's relaxation rate. RK4 is
/// stable up to 2.785; at 0.8 the stroke-induced wobble of an isolated asymmetric dumbbell's R_H
/// closes to < 1e-12 ℓ per period (measured 7e-13; at 2.0 it is 6e-11, which would be 5e-5 of the
/// Fig-1 drift). The error falls as dt⁵ (README, "Accuracy").
pub const DEFAULT_MICRO_STEP_TIMES_RATE: f64 = 0.8;
/// The default step never exceeds this fraction of the shortest period, so that soft springs
/// (small k0) still resolve the stroke.
pub const DEFAULT_MICRO_MAX_STEP_PER_PERIOD: f64 = 1.0 / 200.0;
/// Default tolerance of the rigid-stroke model's adaptive integrator (README, "work-precision").
pub const DEFAULT_RIGID_RTOL: f64 = 1e-7;
/// Default tolerance of the averaged model's adaptive integrator.
pub const DEFAULT_AVERAGED_RTOL: f64 = 1e-8;

/// Most steps one run of a fixed-step integrator may take (~1e5 s, a day, at 1 µs a step): a
/// longer run is refused with the numbers before it starts; split it into several runs.
pub const MAX_FIXED_STEPS_PER_RUN: f64 = 1e11;

/// The swimmers, the fluid and the numerics of one simulation.
///
/// State per swimmer: see [`super::model`]. Positions are SI (m), times s. The engine works in SI
/// throughout: f64 carries relative precision independently of scale, and the adaptive error control
/// measures each component against a physical scale (stroke λ, drift λ³Λ/ℓ³), not against 1.
#[derive(Serialize, Deserialize)]
pub struct Scene {
    mu: f64,
    model: Model,
    mobility: Mobility,
    coefficients: Coefficients,
    /// Overlaps and steric repulsion between swimmers (saved; defaults for older files).
    #[serde(default)]
    contacts: Contacts,
    /// Far-field cutoff of the averaged model's pair sums (m); `None`: every pair.
    #[serde(default)]
    cutoff: Option<f64>,
    /// `None`: the model's default.
    integrator: Option<IntegratorSpec>,
    swimmers: Vec<Dumbbell>,
    /// Hydrodynamic centre of each swimmer that the displacement in `state` is measured from.
    base: Vec<Vector3<f64>>,
    state: Vec<f64>,
    time: f64,
    stats: Stats,
    /// Where the dynamics run (saved; "cpu" for files from before backends existed).
    #[serde(default)]
    backend: Backend,
    /// Device buffers of the last GPU run, reused while the scene's size and method stay.
    #[serde(skip)]
    gpu: Option<GpuRun>,
    /// The stepper of the last run, kept so an adaptive one remembers its step size.
    #[serde(skip)]
    stepper: Option<(IntegratorSpec, Box<dyn Stepper>)>,
    /// Recorders: operations on the scene, not its state (neither saved nor cloned).
    #[serde(skip)]
    recorders: Vec<Recorder>,
    /// Told the scene time as a run advances (neither saved nor cloned).
    #[serde(skip)]
    progress: Option<Progress>,
}

/// A run's progress report: called with the scene time after every CPU step and after every
/// device run segment, e.g. to draw a progress bar. It must be cheap.
pub type Progress = std::sync::Arc<dyn Fn(f64) + Send + Sync>;

impl Default for Scene {
    fn default() -> Self {
        Scene {
            mu: DEFAULT_MU,
            model: Model::default(),
            mobility: Mobility::default(),
            coefficients: Coefficients::default(),
            contacts: Contacts::default(),
            cutoff: None,
            integrator: None,
            swimmers: Vec::new(),
            base: Vec::new(),
            state: Vec::new(),
            time: 0.0,
            stats: Stats::default(),
            backend: Backend::default(),
            gpu: None,
            stepper: None,
            recorders: Vec::new(),
            progress: None,
        }
    }
}

/// A clone is a new simulation from the same state: it has no recorders and a fresh stepper.
impl Clone for Scene {
    fn clone(&self) -> Self {
        Scene {
            mu: self.mu,
            model: self.model,
            mobility: self.mobility,
            coefficients: self.coefficients,
            contacts: self.contacts,
            cutoff: self.cutoff,
            integrator: self.integrator,
            swimmers: self.swimmers.clone(),
            base: self.base.clone(),
            state: self.state.clone(),
            time: self.time,
            stats: self.stats,
            backend: self.backend,
            gpu: None,
            stepper: None,
            recorders: Vec::new(),
            progress: None,
        }
    }
}

impl std::fmt::Debug for Scene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Scene({} swimmers, model {}, mobility {}, integrator {}, t = {:e} s)",
            self.count(),
            self.model.name(),
            self.mobility.name(),
            self.integrator(),
            self.time
        )
    }
}

impl Scene {
    /// An empty scene with water's viscosity.
    pub fn new() -> Self {
        Self::default()
    }

    // ----- configuration -------------------------------------------------------------------

    /// Add a swimmer with hydrodynamic centre `center` (m) and orientation `dir` (any non-zero
    /// length), at length L(t) of the current time. Returns its 0-based index.
    pub fn add(&mut self, d: Dumbbell, center: Vector3<f64>, dir: Vector3<f64>) -> Result<usize> {
        d.validate()?;
        self.check_room(&d, center, dir, 0.0)?;
        let n = unit_direction(dir)?;
        let len = d.rest_length(self.time);
        self.swimmers.push(d);
        self.base.push(center);
        let v = match self.model {
            Model::Micro => n * len,
            Model::Averaged | Model::Rigid => n,
        };
        self.state
            .extend_from_slice(&[0.0, 0.0, 0.0, v.x, v.y, v.z]);
        Ok(self.swimmers.len() - 1)
    }

    /// Whether [`Scene::add`] would accept this swimmer with every sphere gap above `margin` (m):
    /// valid, and no sphere within `margin` of another.
    pub fn fits(&self, d: &Dumbbell, center: Vector3<f64>, dir: Vector3<f64>, margin: f64) -> bool {
        d.validate().is_ok() && self.check_room(d, center, dir, margin).is_ok()
    }

    /// The length at which swimmer `d`'s spheres sit now: L(t), or ℓ in the averaged model, whose
    /// swimmers are stroke-averaged (its contact guard and steric repulsion use ℓ too).
    fn contact_length(&self, d: &Dumbbell) -> f64 {
        match self.model {
            Model::Averaged => d.ell,
            Model::Micro | Model::Rigid => d.rest_length(self.time),
        }
    }

    fn check_room(
        &self,
        d: &Dumbbell,
        center: Vector3<f64>,
        dir: Vector3<f64>,
        margin: f64,
    ) -> Result<()> {
        for (k, c) in ["x", "y", "z"].iter().zip(center.iter()) {
            require_finite(&format!("center.{k}"), *c)?;
        }
        let n = unit_direction(dir)?;
        let (x1, x2) = d.sphere_positions(center, n, self.contact_length(d));
        for (s, other) in self.swimmers.iter().enumerate() {
            let (y1, y2) = self.spheres(s);
            for (xa, aa) in [(x1, d.a1), (x2, d.a2)] {
                for (yb, ab) in [(y1, other.a1), (y2, other.a2)] {
                    let gap = (xa - yb).norm() - aa - ab;
                    if gap <= margin {
                        return Err(invalid!(
                            "the new swimmer would overlap swimmer {s} (sphere gap {gap:.3e} m); place its centre further away"
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    /// Viscosity μ (Pa s).
    pub fn mu(&self) -> f64 {
        self.mu
    }

    /// Set the viscosity μ (Pa s).
    pub fn set_mu(&mut self, mu: f64) -> Result<()> {
        require_positive("mu", mu, "Pa s")?;
        self.mu = mu;
        Ok(())
    }

    /// The model in use.
    pub fn model(&self) -> Model {
        self.model
    }

    /// Switch the model, converting the state: micro → averaged keeps R_H and N of each dumbbell;
    /// averaged → micro rebuilds each dumbbell at its rest length L(t) of the current time.
    pub fn set_model(&mut self, model: Model) {
        if model == self.model {
            return;
        }
        for (s, d) in self.swimmers.iter().enumerate() {
            let i = STATE_PER_SWIMMER * s + 3;
            let v = vec3(&self.state, i);
            let new = match model {
                Model::Averaged | Model::Rigid => v.normalize(),
                Model::Micro => v * d.rest_length(self.time),
            };
            set_vec3(&mut self.state, i, &new);
        }
        self.model = model;
    }

    /// The mobility tensor of the microscopic model.
    pub fn mobility(&self) -> Mobility {
        self.mobility
    }

    /// Set the mobility tensor of the microscopic model.
    pub fn set_mobility(&mut self, m: Mobility) {
        self.mobility = m;
    }

    /// Coefficient set of the averaged model.
    pub fn coefficients(&self) -> Coefficients {
        self.coefficients
    }

    /// Set the coefficient set of the averaged model.
    pub fn set_coefficients(&mut self, c: Coefficients) {
        self.coefficients = c;
    }

    /// Contact handling: overlaps between swimmers and steric repulsion.
    pub fn contacts(&self) -> Contacts {
        self.contacts
    }

    /// Let spheres of different swimmers overlap (RPY's overlapping form) instead of stopping.
    pub fn set_allow_overlap(&mut self, allow: bool) {
        self.contacts.allow_overlap = allow;
    }

    /// Switch the steric repulsion between swimmers on (`Some`) or off.
    pub fn set_steric(&mut self, steric: Option<Steric>) {
        self.contacts.steric = steric;
    }

    /// The averaged model's far-field cutoff (m), if any.
    pub fn cutoff(&self) -> Option<f64> {
        self.cutoff
    }

    /// Leave pairs further apart than `cutoff` (m) out of the averaged model's sums; `None`: keep
    /// every pair (the default). The error this makes is bounded in [`AveragedSystem`].
    pub fn set_cutoff(&mut self, cutoff: Option<f64>) -> Result<()> {
        if let Some(c) = cutoff {
            if !(c.is_finite() && c > 0.0) {
                return Err(invalid!(
                    "the cutoff must be a positive distance in m (e.g. 2e-4, twenty ell), got {c}; or none for every pair"
                ));
            }
        }
        self.cutoff = cutoff;
        Ok(())
    }

    /// The integrator in use (the model's default for this scene unless one was set).
    pub fn integrator(&self) -> IntegratorSpec {
        self.integrator.unwrap_or_else(|| self.default_integrator())
    }

    /// The model's default integrator for the swimmers of this scene.
    ///
    /// Microscopic: RK4 at dt = 0.8/rate of the stiffest spring (see
    /// [`DEFAULT_MICRO_STEP_TIMES_RATE`]), but at most 1/200 of the shortest period. Averaged: dopri5,
    /// whose steps grow to a good fraction of a period (the averaged model is not stiff).
    pub fn default_integrator(&self) -> IntegratorSpec {
        match self.model {
            Model::Micro => IntegratorSpec::Rk4 {
                dt: self.default_micro_step(),
            },
            Model::Averaged => IntegratorSpec::Dopri5 {
                rtol: DEFAULT_AVERAGED_RTOL,
            },
            Model::Rigid => IntegratorSpec::Dopri5 {
                rtol: DEFAULT_RIGID_RTOL,
            },
        }
    }

    /// The microscopic model's default RK4 step for these swimmers (s): 0.8/rate of the stiffest
    /// spring, at most 1/200 of the shortest period.
    pub fn default_micro_step(&self) -> f64 {
        let t_min = self
            .swimmers
            .iter()
            .map(Dumbbell::period)
            .fold(f64::INFINITY, f64::min);
        let dt = (DEFAULT_MICRO_STEP_TIMES_RATE / self.stiff_rate())
            .min(DEFAULT_MICRO_MAX_STEP_PER_PERIOD * t_min);
        if dt.is_finite() {
            dt
        } else {
            1e-6
        }
    }

    /// Where the dynamics run.
    pub fn backend(&self) -> Backend {
        self.backend
    }

    /// Choose where the dynamics run (checked when the scene runs: see [`Scene::backend_info`]).
    pub fn set_backend(&mut self, b: Backend) {
        self.backend = b;
    }

    /// Which backend the next run uses and why, e.g. "cpu: 4 spheres, below the GPU crossover
    /// ...". For "gpu" on a scene that cannot run there, the error says why.
    pub fn backend_info(&self) -> Result<String> {
        self.plan()
            .map(|(gpu, why)| format!("{}: {why}", if gpu { "gpu" } else { "cpu" }))
    }

    /// The options the device kernels do not have: contact handling and the cutoff.
    fn gpu_options_supported(&self) -> std::result::Result<(), String> {
        let cpu_only = |what: &str| Err(format!("{what} runs on the CPU only"));
        match self.model {
            _ if self.contacts != Contacts::default() => {
                cpu_only("contact handling (overlaps allowed, steric repulsion)")
            }
            Model::Averaged if self.cutoff.is_some() => cpu_only("the far-field cutoff"),
            _ => Ok(()),
        }
    }

    /// Whether the next run takes the GPU, and why.
    fn plan(&self) -> Result<(bool, String)> {
        let fit = backend::gpu_model_supported(self.model)
            .and_then(|()| self.gpu_options_supported())
            .and_then(|()| backend::gpu_tableau(&self.integrator()).map(|_| ()));
        match self.backend {
            Backend::Cpu => Ok((false, "the cpu backend was chosen".into())),
            Backend::Gpu => {
                fit.map_err(|e| {
                    unsupported(
                        format!("the gpu backend: {e}"),
                        &[
                            Setting::Backend("cpu"),
                            Setting::Backend("auto"),
                            Setting::FixedStep,
                        ],
                    )
                })?;
                let dev = super::gpu::device().map_err(|e| {
                    unsupported(format!("the gpu backend: {e}"), &[Setting::Backend("cpu")])
                })?;
                Ok((
                    true,
                    format!("{} (the gpu backend was chosen)", dev.describe()),
                ))
            }
            Backend::Auto => {
                if let Err(e) = fit {
                    return Ok((false, format!("auto: {e}")));
                }
                let dev = match super::gpu::device() {
                    Ok(d) => d,
                    Err(e) => return Ok((false, format!("auto: {e}"))),
                };
                let (size, unit) = match self.model {
                    Model::Averaged => (self.count(), "swimmers"),
                    _ => (2 * self.count(), "spheres"),
                };
                let c = backend::crossover(self.model);
                Ok(match c.size {
                    Some(n) if size >= n => (
                        true,
                        format!("auto: {} with {size} {unit}, at or above the measured crossover of {n} ({})", dev.describe(), c.detail),
                    ),
                    Some(n) => (
                        false,
                        format!("auto: {size} {unit}, below the measured GPU crossover of {n} ({})", c.detail),
                    ),
                    None => (false, format!("auto: {}", c.detail)),
                })
            }
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

    /// Set the stroke phase φ of swimmer `i` (rad).
    pub fn set_phase(&mut self, i: usize, phase: f64) -> Result<()> {
        self.check_index(i)?;
        require_finite("phase", phase)?;
        self.swimmers[i].phase = phase;
        Ok(())
    }

    /// All stroke phases φ (rad), in swimmer order.
    pub fn phases(&self) -> Vec<f64> {
        self.swimmers.iter().map(|d| d.phase).collect()
    }

    /// Set all stroke phases at once; the length must match the number of swimmers.
    pub fn set_phases(&mut self, phases: &[f64]) -> Result<()> {
        if phases.len() != self.swimmers.len() {
            return Err(invalid!(
                "phases: got {} values for {} swimmers; give one phase per swimmer",
                phases.len(),
                self.swimmers.len()
            ));
        }
        for (i, p) in phases.iter().enumerate() {
            require_finite(&format!("phases[{i}]"), *p)?;
        }
        for (d, p) in self.swimmers.iter_mut().zip(phases) {
            d.phase = *p;
        }
        Ok(())
    }

    // ----- reading ---------------------------------------------------------------------------

    /// The smallest gap |x_α − x_β| − a_α − a_β over all pairs of spheres (m) and the two spheres
    /// (sphere α belongs to swimmer α/2, the a1 sphere first); `None` with fewer than two spheres.
    pub fn closest_spheres(&self) -> Option<(f64, usize, usize)> {
        let n = 2 * self.count();
        let mut soa = super::pairs::SoaSpheres::default();
        soa.resize(n);
        let mut radii = Vec::with_capacity(n);
        for i in 0..self.count() {
            let (a, b) = self.spheres(i);
            let d = &self.swimmers[i];
            for (k, (p, r)) in [(a, d.a1), (b, d.a2)].into_iter().enumerate() {
                let j = 2 * i + k;
                (soa.x[j], soa.y[j], soa.z[j]) = (p.x, p.y, p.z);
                radii.push(r);
            }
        }
        super::pairs::min_gap(&soa, &radii, n >= 256)
    }

    /// Number of swimmers.
    pub fn count(&self) -> usize {
        self.swimmers.len()
    }

    /// Current time (s).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Work counters accumulated over all runs.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// The parameters of swimmer `i`.
    pub fn swimmer(&self, i: usize) -> Result<&Dumbbell> {
        self.check_index(i)?;
        Ok(&self.swimmers[i])
    }

    /// All swimmers' parameters.
    pub fn swimmers(&self) -> &[Dumbbell] {
        &self.swimmers
    }

    /// The common stroke period 2π/ω; an error if the swimmers' ω differ or there are none.
    pub fn period(&self) -> Result<f64> {
        let first = self.swimmers.first().ok_or_else(|| {
            unsupported(
                "the scene has no swimmers, so no period",
                &[Setting::AddSwimmer],
            )
        })?;
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

    fn check_index(&self, i: usize) -> Result<()> {
        if i < self.swimmers.len() {
            Ok(())
        } else if self.swimmers.is_empty() {
            Err(invalid!(
                "swimmer index {i} is out of range: the scene has no swimmers"
            ))
        } else {
            Err(invalid!(
                "swimmer index {i} is out of range: the scene has {} swimmers (0 to {})",
                self.swimmers.len(),
                self.swimmers.len() - 1
            ))
        }
    }

    /// Hydrodynamic centre R_H of swimmer `i` (m).
    pub fn center(&self, i: usize) -> Result<Vector3<f64>> {
        self.check_index(i)?;
        Ok(self.base[i] + vec3(&self.state, STATE_PER_SWIMMER * i))
    }

    /// Displacement of R_H of swimmer `i` since its base position, without rounding against the
    /// absolute position (m).
    pub fn displacement(&self, i: usize) -> Result<Vector3<f64>> {
        self.check_index(i)?;
        Ok(vec3(&self.state, STATE_PER_SWIMMER * i))
    }

    /// Unit orientation N of swimmer `i` (from sphere a1 to sphere a2).
    pub fn dir(&self, i: usize) -> Result<Vector3<f64>> {
        self.check_index(i)?;
        Ok(vec3(&self.state, STATE_PER_SWIMMER * i + 3).normalize())
    }

    /// Current length |X₂ − X₁| of swimmer `i` (m); in the averaged model its rest length L(t).
    pub fn length(&self, i: usize) -> Result<f64> {
        self.check_index(i)?;
        Ok(match self.model {
            Model::Micro => vec3(&self.state, STATE_PER_SWIMMER * i + 3).norm(),
            Model::Averaged | Model::Rigid => self.swimmers[i].rest_length(self.time),
        })
    }

    /// Sphere centres (X₁, X₂) of swimmer `i` (m); in the averaged model at rest length L(t).
    pub fn spheres(&self, i: usize) -> (Vector3<f64>, Vector3<f64>) {
        let d = &self.swimmers[i];
        let rh = self.base[i] + vec3(&self.state, STATE_PER_SWIMMER * i);
        let v = vec3(&self.state, STATE_PER_SWIMMER * i + 3);
        match self.model {
            Model::Micro => (rh - d.w2() * v, rh + d.w1() * v),
            Model::Averaged | Model::Rigid => d.sphere_positions(rh, v, self.contact_length(d)),
        }
    }

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

    /// Every swimmer's swimming velocity (m/s): dR_H/dt of the averaged model; in the sphere models,
    /// whose centres oscillate within a stroke, R_H's displacement over the next period divided
    /// by T (measured on a copy; the scene is not changed).
    pub fn center_velocities(&self) -> Result<Vec<Vector3<f64>>> {
        self.center_velocities_within(&never)
    }

    /// [`Scene::center_velocities`], its probe period stopped when `interrupted()` says so.
    pub fn center_velocities_within(
        &self,
        interrupted: &dyn Fn() -> bool,
    ) -> Result<Vec<Vector3<f64>>> {
        let n = self.count();
        if self.model == Model::Averaged {
            let mut sys = self.system()?;
            let mut dy = vec![0.0; self.state.len()];
            sys.rhs(self.time, &self.state, &mut dy);
            return Ok((0..n).map(|i| vec3(&dy, STATE_PER_SWIMMER * i)).collect());
        }
        let period = self.period()?;
        let mut probe = self.clone();
        probe
            .run_periods(1.0, interrupted)
            .map_err(|e| probe_error(e, self))?;
        (0..n)
            .map(|i| Ok((probe.displacement(i)? - self.displacement(i)?) / period))
            .collect()
    }

    /// The state vector (see [`super::model`]) and the base positions: for tests and savers.
    pub fn raw_state(&self) -> (&[f64], &[Vector3<f64>]) {
        (&self.state, &self.base)
    }

    fn system(&self) -> Result<Box<dyn OdeSystem>> {
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
    fn check_averaged(&self) -> Result<()> {
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

    // ----- running ---------------------------------------------------------------------------

    /// Advance the scene by `duration` seconds. Equivalent to:
    ///
    /// ```text
    /// t_end = time + duration
    /// while time < t_end:
    ///     if interrupted(): stop with Interrupted (state and time of the last step kept)
    ///     take one step of the integrator towards t_end (never past it)
    ///     if the new state has NaN/inf, overlapping spheres or a runaway spring:
    ///         adaptive: retry with a smaller step; fixed-step: stop with StepFailed
    ///         (swimmer, time, cause), keeping the last good state
    ///     time = new time
    ///     for each recorder due at this time (steps end exactly on due times): take a row
    /// ```
    /// Recorders also take a row at the end of the run if their trigger is "at end". Rows taken
    /// before an error or interrupt are kept.
    pub fn run(&mut self, duration: f64, interrupted: &dyn Fn() -> bool) -> Result<()> {
        require_finite("duration", duration)?;
        if duration < 0.0 {
            return Err(invalid!(
                "duration must be >= 0 s, got {duration}; the dynamics cannot run backwards"
            ));
        }
        let t_end = self.time + duration;
        self.check_run(t_end)?;
        loop {
            // Stop where a recorder wants a row, so nothing is evaluated between rows.
            let segment_end = self
                .recorders
                .iter()
                .filter_map(|r| r.next_due(self.time))
                .fold(t_end, f64::min)
                .max(self.time);
            self.advance_to(segment_end, interrupted)?;
            let end_of_run = self.time >= t_end;
            self.fire_recorders(end_of_run, interrupted)?;
            if end_of_run {
                return Ok(());
            }
        }
    }

    /// What is refused before a run to `t_end` starts: a recorder the run cannot resolve or that
    /// would take more rows than [`super::recorder::MAX_ROWS_PER_RUN`], a fixed step that cannot
    /// advance the time, more than [`MAX_FIXED_STEPS_PER_RUN`] steps.
    fn check_run(&self, t_end: f64) -> Result<()> {
        if t_end <= self.time {
            return Ok(());
        }
        for r in &self.recorders {
            r.check_run(self.time, t_end)?;
        }
        if let IntegratorSpec::Euler { dt } | IntegratorSpec::Rk4 { dt } = self.integrator() {
            let scale = self.time.abs().max(t_end.abs());
            if dt < super::recorder::MIN_RELATIVE_INTERVAL * scale {
                return Err(invalid!(
                    "the step dt = {dt:e} s cannot advance the time at t = {scale:e} s (f64 resolves only ~{:e} s there); use a larger step, or a new scene from time 0",
                    super::recorder::MIN_RELATIVE_INTERVAL * scale
                ));
            }
            let steps = (t_end - self.time) / dt;
            if steps > MAX_FIXED_STEPS_PER_RUN {
                return Err(invalid!(
                    "this run would take {steps:.3e} steps of dt = {dt:e} s, more than the {MAX_FIXED_STEPS_PER_RUN:e} one run may take (days of computing); run a shorter time, split it into several runs, or use a larger step"
                ));
            }
        }
        Ok(())
    }

    fn fire_recorders(&mut self, end_of_run: bool, interrupted: &dyn Fn() -> bool) -> Result<()> {
        let mut recorders = std::mem::take(&mut self.recorders);
        let result = recorders
            .iter_mut()
            .try_for_each(|r| r.fire(self, end_of_run, interrupted));
        self.recorders = recorders;
        result
    }

    /// Integrate to `t_end` with the guards (the loop of [`Scene::run`] without recorders), on the
    /// backend [`Scene::backend_info`] names.
    fn advance_to(&mut self, t_end: f64, interrupted: &dyn Fn() -> bool) -> Result<()> {
        if self.time >= t_end {
            return Ok(());
        }
        if self.plan()?.0 {
            self.advance_gpu(t_end, interrupted)
        } else {
            self.advance_cpu(t_end, interrupted, u64::MAX)
        }
    }

    /// [`Scene::advance_to`] on the GPU: uniform steps as the CPU stepper takes them. A step whose
    /// state fails a guard on the device is replayed on the CPU, which either reports it exactly
    /// as the CPU backend does or (a borderline case decided differently by rounding) takes it.
    fn advance_gpu(&mut self, t_end: f64, interrupted: &dyn Fn() -> bool) -> Result<()> {
        let (dt, tableau) =
            backend::gpu_tableau(&self.integrator()).map_err(|e| invalid!("{e}"))?;
        let model = match self.model {
            Model::Micro => GpuModel::Micro {
                mu: self.mu,
                mobility: self.mobility,
            },
            Model::Averaged => {
                self.check_averaged()?;
                GpuModel::Averaged {
                    coefficients: self.coefficients,
                }
            }
            Model::Rigid => return Err(invalid!("the rigid-stroke model runs on the CPU only")),
        };
        let mut run = match self.gpu.take() {
            Some(r) if r.fits(model, self.count(), &tableau) => r,
            _ => GpuRun::new(model, self.count(), tableau.clone()).map_err(|e| invalid!("{e}"))?,
        };
        let stages = tableau.stages() as u64;
        let result = loop {
            if self.time >= t_end {
                break Ok(());
            }
            let (n, h) = uniform_steps(self.time, t_end, dt);
            let t0 = self.time;
            let outcome = run.run(
                &self.swimmers,
                &self.base,
                &mut self.state,
                UniformSteps { t0, h, count: n },
                interrupted,
            );
            let done = match outcome {
                Err(e) => {
                    break Err(unsupported(
                        format!(
                            "the GPU run failed: {e}; the scene keeps its state at t = {:.6e} s",
                            self.time
                        ),
                        &[Setting::Backend("cpu")],
                    ))
                }
                Ok(RunOutcome::Done) => n,
                Ok(RunOutcome::Failed { steps_done })
                | Ok(RunOutcome::Interrupted { steps_done }) => steps_done,
            };
            self.time = if done == n {
                t_end
            } else {
                t0 + done as f64 * h
            };
            self.stats.steps += done;
            self.stats.rhs_evals += done * stages + 1;
            self.report();
            match outcome {
                Ok(RunOutcome::Interrupted { .. }) => {
                    break Err(EngineError::Interrupted { time: self.time })
                }
                Ok(RunOutcome::Failed { .. }) => {
                    // One step on the CPU: the same step, checked by the same guards.
                    if let Err(e) = self.advance_cpu(t_end, interrupted, 1) {
                        break Err(e);
                    }
                }
                _ => {}
            }
        };
        self.gpu = Some(run);
        result
    }

    /// [`Scene::advance_to`] on the CPU, taking at most `max_steps` steps.
    fn advance_cpu(
        &mut self,
        t_end: f64,
        interrupted: &dyn Fn() -> bool,
        max_steps: u64,
    ) -> Result<()> {
        let mut sys = self.system()?;
        let spec = self.integrator();
        let mut stepper = match self.stepper.take() {
            Some((cached, mut st)) if cached == spec => {
                st.reset();
                st
            }
            _ => spec.build(),
        };
        let mut outcome = Ok(());
        let mut taken = 0;
        while self.time < t_end && taken < max_steps {
            taken += 1;
            if interrupted() {
                outcome = Err(EngineError::Interrupted { time: self.time });
                break;
            }
            match stepper.step(
                sys.as_mut(),
                self.time,
                &mut self.state,
                t_end,
                &mut self.stats,
            ) {
                Ok(t) => {
                    self.time = t;
                    self.report();
                }
                Err(f) => {
                    outcome = Err(EngineError::StepFailed {
                        time: f.time,
                        last_good: self.time,
                        swimmer: f.problem.swimmer,
                        cause: f.problem.cause,
                        hint: f.problem.hint,
                        fixes: f.problem.fixes,
                    });
                    break;
                }
            }
        }
        self.stepper = Some((spec, stepper));
        outcome
    }

    /// Report progress to `p` during runs (`None`: no reports).
    pub fn set_progress(&mut self, p: Option<Progress>) {
        self.progress = p;
    }

    /// Tell the progress report the current time.
    fn report(&self) {
        if let Some(p) = &self.progress {
            p(self.time);
        }
    }

    /// Take over the recorders of `old`, which this scene replaces.
    pub fn adopt_recorders(&mut self, old: Scene) {
        self.recorders = old.recorders;
    }

    /// Attach a recorder; returns its id.
    pub fn add_recorder(&mut self, r: Recorder) -> usize {
        self.recorders.push(r);
        self.recorders.len() - 1
    }

    /// A recorder by id, to change (e.g. to stream its rows).
    pub fn recorder_mut(&mut self, id: usize) -> Result<&mut Recorder> {
        self.recorders
            .get_mut(id)
            .ok_or_else(|| invalid!("recorder {id} does not belong to this scene"))
    }

    /// A recorder by id.
    pub fn recorder(&self, id: usize) -> Result<&Recorder> {
        self.recorders
            .get(id)
            .ok_or_else(|| invalid!("recorder {id} does not belong to this scene"))
    }

    /// Advance by `n` stroke periods (requires a common ω).
    pub fn run_periods(&mut self, n: f64, interrupted: &dyn Fn() -> bool) -> Result<()> {
        require_finite("periods", n)?;
        if n < 0.0 {
            return Err(invalid!("the number of periods must be >= 0, got {n}"));
        }
        let t = self.period()?;
        self.run(n * t, interrupted)
    }

    /// The largest spring relaxation rate k0 (1/γ1 + 1/γ2) in the scene (1/s): the stiffness.
    pub fn stiff_rate(&self) -> f64 {
        self.swimmers
            .iter()
            .map(|d| d.relaxation_rate(self.mu))
            .fold(0.0, f64::max)
    }
}

/// A cubic lattice of `swimmers` Fig-1 swimmers (symmetric, spacing 3ℓ, along x, phases spread
/// over the period) for timings: every pair interacts.
pub fn lattice_scene(swimmers: usize, model: Model) -> Result<Scene> {
    let mut s = Scene::new();
    s.set_model(model);
    let d = Dumbbell::default();
    let side = (swimmers as f64).cbrt().ceil() as usize;
    let spacing = 3.0 * d.ell;
    for i in 0..swimmers {
        let (x, y, z) = (i % side, (i / side) % side, i / (side * side));
        let phase = (i as f64 * 0.7) % (2.0 * std::f64::consts::PI);
        let c = Vector3::new(x as f64, y as f64, z as f64) * spacing;
        s.add(Dumbbell { phase, ..d }, c, Vector3::x())?;
    }
    Ok(s)
}

/// An interrupt of a probe run on a copy of `s`, reported at `s`'s own time (the copy's time means
/// nothing to the user: `s` itself did not move).
pub(crate) fn probe_error(e: EngineError, s: &Scene) -> EngineError {
    match e {
        EngineError::Interrupted { .. } => EngineError::Interrupted { time: s.time },
        other => other,
    }
}

/// A run that is never interrupted.
pub fn never() -> bool {
    false
}
