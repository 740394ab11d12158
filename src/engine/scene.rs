//! A scene: the swimmers, the fluid, the model that moves them, and the integrator: state and
//! settings only. What runs it (recorders, stepper, device buffers, interrupt and progress) is a
//! [`super::simulation::Simulation`].
//!
//! This file holds the state, its configuration and plain reading; the rest of `Scene` lives in
//! child modules: `dynamics` (the models' right-hand side and what it says now) and `save` (JSON,
//! and validation on load).

use super::averaged::AveragedSystem;
use super::backend::Backend;
use super::contacts::{Contacts, Overlaps, Steric};
use super::error::{
    invalid, require_finite, require_positive, unsupported, EngineError, Result, Setting,
};
use super::ewald::{Ewald, EwaldMethod, DEFAULT_EWALD_TOL, SPECTRAL_FROM_SPHERES};
use super::integrators::{IntegratorSpec, OdeSystem, Stats};
use super::micro::MicroSystem;
use super::mobility::Mobility;
use super::model::{set_vec3, vec3, Coefficients, Model, STATE_PER_SWIMMER};
use super::periodic::{separation, PeriodicBox};
use super::rigid::RigidSystem;
use super::swimmer::{unit_direction, Dumbbell};
use super::thermal::{NoiseRoot, Thermal};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

mod dynamics;
mod save;
pub use super::model::DEFAULT_MU;
pub use save::{MAX_TIME_IN_PERIODS, SAVE_FORMAT};

/// The microscopic model's default RK4 step times the stiffest spring's relaxation rate. RK4 is
/// stable up to 2.785; at 0.8 the stroke-induced wobble of an isolated asymmetric dumbbell's R_H
/// closes to < 1e-12 ℓ per period (measured 7e-13; at 2.0 it is 6e-11, which would be 5e-5 of the
/// Fig-1 drift). The error falls as dt⁵ (README, "Accuracy").
pub const DEFAULT_MICRO_STEP_TIMES_RATE: f64 = 0.8;
/// With thermal noise the spring model's default Euler-Maruyama step times the stiffest spring's
/// relaxation rate: Euler-Maruyama overestimates a spring's length variance kT/k0 by 1/(1 − 0.05).
pub const DEFAULT_NOISY_STEP_TIMES_RATE: f64 = 0.1;
/// The default step never exceeds this fraction of the shortest period, so that soft springs
/// (small k0) still resolve the stroke.
pub const DEFAULT_MICRO_MAX_STEP_PER_PERIOD: f64 = 1.0 / 200.0;
/// Default tolerance of the rigid-stroke model's adaptive integrator (README, "work-precision").
pub const DEFAULT_RIGID_RTOL: f64 = 1e-7;
/// The tolerance of `auto(tol)`, the default of the spring and rigid-stroke models without noise,
/// relative to the drift: ten times [`dynamics::RK4_DEFAULT_DRIFT_ERROR`], so that auto's inner RK4,
/// which steps where its drift error is a tenth of tol, steps at exactly the direct step
/// 0.8/rate. Runs that cannot be averaged are then the direct RK4 runs bit for bit; a larger
/// inner step errs on the drift of pairs far apart (a swimmer's own stroke error does not shrink
/// with the interaction; README, "Long runs").
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

/// Swimmer `d` must not reach its own image: the box's shortest side above 2(ℓ + λ + a1 + a2).
/// How far from the origin a swimmer's centre, and how long a box side, may reach, in units of
/// the scene's smallest sphere radius. A coordinate carries an error of an ulp (2.2e-16 of
/// itself) into every separation, minimum image and wrapped position, so at this reach a sphere
/// is still resolved to 2.2e-8 of its radius; far beyond, spheres merge (a dumbbell at 1e20 m has
/// both at one point) and wrapping returns NaN.
pub const MAX_EXTENT_IN_RADII: f64 = 1e8;

/// `x` to three significant digits, as a reader takes it in: "75", "7.5e-7".
fn short(x: f64) -> String {
    let r: f64 = format!("{x:.2e}").parse().unwrap_or(x);
    if (1e-3..1e6).contains(&r.abs()) {
        format!("{r}")
    } else {
        format!("{r:e}")
    }
}

/// The reach [`MAX_EXTENT_IN_RADII`] of swimmers `ds` (m), with the smallest radius; `None` without
/// swimmers.
fn extent_limit<'a>(ds: impl IntoIterator<Item = &'a Dumbbell>) -> Option<(f64, f64)> {
    let r = ds.into_iter().map(|d| d.a1.min(d.a2)).reduce(f64::min)?;
    Some((MAX_EXTENT_IN_RADII * r, r))
}

