//! Saving and loading a scene: JSON that round-trips exactly, and on load every value checked as
//! the setters check it (a file edited by hand, truncated or written by something else is refused
//! with the value at fault).

use super::*;
use serde::{Deserialize, Serialize};

/// The latest time a scene may hold, in stroke periods: at 1e9 periods f64 still resolves the
/// phase to ~1e-7 of a period (and a default microscopic step to ~1e-4 of itself).
pub const MAX_TIME_IN_PERIODS: f64 = 1e9;

/// Version of the JSON layout written by [`Scene::to_json`].
pub const SAVE_FORMAT: u32 = 1;

/// A scene file as read.
#[derive(Deserialize)]
struct Loaded {
    format: u32,
    scene: SceneFile,
}

#[derive(Serialize)]
struct SavedScene {
    format: u32,
    scene: SceneFile,
}

/// A scene as its file holds it, field by field in the order written: the boundary as a "box"
/// and a "wall", each saved only when set, and every value saved only when not its default
/// where older files lack it.
#[derive(Serialize, Deserialize)]
#[serde(rename = "Scene")]
struct SceneFile {
    mu: f64,
    model: Model,
    mobility: Mobility,
    coefficients: Coefficients,
    /// Defaults for older files.
    #[serde(default)]
    contacts: Contacts,
    #[serde(default)]
    cutoff: Option<f64>,
    integrator: Option<IntegratorSpec>,
    swimmers: Vec<Dumbbell>,
    base: Vec<Vector3<f64>>,
    state: Vec<f64>,
    /// Older files have none: the origins become the state as loaded (the displacements' origin
    /// kept at the base positions, as `msd()` had it).
    #[serde(default)]
    origins: Vec<Origin>,
    time: f64,
    stats: Stats,
    /// "cpu" for files from before backends existed.
    #[serde(default)]
    backend: Backend,
    /// Saved unless all default, so noise-free files are unchanged.
    #[serde(default, skip_serializing_if = "Thermal::is_default")]
    thermal: Thermal,
    #[serde(default, rename = "box", skip_serializing_if = "Option::is_none")]
    periodic: Option<PeriodicBox>,
    /// Saved only when set: a scene that follows its run's integrator keeps following it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    ewald_tol: Option<f64>,
    #[serde(default, skip_serializing_if = "is_auto_ewald")]
    ewald_method: EwaldMethod,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    wall: Option<Wall>,
    #[serde(default, skip_serializing_if = "ExternalForces::is_none")]
    external: ExternalForces,
}

fn is_auto_ewald(m: &EwaldMethod) -> bool {
    *m == EwaldMethod::Auto
}

impl SceneFile {
    /// The file of scene `s`.
    fn of(s: &Scene) -> Self {
        SceneFile {
            mu: s.mu,
            model: s.model,
            mobility: s.mobility,
            coefficients: s.coefficients,
            contacts: s.contacts,
            cutoff: s.cutoff,
            integrator: s.integrator,
            swimmers: s.swimmers.clone(),
            base: s.base.clone(),
            state: s.state.clone(),
            origins: s.origins.clone(),
            time: s.time,
            stats: s.stats,
            backend: s.backend,
            thermal: s.thermal,
            periodic: s.periodic().copied(),
            ewald_tol: s.ewald_tol,
            ewald_method: s.ewald_method,
            wall: s.wall().copied(),
            external: s.external,
        }
    }

    /// The scene of this file in open space, and the box and wall the file gives.
    fn into_parts(self) -> (Scene, Option<PeriodicBox>, Option<Wall>) {
        let scene = Scene {
            mu: self.mu,
            model: self.model,
            mobility: self.mobility,
            coefficients: self.coefficients,
            contacts: self.contacts,
            cutoff: self.cutoff,
            integrator: self.integrator,
            swimmers: self.swimmers,
            base: self.base,
            state: self.state,
            origins: self.origins,
            time: self.time,
            stats: self.stats,
            backend: self.backend,
            thermal: self.thermal,
            boundary: Boundary::Open,
            ewald_tol: self.ewald_tol,
            ewald_method: self.ewald_method,
            external: self.external,
        };
        (scene, self.periodic, self.wall)
    }
}

impl Scene {
    /// The latest time this scene may hold (s): [`MAX_TIME_IN_PERIODS`] of its longest stroke
    /// period (of 1 s without swimmers). A load refuses a later time, and no run goes past it.
    pub fn latest_time(&self) -> f64 {
        let longest = self
            .swimmers
            .iter()
            .map(Dumbbell::period)
            .reduce(f64::max)
            .unwrap_or(1.0);
        longest * MAX_TIME_IN_PERIODS
    }

