//! A scene: the swimmers, the fluid, the model that moves them, and the integrator: state and
//! settings only. What runs it (recorders, stepper, device buffers, interrupt and progress) is a
//! [`super::simulation::Simulation`].
//!
//! This file holds the state, its configuration and plain reading; the rest of `Scene` lives in
//! child modules: `placement` (adding swimmers and the checks they pass), `timing` (periods and
//! the integrator, set or default), `dynamics` (the models' right-hand side, what it says now and
//! what the next run costs), `external` (the wall and external forces, and the reach positions and
//! the wall are held to) and `save` (JSON, and validation on load).

use super::averaged::AveragedSystem;
use super::backend::Backend;
use super::contacts::{Contacts, Overlaps, Steric};
use super::error::{
    invalid, require_finite, require_positive, unsupported, EngineError, Result, Setting,
};
use super::ewald::{Ewald, EwaldMethod, DEFAULT_EWALD_TOL, SPECTRAL_FROM_SPHERES};
use super::forces::{ExternalForces, Gravity};
use super::integrators::{IntegratorSpec, OdeSystem, Reach, Stats};
use super::micro::MicroSystem;
use super::mobility::{Mobility, MobilityOperator};
use super::model::{set_vec3, vec3, Coefficients, Model, STATE_PER_SWIMMER};
use super::open_space::OpenSpace;
use super::periodic::{separation, PeriodicBox};
use super::rigid::RigidSystem;
use super::swimmer::{unit_direction, Dumbbell};
use super::thermal::{NoiseRoot, Thermal};
use super::wall::{Wall, WallMobility};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

mod dynamics;
mod external;
mod placement;
mod save;
mod timing;
pub use super::model::DEFAULT_MU;
pub use placement::MAX_EXTENT_IN_RADII;
use placement::{check_box_extent, check_center, check_fits_box};
pub use save::{MAX_TIME_IN_PERIODS, SAVE_FORMAT};
pub use timing::{
    DEFAULT_AUTO_TOL, DEFAULT_AVERAGED_RTOL, DEFAULT_MICRO_MAX_STEP_PER_PERIOD,
    DEFAULT_MICRO_STEP_TIMES_RATE, DEFAULT_NOISY_STEP_TIMES_RATE, DEFAULT_RIGID_RTOL,
    DEFAULT_SUSPENSION_TOL, MAX_COMMON_PERIODS, MAX_PERIOD_DENOMINATOR, SUSPENSION_SWIMMERS,
};

/// The swimmers, the fluid and the numerics of one simulation.
///
/// State per swimmer: see [`super::model`]. Positions are SI (m), times s. The engine works in SI
/// throughout: f64 carries relative precision independently of scale, and the adaptive error control
/// measures each component against a physical scale (stroke λ, drift λ³Λ/ℓ³), not against 1.
#[derive(Clone, Serialize, Deserialize)]
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
    /// The swimmers' parameters (the steppers read them).
    pub(in crate::engine) swimmers: Vec<Dumbbell>,
    /// Hydrodynamic centre of each swimmer that the displacement in `state` is measured from.
    pub(in crate::engine) base: Vec<Vector3<f64>>,
    /// See [`super::model`]; the steppers advance it.
    pub(in crate::engine) state: Vec<f64>,
    pub(in crate::engine) time: f64,
    pub(in crate::engine) stats: Stats,
    /// Where the dynamics run (saved; "cpu" for files from before backends existed).
    #[serde(default)]
    backend: Backend,
    /// Temperature and noise seed (saved unless all default, so noise-free files are unchanged).
    #[serde(default, skip_serializing_if = "Thermal::is_default")]
    thermal: Thermal,
    /// The periodic box; `None`: open space (saved only when set).
    #[serde(default, rename = "box", skip_serializing_if = "Option::is_none")]
    periodic: Option<PeriodicBox>,
    /// Tolerance of the box's Ewald sums (saved only when not the default).
    #[serde(
        default = "default_ewald_tol",
        skip_serializing_if = "is_default_ewald_tol"
    )]
    ewald_tol: f64,
    /// How the box's mobility products are summed (saved only when not "auto").
    #[serde(default, skip_serializing_if = "is_auto_ewald")]
    ewald_method: EwaldMethod,
    /// A no-slip wall below the fluid; `None`: none (saved only when set).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    wall: Option<Wall>,
    /// External forces on the spheres (saved only when there are some).
    #[serde(default, skip_serializing_if = "ExternalForces::is_none")]
    external: ExternalForces,
}

fn is_auto_ewald(m: &EwaldMethod) -> bool {
    *m == EwaldMethod::Auto
}

fn default_ewald_tol() -> f64 {
    DEFAULT_EWALD_TOL
}

