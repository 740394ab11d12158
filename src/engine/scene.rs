//! A scene: the swimmers, the fluid, the model that moves them, and the integrator: state and
//! settings only. What runs it (recorders, stepper, device buffers, interrupt and progress) is a
//! [`super::simulation::Simulation`].
//!
//! This file holds the struct; the rest of `Scene` lives in child modules: `state` (the
//! swimmers' state and its plain reading), `settings` (the fluid, the model and the numerics),
//! `boundary` (open space, the box or the wall, one [`Boundary`] value, and the reach positions
//! are held to), `placement` (adding swimmers and the checks they pass), `timing` (periods and
//! the integrator, set or default), `dynamics` (the models' right-hand side, what it says now
//! and what the next run costs), `external` (external forces, and what a failed step learns
//! from them) and `save` (JSON, and validation on load).

use super::backend::Backend;
use super::boundary::{Boundary, Extent, Geometry, Kind, MobilitySettings};
use super::contacts::{Contacts, Overlaps, Steric};
use super::error::{
    invalid, require_finite, require_positive, unsupported, EngineError, Result, Setting,
};
use super::ewald::{
    ewald_tol_for, Ewald, EwaldMethod, SPECTRAL_COSTLY_BELOW, SPECTRAL_FROM_SPHERES,
};
use super::forces::{ExternalForces, Gravity};
use super::integrators::{IntegratorSpec, OdeSystem, Reach, Stats};
use super::mobility::{Mobility, MobilityOperator};
use super::model::{
    set_vec3, vec3, Coefficients, Model, SceneView, SwimmerModel, STATE_PER_SWIMMER,
};
use super::models;
use super::periodic::PeriodicBox;
use super::swimmer::{unit_direction, Dumbbell};
use super::thermal::{NoiseRoot, Thermal};
use super::wall::Wall;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

mod boundary;
mod dynamics;
mod external;
pub(crate) use external::CollapseCause;
mod placement;
mod save;
mod settings;
mod state;
mod timing;
pub use super::boundary::MAX_EXTENT_IN_RADII;
pub use super::model::DEFAULT_MU;
use placement::check_center;
pub use save::MAX_TIME_IN_PERIODS;
pub use timing::{DEFAULT_AUTO_TOL, SUSPENSION_SWIMMERS};

/// The swimmers, the fluid and the numerics of one simulation.
///
/// State per swimmer: see [`super::model`]. Positions are SI (m), times s. The engine works in SI
/// throughout: f64 carries relative precision independently of scale, and the adaptive error control
/// measures each component against a physical scale (stroke λ, drift λ³Λ/ℓ³), not against 1.
///
/// Saved whole as JSON (`save`): the file layout is that module's, field by field.
#[derive(Clone)]
pub struct Scene {
    mu: f64,
    model: Model,
    mobility: Mobility,
    coefficients: Coefficients,
    /// Overlaps and steric repulsion between swimmers.
    contacts: Contacts,
    /// Far-field cutoff of the averaged model's pair sums (m); `None`: every pair.
    cutoff: Option<f64>,
    /// `None`: the model's default.
    integrator: Option<IntegratorSpec>,
    /// The swimmers' parameters (the steppers read them).
    pub(in crate::engine) swimmers: Vec<Dumbbell>,
    /// Hydrodynamic centre of each swimmer that the displacement in `state` is measured from.
    pub(in crate::engine) base: Vec<Vector3<f64>>,
    /// See [`super::model`]; the steppers advance it.
    pub(in crate::engine) state: Vec<f64>,
    /// Where each swimmer's displacement and orientation are measured from.
    origins: Vec<Origin>,
    pub(in crate::engine) time: f64,
    pub(in crate::engine) stats: Stats,
    /// Where the dynamics run.
    backend: Backend,
    /// Temperature and noise seed.
    thermal: Thermal,
    /// Open space, the periodic box or the wall.
    boundary: Boundary,
    /// Tolerance of the box's Ewald sums; `None`: the one that serves the run's integrator
    /// (`Scene::ewald_tol`).
    ewald_tol: Option<f64>,
    /// How the box's mobility products are summed.
    ewald_method: EwaldMethod,
    /// External forces on the spheres.
    external: ExternalForces,
}

/// Where a swimmer's displacement and orientation are measured from (`msd()`, the orientation
/// autocorrelation): its placement, or the last [`Scene::reset_origins`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Origin {
    /// The displacement of R_H from its base position then (m).
    pub displacement: Vector3<f64>,
    /// The unit orientation N then.
    pub dir: Vector3<f64>,
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
            origins: Vec::new(),
            time: 0.0,
            stats: Stats::default(),
            backend: Backend::default(),
            thermal: Thermal::default(),
            boundary: Boundary::Open,
            ewald_tol: None,
            ewald_method: EwaldMethod::Auto,
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
}