    /// The scene as JSON (swimmers, phases, model, integrator, time, state), exactly round-tripping.
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string_pretty(&SavedScene {
            format: SAVE_FORMAT,
            scene: SceneFile::of(self),
        })
        .map_err(|e| invalid!("cannot serialise the scene: {e}"))
    }

    /// The scene as [`Scene::to_json`] writes it, as a JSON value (a checkpoint nests it).
    pub fn to_json_value(&self) -> Result<serde_json::Value> {
        serde_json::to_value(SavedScene {
            format: SAVE_FORMAT,
            scene: SceneFile::of(self),
        })
        .map_err(|e| invalid!("cannot serialise the scene: {e}"))
    }

    /// A scene from [`Scene::to_json`] output.
    pub fn from_json(text: &str) -> Result<Scene> {
        Self::from_loaded(
            serde_json::from_str(text).map_err(|e| invalid!("not a swimlab scene file: {e}"))?,
        )
    }

    /// A scene from [`Scene::to_json_value`] output.
    pub fn from_json_value(value: serde_json::Value) -> Result<Scene> {
        Self::from_loaded(
            serde_json::from_value(value).map_err(|e| invalid!("not a swimlab scene file: {e}"))?,
        )
    }

    /// The scene of a file read, every value checked as the setters check it.
    fn from_loaded(loaded: Loaded) -> Result<Scene> {
        if loaded.format != SAVE_FORMAT {
            return Err(invalid!(
                "scene file format {} is not supported (this swimlab reads format {SAVE_FORMAT})",
                loaded.format
            ));
        }
        let (s, periodic, wall) = loaded.scene.into_parts();
        let n = s.swimmers.len();
        if s.base.len() != n || s.state.len() != STATE_PER_SWIMMER * n {
            return Err(invalid!(
                "scene file is inconsistent: {n} swimmers but {} base positions and {} state values",
                s.base.len(),
                s.state.len()
            ));
        }
        // The origins after the state is checked: an old file's are read from its orientations.
        let mut s = s.validate(periodic, wall)?;
        if s.origins.is_empty() {
            s.origins = (0..n)
                .map(|i| Origin {
                    displacement: Vector3::zeros(),
                    dir: vec3(&s.state, STATE_PER_SWIMMER * i + 3).normalize(),
                })
                .collect();
        }
        if s.origins.len() != n {
            return Err(invalid!(
                "scene file is inconsistent: {n} swimmers but {} origins; remove \"origins\" to measure from the state as loaded",
                s.origins.len()
            ));
        }
        for (i, o) in s.origins.iter().enumerate() {
            let finite = o
                .displacement
                .iter()
                .chain(o.dir.iter())
                .all(|x| x.is_finite());
            if !finite || (o.dir.norm() - 1.0).abs() > 1e-9 {
                return Err(invalid!(
                    "the origin of swimmer {i} is not a finite displacement and a unit orientation; remove \"origins\" to measure from the state as loaded"
                ));
            }
        }
        Ok(s)
    }

    /// Check a scene read from a file, in open space, as the setters check their values, and put
    /// it in the boundary the file gives (`periodic`, `wall`): a file that was edited by hand,
    /// truncated or written by something else is refused with the value at fault.
    fn validate(mut self, periodic: Option<PeriodicBox>, wall: Option<Wall>) -> Result<Scene> {
        require_positive("mu", self.mu, "Pa s")?;
        if let Some(spec) = self.integrator {
            spec.checked()?;
        }
        if let Some(st) = self.contacts.steric {
            Steric::new(st.range, st.stiffness)?;
        }
        self.thermal.validate()?;
        if let Some(t) = self.ewald_tol {
            crate::engine::ewald::check_tol(t)?;
        }
        if let Some(b) = periodic {
            let mut probe = Scene::new();
            probe.set_box(Some(b.sides()))?;
            for (i, d) in self.swimmers.iter().enumerate() {
                b.check_fits(d).map_err(|e| invalid!("swimmer {i}: {e}"))?;
            }
        }
        let wall = wall.map(Wall::checked).transpose()?;
        self.boundary = Boundary::from_saved(periodic, wall)?;
        self.check_boundary_reach()?;
        self.check_clear_of(self.geometry())?;
        crate::engine::forces::ExternalForces::check_force(self.external.force)?;
        if let Some(g) = self.external.gravity {
            g.checked()?;
        }
        if let Some(c) = self.cutoff {
            let mut probe = Scene::new();
            probe.set_cutoff(Some(c))?;
        }
        for (i, d) in self.swimmers.iter().enumerate() {
            d.validate().map_err(|e| invalid!("swimmer {i}: {e}"))?;
        }
        require_finite("time", self.time)?;
        if self.time < 0.0 {
            return Err(invalid!(
                "time is {:e} s; a scene's time starts at 0 and only grows",
                self.time
            ));
        }
        let t_max = self.latest_time();
        if self.time > t_max {
            return Err(invalid!(
                "time is {:e} s, beyond {MAX_TIME_IN_PERIODS:e} stroke periods ({t_max:e} s), where f64 no longer resolves the stroke; reset the time to 0 (the state is what matters)",
                self.time
            ));
        }
        for (i, b) in self.base.iter().enumerate() {
            if !b.iter().all(|x| x.is_finite()) {
                return Err(invalid!("base position of swimmer {i} is not finite"));
            }
        }
        if let Some(k) = self.state.iter().position(|v| !v.is_finite()) {
            return Err(invalid!(
                "state value {k} (swimmer {}) is not finite",
                k / STATE_PER_SWIMMER
            ));
        }
        for i in 0..self.count() {
            super::check_center(&self.center(i)?, &self.swimmers)
                .map_err(|e| invalid!("swimmer {i}: {e}"))?;
        }
        if let Some(extent) = Extent::of(&self.swimmers) {
            self.geometry().check_cell(&extent)?;
        }
        let model = self.swimmer_model();
        for i in 0..self.count() {
            model.check_vector(i, &vec3(&self.state, STATE_PER_SWIMMER * i + 3))?;
        }
        if let Some((gap, a, b)) = self.closest_spheres() {
            let (sa, sb) = (self.owner(a), self.owner(b));
            let same = sa == sb;
            if gap <= 0.0 && (same || !self.contacts.allow_overlap) {
                return Err(invalid!(
                    "spheres {a} and {b} (swimmers {sa} and {sb}) overlap by {:.3e} m; move them apart{}",
                    -gap,
                    if same { "" } else { ", or allow overlaps (\"overlaps\": allow)" }
                ));
            }
        }
        Ok(self)
    }
}