fn is_default_ewald_tol(t: &f64) -> bool {
    *t == DEFAULT_EWALD_TOL
}

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
            thermal: Thermal::default(),
            periodic: None,
            ewald_tol: DEFAULT_EWALD_TOL,
            ewald_method: EwaldMethod::Auto,
            wall: None,
            external: ExternalForces::default(),
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

    /// Add swimmer `d` (valid) with hydrodynamic centre `center` and unit orientation `n`, its room
    /// checked by the caller (random placement keeps its own cell lists). Returns its index.
    pub(in crate::engine) fn push(
        &mut self,
        d: Dumbbell,
        center: Vector3<f64>,
        n: Vector3<f64>,
    ) -> usize {
        let len = d.rest_length(self.time);
        self.swimmers.push(d);
        self.base.push(center);
        let v = match self.model {
            Model::Micro => n * len,
            Model::Averaged | Model::Rigid => n,
        };
        self.state
            .extend_from_slice(&[0.0, 0.0, 0.0, v.x, v.y, v.z]);
        self.swimmers.len() - 1
    }

    /// Whether swimmer `d` can be placed in this scene at all: valid, and in a box short of
    /// meeting its own image.
    pub(in crate::engine) fn check_placeable(&self, d: &Dumbbell) -> Result<()> {
        d.validate()?;
        if let Some(b) = &self.periodic {
            check_fits_box(d, b)?;
        }
        Ok(())
    }

    /// The length at which swimmer `d`'s spheres sit now: L(t), or ℓ in the averaged model, whose
    /// swimmers are stroke-averaged (its contact guard and steric repulsion use ℓ too).
    pub(in crate::engine) fn contact_length(&self, d: &Dumbbell) -> f64 {
        match self.model {
            Model::Averaged => d.ell,
            Model::Micro | Model::Rigid => d.rest_length(self.time),
        }
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

    /// What touching spheres of different swimmers do.
    pub fn set_overlaps(&mut self, o: Overlaps) {
        self.set_allow_overlap(o == Overlaps::Allow);
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

    /// The periodic box, if any (`None`: open space).
    pub fn periodic(&self) -> Option<&PeriodicBox> {
        self.periodic.as_ref()
    }

    /// Put the scene in a periodic box of sides `sides` (m), centred on the origin, or (`None`)
    /// back in open space. Every swimmer must fit (a box side longer than twice its reach
    /// ℓ + λ + a1 + a2, so that it never meets its own image) and no spheres may overlap by their
    /// minimum images; otherwise the scene is unchanged and the error says which.
    pub fn set_box(&mut self, sides: Option<[f64; 3]>) -> Result<()> {
        let Some(sides) = sides else {
            self.periodic = None;
            return Ok(());
        };
        if self.wall.is_some() {
            return Err(unsupported(
                "a periodic box together with a wall is not available (the wall's mobility has no periodic images); remove the wall first",
                &[Setting::NoWall],
            ));
        }
        let b = PeriodicBox::new(sides)?;
        for (i, d) in self.swimmers.iter().enumerate() {
            check_fits_box(d, &b).map_err(|e| invalid!("swimmer {i}: {e}"))?;
        }
        check_box_extent(&b, &self.swimmers)?;
        let old = self.periodic.replace(b);
        if let Some((gap, a, c)) = self.closest_spheres() {
            if gap <= 0.0 && !(self.contacts.allow_overlap && a / 2 != c / 2) {
                self.periodic = old;
                return Err(invalid!(
                    "in that box sphere {a} (swimmer {}) would overlap the image of sphere {c} (swimmer {}) by {:.3e} m; use a larger box or move the swimmers",
                    a / 2,
                    c / 2,
                    -gap
                ));
            }
        }
        Ok(())
    }

    /// Tolerance of the box's Ewald sums, relative to a sphere's Stokes mobility.
    pub fn ewald_tol(&self) -> f64 {
        self.ewald_tol
    }

    /// Set the tolerance of the box's Ewald sums (1e-15 to 1e-2).
    pub fn set_ewald_tol(&mut self, tol: f64) -> Result<()> {
        crate::engine::ewald::check_tol(tol)?;
        self.ewald_tol = tol;
        Ok(())
    }

    /// How the box's mobility products are summed: "auto", "beenakker" or "spectral".
    pub fn ewald_method(&self) -> EwaldMethod {
        self.ewald_method
    }

    /// Set how the box's mobility products are summed.
    pub fn set_ewald_method(&mut self, method: EwaldMethod) {
        self.ewald_method = method;
    }

    /// The box's periodic mobility for the sphere models (`None` in open space), its products by
    /// the scene's Ewald method.
    pub(crate) fn ewald(&self) -> Result<Option<Ewald>> {
        self.ewald_by(self.ewald_method)
    }

    /// The boundary's mobility for the sphere models: the box's Ewald sums with products by
    /// `method` (blocks and matrices are Beenakker's either way), the wall's, or open space.
    pub(crate) fn mobility_operator_by(
        &self,
        method: EwaldMethod,
    ) -> Result<Box<dyn MobilityOperator>> {
        Ok(match (self.ewald_by(method)?, self.wall) {
            (Some(e), _) => Box::new(e),
            (None, Some(w)) => Box::new(WallMobility::new(self.mu, self.mobility, w)),
            (None, None) => Box::new(OpenSpace::new(self.mu, self.mobility)),
        })
    }

    /// The boundary's mobility with the scene's Ewald method.
    pub(crate) fn mobility_operator(&self) -> Result<Box<dyn MobilityOperator>> {
        self.mobility_operator_by(self.ewald_method)
    }

    /// The box's periodic mobility with products by `method`.
    pub(crate) fn ewald_by(&self, method: EwaldMethod) -> Result<Option<Ewald>> {
        self.periodic
            .map(|b| {
                Ewald::with_method(
                    b,
                    self.mu,
                    self.mobility,
                    2 * self.count(),
                    self.ewald_tol,
                    method,
                    None,
                )
            })
            .transpose()
    }

    /// Position `p` as shown: wrapped into the box, if there is one.
    pub fn shown(&self, p: Vector3<f64>) -> Vector3<f64> {
        match &self.periodic {
            Some(b) => b.wrap(p),
            None => p,
        }
    }

    /// Temperature, noise seed and how the noise's square root is taken.
    pub fn thermal(&self) -> Thermal {
        self.thermal
    }

    /// Set the temperature (K); 0 turns thermal noise off.
    pub fn set_temperature(&mut self, kelvin: f64) -> Result<()> {
        self.thermal.temperature = Thermal::check_temperature(kelvin)?;
        Ok(())
    }

    /// Seed the noise: runs from the same state and seed draw the same noise.
    pub fn set_seed(&mut self, seed: u64) {
        self.thermal.seed = seed;
    }

    /// How √M·ξ is computed: dense Cholesky, Lanczos, or by size.
    pub fn set_noise_root(&mut self, root: NoiseRoot) {
        self.thermal.root = root;
    }

    /// The Lanczos iteration's tolerance.
    pub fn set_lanczos_tol(&mut self, tol: f64) -> Result<()> {
        self.thermal.lanczos_tol = Thermal::check_lanczos_tol(tol)?;
        Ok(())
    }

    /// Where the dynamics run.
    pub fn backend(&self) -> Backend {
        self.backend
    }

    /// Choose where the dynamics run (checked when the scene runs: see [`super::plan`]).
    pub fn set_backend(&mut self, b: Backend) {
        self.backend = b;
    }

    /// Set the stroke phase φ of swimmer `i` (rad). Where the phase places the spheres (the
    /// rigid-stroke and averaged models), a phase that would put one into the wall is refused and
    /// the scene kept.
    pub fn set_phase(&mut self, i: usize, phase: f64) -> Result<()> {
        self.check_index(i)?;
        require_finite("phase", phase)?;
        let old = self.swimmers[i].phase;
        self.swimmers[i].phase = phase;
        self.keep_above_wall(|s| s.swimmers[i].phase = old)
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
        let old = self.phases();
        for (d, p) in self.swimmers.iter_mut().zip(phases) {
            d.phase = *p;
        }
        self.keep_above_wall(|s| {
            for (d, p) in s.swimmers.iter_mut().zip(old) {
                d.phase = p;
            }
        })
    }

    // ----- reading ---------------------------------------------------------------------------

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

    /// Sphere velocities (m/s) for given sphere forces (N), one per sphere, swimmer by swimmer
    /// (the a1 sphere first), with the scene's mobility and viscosity at the present sphere
    /// positions: v_α = F_α/(6πμa_α) + Σ_{β≠α} H_αβ F_β; in a box the periodic mobility (Ewald
    /// sums, no net flow). For checks against other codes.
    pub fn sphere_velocities(&self, forces: &[Vector3<f64>]) -> Result<Vec<Vector3<f64>>> {
        let n = 2 * self.count();
        if forces.len() != n {
            return Err(invalid!(
                "sphere velocities need one force per sphere: {n} for {} swimmers (two spheres each, the a1 sphere first), got {}",
                self.count(),
                forces.len()
            ));
        }
        if let Some(k) = forces.iter().position(|f| !f.iter().all(|x| x.is_finite())) {
            return Err(invalid!(
                "the force on sphere {k} is not finite ({:?}); give finite numbers",
                forces[k].as_slice()
            ));
        }
        let mut pos = Vec::with_capacity(n);
        let mut radii = Vec::with_capacity(n);
        for (i, d) in self.swimmers.iter().enumerate() {
            let (x1, x2) = self.spheres(i);
            pos.extend([x1, x2]);
            radii.extend([d.a1, d.a2]);
        }
        let mut v = vec![Vector3::zeros(); n];
        self.mobility_operator()?
            .interaction_velocities(&pos, &radii, forces, &mut v);
        for ((vi, f), a) in v.iter_mut().zip(forces).zip(&radii) {
            *vi += f * super::mobility::self_mobility(self.mu, *a);
        }
        Ok(v)
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

    /// Sphere centres of swimmer `i` as shown (snapshots, trajectories): in a box moved with its
    /// R_H into the box, the swimmer kept whole (its spheres may reach over a face).
    pub fn shown_spheres(&self, i: usize) -> (Vector3<f64>, Vector3<f64>) {
        let (x1, x2) = self.spheres(i);
        let rh = self.base[i] + vec3(&self.state, STATE_PER_SWIMMER * i);
        let shift = self.shown(rh) - rh;
        (x1 + shift, x2 + shift)
    }
}