/// Refuse a swimmer centre that the scene's positions cannot carry ([`MAX_EXTENT_IN_RADII`]).
fn check_center<'a>(
    center: &Vector3<f64>,
    ds: impl IntoIterator<Item = &'a Dumbbell>,
) -> Result<()> {
    match extent_limit(ds) {
        Some(reach) => check_center_within(center, reach),
        None => Ok(()),
    }
}

/// [`check_center`] with the reach and the smallest radius, `(limit, r)`, already known.
fn check_center_within(center: &Vector3<f64>, (limit, r): (f64, f64)) -> Result<()> {
    for (k, c) in ["x", "y", "z"].iter().zip(center.iter()) {
        if c.abs() > limit {
            return Err(invalid!(
                "a swimmer's centre at {k} = {c:e} m is beyond the {} m from the origin that positions may reach ({MAX_EXTENT_IN_RADII:e} times the smallest sphere radius, {} m): there f64 no longer resolves the spheres (separations, minimum images and wrapped positions err by more than {:.0e} of a radius); place it within {} m of the origin",
                short(limit),
                short(r),
                MAX_EXTENT_IN_RADII * f64::EPSILON,
                short(limit)
            ));
        }
    }
    Ok(())
}

/// Refuse a box whose sides the scene's positions cannot carry ([`MAX_EXTENT_IN_RADII`]).
fn check_box_extent<'a>(b: &PeriodicBox, ds: impl IntoIterator<Item = &'a Dumbbell>) -> Result<()> {
    match extent_limit(ds) {
        Some(reach) => check_box_within(b, reach),
        None => Ok(()),
    }
}

/// [`check_box_extent`] with the reach and the smallest radius, `(limit, r)`, already known.
fn check_box_within(b: &PeriodicBox, (limit, r): (f64, f64)) -> Result<()> {
    for (k, l) in ["x", "y", "z"].iter().zip(b.sides()) {
        if l > limit {
            return Err(invalid!(
                "the box side along {k}, {l:e} m, is longer than the {} m that positions may reach ({MAX_EXTENT_IN_RADII:e} times the smallest sphere radius, {} m): across it f64 no longer resolves the spheres, and wrapping cannot carry them; give sides up to {} m, or no box for open space",
                short(limit),
                short(r),
                short(limit)
            ));
        }
    }
    Ok(())
}

/// Two spheres `gap` apart (m, surface to surface) are clear of each other by more than
/// `margin`; a NaN gap is not.
fn clear(gap: f64, margin: f64) -> bool {
    gap > margin
}

/// A new swimmer's spheres meet those of swimmer `s` (the gap, m, is ≤ 0 or NaN).
fn overlap_error(s: usize, gap: f64) -> EngineError {
    invalid!(
        "the new swimmer would overlap swimmer {s} (sphere gap {gap:.3e} m); place its centre further away"
    )
}

fn check_fits_box(d: &Dumbbell, b: &PeriodicBox) -> Result<()> {
    let reach = d.ell + d.lambda + d.a1 + d.a2;
    if b.shortest() <= 2.0 * reach {
        return Err(invalid!(
            "a box side of {:e} m is too short for a swimmer of reach ell + lambda + a1 + a2 = {reach:e} m, which would meet its own image; make every side longer than {:e} m",
            b.shortest(),
            2.0 * reach
        ));
    }
    Ok(())
}

/// Default tolerance of the averaged model's adaptive integrator.
pub const DEFAULT_AVERAGED_RTOL: f64 = 1e-8;

/// Default tolerance of `suspension(tol)`, the averaged model's default for a suspension: the
/// loosest decade whose displacements stay well within 1e-3 (RMS, relative) of fine RK4 on a
/// suspension with steric contacts (README, "Bulk suspensions at speed").
pub const DEFAULT_SUSPENSION_TOL: f64 = 1e-3;

/// From this many swimmers an averaged scene counts as a suspension (whatever its settings).
pub const SUSPENSION_SWIMMERS: usize = 64;

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
        Ok(self.push(d, center, n))
    }

    /// Add swimmers `(d, center, dir)` in order, all or none: the same checks as [`Scene::add`]
    /// one after another would make, each swimmer against the scene's and the earlier new ones,
    /// with the same first failure (the index into `items` and its error); on a failure the
    /// scene is unchanged. The overlaps are found through cell lists, O(n) for n swimmers at a
    /// bounded density, where adding them one at a time measures every pair, O(n²).
    pub fn add_many(
        &mut self,
        items: &[(Dumbbell, Vector3<f64>, Vector3<f64>)],
    ) -> std::result::Result<(), (usize, EngineError)> {
        // Everything but the overlaps, in order; the overlaps are looked for before the first
        // swimmer that fails here.
        let mut failed: Option<(usize, EngineError)> = None;
        let mut dirs = Vec::with_capacity(items.len());
        let mut a_min = self
            .swimmers
            .iter()
            .map(|o| o.a1.min(o.a2))
            .fold(f64::INFINITY, f64::min);
        for (k, (d, center, dir)) in items.iter().enumerate() {
            let checked = d.validate().and_then(|()| {
                for (name, c) in ["x", "y", "z"].iter().zip(center.iter()) {
                    require_finite(&format!("center.{name}"), *c)?;
                }
                let n = unit_direction(*dir)?;
                // The reach of the scene with this swimmer and the ones before it.
                a_min = a_min.min(d.a1.min(d.a2));
                let reach = (MAX_EXTENT_IN_RADII * a_min, a_min);
                check_center_within(center, reach)?;
                if let Some(b) = &self.periodic {
                    check_fits_box(d, b)?;
                    check_box_within(b, reach)?;
                }
                Ok(n)
            });
            match checked {
                Ok(n) => dirs.push(n),
                Err(e) => {
                    failed = Some((k, e));
                    break;
                }
            }
        }
        // Placed, then measured where the scene holds them (as one add after another would).
        let old = self.count();
        for ((d, center, _), n) in items.iter().zip(&dirs) {
            self.push(*d, *center, *n);
        }
        if let Some((k, s, gap)) = self.first_overlap(old, &dirs) {
            self.truncate(old);
            return Err((k, overlap_error(s, gap)));
        }
        if let Some(f) = failed {
            self.truncate(old);
            return Err(f);
        }
        Ok(())
    }

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

    /// Keep the first `count` swimmers only.
    fn truncate(&mut self, count: usize) {
        self.swimmers.truncate(count);
        self.base.truncate(count);
        self.state.truncate(STATE_PER_SWIMMER * count);
    }

    /// For [`Scene::add_many`], with its swimmers from `old` on just placed along `dirs`: the
    /// first of them (counted from `old`) that [`Scene::add`] would have refused for an overlap
    /// (a gap ≤ 0 between one of its spheres, where `add` measures them, and a sphere of an
    /// earlier swimmer, where the scene holds it), the first swimmer it overlaps, and the gap
    /// `add` would name.
    fn first_overlap(&self, old: usize, dirs: &[Vector3<f64>]) -> Option<(usize, usize, f64)> {
        let total = self.count();
        let (mut x, mut y, mut z) = (
            vec![0.0; 2 * total],
            vec![0.0; 2 * total],
            vec![0.0; 2 * total],
        );
        let mut radii = Vec::with_capacity(2 * total);
        for i in 0..total {
            let (x1, x2) = self.spheres(i);
            for (k, p) in [x1, x2].into_iter().enumerate() {
                (x[2 * i + k], y[2 * i + k], z[2 * i + k]) = (p.x, p.y, p.z);
            }
            radii.extend([self.swimmers[i].a1, self.swimmers[i].a2]);
        }
        let at = |j: usize| Vector3::new(x[j], y[j], z[j]);
        let a_max = radii.iter().copied().fold(0.0, f64::max);
        // Spheres overlap closer than the sum of their radii, at most 2 a_max: every such pair
        // is in neighbouring cells of that side.
        let side = 2.0 * a_max;
        let wraps = self.periodic.is_none_or(|b| side <= 0.5 * b.shortest());
        let grid = (side > 0.0 && side.is_finite() && wraps)
            .then(|| super::cells::CellGrid::build_in(&x, &y, &z, side, self.periodic.as_ref()));
        let gap = |p: Vector3<f64>, a: f64, j: usize| {
            separation(self.periodic.as_ref(), p - at(j)).norm() - a - radii[j]
        };
        let mut runs = Vec::with_capacity(27);
        for (k, n) in dirs.iter().enumerate() {
            let swimmer = old + k;
            let d = &self.swimmers[swimmer];
            let (c1, c2) = d.sphere_positions(self.base[swimmer], *n, self.contact_length(d));
            let mine = [(c1, d.a1), (c2, d.a2)];
            let mut first: Option<usize> = None;
            for &(p, a) in &mine {
                let mut check = |j: usize| {
                    if !clear(gap(p, a, j), 0.0) && first.is_none_or(|s| j / 2 < s) {
                        first = Some(j / 2);
                    }
                };
                match &grid {
                    Some(g) => {
                        g.neighbour_runs(p.x, p.y, p.z, &mut runs);
                        for &(from, to) in &runs {
                            // A run holds its points in ascending order: the earlier swimmers'
                            // spheres come first.
                            for &j in &g.order[from as usize..to as usize] {
                                if j as usize >= 2 * swimmer {
                                    break;
                                }
                                check(j as usize);
                            }
                        }
                    }
                    None => (0..2 * swimmer).for_each(check),
                }
            }
            if let Some(s) = first {
                // The gap `add` names: the first overlapping pair in its order.
                let named = mine
                    .iter()
                    .flat_map(|&(p, a)| [2 * s, 2 * s + 1].map(|j| gap(p, a, j)))
                    .find(|&g| !clear(g, 0.0))
                    .unwrap_or(f64::NAN);
                return Some((k, s, named));
            }
        }
        None
    }

    /// Whether [`Scene::add`] would accept this swimmer with every sphere gap above `margin` (m):
    /// valid, and no sphere within `margin` of another.
    pub fn fits(&self, d: &Dumbbell, center: Vector3<f64>, dir: Vector3<f64>, margin: f64) -> bool {
        d.validate().is_ok() && self.check_room(d, center, dir, margin).is_ok()
    }

    /// The length at which swimmer `d`'s spheres sit now: L(t), or ℓ in the averaged model, whose
    /// swimmers are stroke-averaged (its contact guard and steric repulsion use ℓ too).
    pub(in crate::engine) fn contact_length(&self, d: &Dumbbell) -> f64 {
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
        check_center(&center, self.swimmers.iter().chain([d]))?;
        if let Some(b) = &self.periodic {
            check_fits_box(d, b)?;
            check_box_extent(b, self.swimmers.iter().chain([d]))?;
        }
        let (x1, x2) = d.sphere_positions(center, n, self.contact_length(d));
        for (s, other) in self.swimmers.iter().enumerate() {
            let (y1, y2) = self.spheres(s);
            for (xa, aa) in [(x1, d.a1), (x2, d.a2)] {
                for (yb, ab) in [(y1, other.a1), (y2, other.a2)] {
                    let gap = separation(self.periodic.as_ref(), xa - yb).norm() - aa - ab;
                    if !clear(gap, margin) {
                        return Err(overlap_error(s, gap));
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

    /// What makes the next run far costlier than its length suggests, each as a notice of its
    /// kind with the fix: spectral Ewald sums chosen for a box of few spheres. Its FFT grid is
    /// transformed six times a product whatever the number of spheres, while Beenakker's sums
    /// shrink as N²; below a quarter of the crossover they cost (700/N)² ≳ 16 times less.
    pub fn cost_notices(&self) -> Vec<(&'static str, EngineError)> {
        let mut out = Vec::new();
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

    /// The box's periodic mobility for the sphere models (`None` in open space), its products by
    /// the scene's Ewald method.
    pub(crate) fn ewald(&self) -> Result<Option<Ewald>> {
        self.ewald_by(self.ewald_method)
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
            && (self.periodic.is_some()
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

    /// Where the dynamics run.
    pub fn backend(&self) -> Backend {
        self.backend
    }

    /// Choose where the dynamics run (checked when the scene runs: see [`super::plan`]).
    pub fn set_backend(&mut self, b: Backend) {
        self.backend = b;
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
        soa.periodic = self.periodic;
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

    /// The common period of all strokes (s): 2π/ω when the ω agree; when they differ but are
    /// commensurate (every ratio ωᵢ/ω₀ a fraction p/q with q ≤ [`MAX_PERIOD_DENOMINATOR`], to 1e-12),
    /// the least common multiple of the periods, if at most [`MAX_COMMON_PERIODS`] of the longest.
    pub fn common_period(&self) -> Result<f64> {
        let first = self.swimmers.first().ok_or_else(|| {
            unsupported(
                "the scene has no swimmers, so no period",
                &[Setting::AddSwimmer],
            )
        })?;
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
        match self.ewald()? {
            Some(e) => e.interaction_velocities(&pos, &radii, forces, &mut v),
            None => self
                .mobility
                .interaction_velocities(self.mu, &pos, &radii, forces, &mut v),
        }
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

    /// The shortest stroke period of the swimmers (s); infinite without swimmers.
    pub fn shortest_period(&self) -> f64 {
        self.swimmers
            .iter()
            .map(Dumbbell::period)
            .fold(f64::INFINITY, f64::min)
    }

    /// The largest spring relaxation rate k0 (1/γ1 + 1/γ2) in the scene (1/s): the stiffness.
    pub fn stiff_rate(&self) -> f64 {
        self.swimmers
            .iter()
            .map(|d| d.relaxation_rate(self.mu))
            .fold(0.0, f64::max)
    }
}
