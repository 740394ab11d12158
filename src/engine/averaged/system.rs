//! The averaged system: its shortcuts, sizes, per-swimmer state and settings (contacts, box,
//! noise, cutoff, lists), and the structure of arrays refilled from the state.

use super::arrays::{Listed, Soa};
use super::terms::{Coef, CutoffSwitch};
use crate::engine::contacts::Contacts;
use crate::engine::mobility::Mobility;
use crate::engine::model::{vec3, Coefficients, STATE_PER_SWIMMER};
use crate::engine::pairs::SoaSpheres;
use crate::engine::periodic::PeriodicBox;
use crate::engine::swimmer::Dumbbell;
use crate::engine::thermal::{RigidDiffusion, Thermal};
use nalgebra::Vector3;

/// Which shortcuts the averaged model may take. All are exact (they skip terms that are zero or
/// evaluate the same algebra in 1D); switching them off is for tests that prove it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shortcuts {
    /// Leave out pairs with sin(φσ − φρ) = 0.
    pub skip_zero_phase_pairs: bool,
    /// Leave out the I and K terms of symmetric swimmers (A_R = A_N = 0).
    pub skip_symmetric_terms: bool,
    /// Use the 1D reduction (e:stroke_averaged) when every centre and orientation is on one line.
    pub aligned_1d: bool,
}

impl Default for Shortcuts {
    fn default() -> Self {
        Shortcuts {
            skip_zero_phase_pairs: true,
            skip_symmetric_terms: true,
            aligned_1d: true,
        }
    }
}

impl Shortcuts {
    /// No shortcut: every pair and term is evaluated in 3D.
    pub fn none() -> Self {
        Shortcuts {
            skip_zero_phase_pairs: false,
            skip_symmetric_terms: false,
            aligned_1d: false,
        }
    }
}

/// From this many swimmers on, the rows of the pair sums run in parallel: each row costs O(S),
/// so the rows together are then long enough that rayon's dispatch is a negligible share of them
/// (timings in the book's design notes).
pub const PARALLEL_SWIMMERS: usize = 256;

/// The stroke-averaged right-hand side.
///
/// Every row σ sums over all ρ (sin(φσ − φρ) from the stored sin φ and cos φ, so no pair list is
/// kept: memory is O(S)): in index order below [`LANE_SWIMMERS`], in 8 vector lanes from there
/// ([`super::lanes`]), through cell lists for a cutoff from [`CELL_LIST_SWIMMERS`]. Rows run in parallel
/// from [`PARALLEL_SWIMMERS`] on, and a row's sum does not depend on the thread count.
///
/// Far-field cutoff ([`AveragedSystem::set_cutoff`], off by default): pairs further apart than D_c
/// are left out, and pairs beyond D_s = (1 − w)D_c weighed down smoothly ([`CutoffSwitch`]). Each
/// term of a pair at distance D ≥ D_s is bounded with |sin| ≤ 1 and every bracket bounded term by
/// term (|N·D̂|, |q| ≤ 1): what the cutoff takes from such a pair is at most
/// |ΔdR_H/dt| ≤ (9/64) v0 [28 |A_R| (Λ/ℓ) ξ³ + 84 c_J ξ⁴] and
/// |ΔdN/dt| ≤ w0 (Λ/ℓ) [(15/64)·148 ξ⁵ + (9/32)·68 |A_N| ξ⁴], ξ = ℓ/D_s
/// ([`AveragedSystem::far_pair_bound`] at D_s); a swimmer's error is at most the number of its
/// pairs beyond D_s times that. The D⁻³ term of asymmetric swimmers decays slowest: in a uniform
/// suspension the number of pairs in a shell grows as D², so the cutoff suits symmetric swimmers
/// (D⁻⁴ and faster) or a dilute scene best.
#[derive(Debug, Clone)]
pub struct AveragedSystem {
    pub(super) coef: Vec<Coef>,
    pub(super) base: Vec<Vector3<f64>>,
    pub(super) sin_phi: Vec<f64>,
    pub(super) cos_phi: Vec<f64>,
    pub(super) soa: Soa,
    pub(super) skip_zero_phase: bool,
    /// D_c² (m²); infinite without a cutoff.
    pub(super) cutoff2: f64,
    /// The cutoff's switch (every pair weighs 1 without a cutoff).
    pub(super) switch: CutoffSwitch,
    /// The common axis when every centre and orientation lies on one line.
    pub(super) axis: Option<Vector3<f64>>,
    pub(super) scale_r: Vec<f64>,
    pub(super) scale_n: Vec<f64>,
    pub(super) skip_symmetric: bool,
    /// The weights (w1, w2) placing each swimmer's spheres about R_H.
    pub(super) weights: Vec<(f64, f64)>,
    /// Sphere radii, sphere 2σ being σ's a1 sphere (the sphere models' numbering).
    pub(super) radii: Vec<f64>,
    /// Sphere centres at length ℓ, filled with the arrays (contact guard and steric repulsion).
    pub(super) sphere_pos: Vec<Vector3<f64>>,
    /// Steric force on every sphere (scratch; empty without the repulsion).
    pub(super) steric_f: Vec<Vector3<f64>>,
    /// Sphere centres for the contact guard's minimum-gap pass (scratch).
    pub(super) gap_soa: SoaSpheres,
    pub(super) contacts: Contacts,
    pub(super) mu: f64,
    /// Use neighbour lists for a cutoff: `None` decides by size ([`LIST_SWIMMERS`]).
    pub(super) lists: Option<bool>,
    /// The skin of the neighbour lists (m); `None`: [`DEFAULT_SKIN_OF_CUTOFF`] of the cutoff.
    pub(super) skin: Option<f64>,
    /// The lists and their slot arrays (with a cutoff and lists in use).
    pub(super) listed: Listed,
    /// Sum all-pairs rows in vector lanes: `None` decides by size ([`LANE_SWIMMERS`]).
    pub(super) lanes: Option<bool>,
    /// Thermal noise: the seed and each swimmer's rigid-dumbbell diffusion.
    pub(super) thermal: Option<(u64, Vec<RigidDiffusion>)>,
    /// The periodic box, if any: pairs by minimum image (the scene requires a cutoff ≤ L/2).
    pub(super) periodic: Option<PeriodicBox>,
    /// The shortest stroke period (s; infinite without swimmers): the time scale adaptive steps
    /// are held to.
    pub(super) period: f64,
}

/// From this many swimmers the all-pairs rows are summed in vector lanes ([`super::lanes`]); below it
/// the scalar rows, whose sums are in index order.
pub const LANE_SWIMMERS: usize = 256;

/// From this many swimmers a cutoff's pairs are summed over neighbour lists
/// ([`crate::engine::neighbours`]): below it the all-pairs loop is as fast. The two differ only by the
/// rounding of the sums' order.
pub const LIST_SWIMMERS: usize = 256;

/// The neighbour lists' skin as a fraction of the cutoff: a list holds pairs within 1.1 cutoffs
/// (a third more pairs) and lasts until a swimmer has moved 0.05 cutoffs.
pub const DEFAULT_SKIN_OF_CUTOFF: f64 = 0.05;

impl AveragedSystem {
    /// A system for these swimmers with every shortcut; `y` is the current state (used to detect an
    /// aligned scene).
    pub fn new(swimmers: &[Dumbbell], base: &[Vector3<f64>], set: Coefficients, y: &[f64]) -> Self {
        Self::with_shortcuts(swimmers, base, set, y, Shortcuts::default())
    }

    /// A system taking only the given shortcuts.
    pub fn with_shortcuts(
        swimmers: &[Dumbbell],
        base: &[Vector3<f64>],
        set: Coefficients,
        y: &[f64],
        shortcuts: Shortcuts,
    ) -> Self {
        let coef: Vec<Coef> = swimmers.iter().map(|d| Coef::new(d, set)).collect();
        let n = coef.len();
        let mut soa = Soa::default();
        for v in [
            &mut soa.x,
            &mut soa.y,
            &mut soa.z,
            &mut soa.nx,
            &mut soa.ny,
            &mut soa.nz,
        ] {
            v.resize(n, 0.0);
        }
        let mut sys = AveragedSystem {
            scale_r: swimmers.iter().map(Dumbbell::drift_scale).collect(),
            // The matching rotation scale (λ/ℓ)²(Λ/ℓ).
            scale_n: swimmers
                .iter()
                .map(|d| d.drift_scale() / d.stroke_scale())
                .collect(),
            sin_phi: coef.iter().map(|c| c.phase.sin()).collect(),
            cos_phi: coef.iter().map(|c| c.phase.cos()).collect(),
            coef,
            base: base.to_vec(),
            soa,
            skip_zero_phase: shortcuts.skip_zero_phase_pairs,
            cutoff2: f64::INFINITY,
            switch: CutoffSwitch::new(None),
            axis: None,
            skip_symmetric: shortcuts.skip_symmetric_terms,
            weights: swimmers.iter().map(|d| (d.w1(), d.w2())).collect(),
            radii: swimmers.iter().flat_map(|d| [d.a1, d.a2]).collect(),
            sphere_pos: vec![Vector3::zeros(); 2 * n],
            steric_f: Vec::new(),
            gap_soa: SoaSpheres::default(),
            contacts: Contacts::default(),
            mu: crate::engine::model::DEFAULT_MU,
            lists: None,
            skin: None,
            listed: Listed::default(),
            lanes: None,
            thermal: None,
            periodic: None,
            period: swimmers
                .iter()
                .map(Dumbbell::period)
                .fold(f64::INFINITY, f64::min),
        };
        if shortcuts.aligned_1d {
            sys.axis = sys.common_axis(y);
        }
        sys
    }

    /// Contact handling in fluid of viscosity `mu`. The averaged model knows no sphere positions;
    /// for contacts its swimmers are rigid dumbbells of length ℓ, spheres at R_H − w2 ℓN and
    /// R_H + w1 ℓN. By default the run stops when spheres of two swimmers overlap (the far-field
    /// terms grow as D⁻⁵ there, the model has left its range). Steric forces F₁, F₂ on a swimmer's
    /// spheres move it as a free-draining rigid dumbbell: dR_H/dt += (F₁ + F₂)/(6πμ(a1 + a2)),
    /// dN/dt += (1 − NNᵀ)(F₂/(6πμa2) − F₁/(6πμa1))/ℓ (the rod's tension drops out).
    pub fn set_contacts(&mut self, contacts: Contacts, mu: f64) {
        self.contacts = contacts;
        self.mu = mu;
        self.steric_f = match contacts.steric {
            Some(_) => vec![Vector3::zeros(); self.radii.len()],
            None => Vec::new(),
        };
        if contacts.steric.is_some() {
            // The 1D reduction has no sphere geometry.
            self.axis = None;
        }
    }

    /// Put the swimmers in periodic box `periodic`: every pair by its minimum image. The caller
    /// sets a cutoff of at most half the shortest side, so a pair meets one image at most. The
    /// 1D reduction and the all-pairs vector rows are open space's and are not used in a box.
    pub fn set_periodic(&mut self, periodic: Option<PeriodicBox>) {
        self.periodic = periodic;
        self.gap_soa.periodic = periodic;
        if periodic.is_some() {
            self.axis = None;
        }
    }

    /// Thermal noise at `thermal`'s temperature: every swimmer diffuses as a rigid dumbbell of
    /// length ℓ ([`RigidDiffusion`]) in fluid of viscosity `mu` with the pair `mobility`.
    pub fn set_thermal(
        &mut self,
        thermal: Thermal,
        swimmers: &[Dumbbell],
        mu: f64,
        mobility: Mobility,
    ) -> crate::engine::error::Result<()> {
        self.thermal = if thermal.is_on() {
            let d = swimmers
                .iter()
                .map(|d| RigidDiffusion::new(d, d.ell, mu, mobility, thermal.kt()))
                .collect::<crate::engine::error::Result<Vec<_>>>()?;
            Some((thermal.seed, d))
        } else {
            None
        };
        Ok(())
    }

    /// Force the vector-lane rows on or off (`None`: by size). They equal the scalar rows to the
    /// rounding of the summation order.
    pub fn set_vector_rows(&mut self, on: Option<bool>) {
        self.lanes = on;
    }

    /// Force neighbour lists on or off for the cutoff's pairs (`None`: by size). They equal the
    /// all-pairs rows to the rounding of the summation order.
    pub fn set_neighbour_lists(&mut self, on: Option<bool>) {
        self.lists = on;
    }

    /// The neighbour lists' skin (m; `None`: [`DEFAULT_SKIN_OF_CUTOFF`] of the cutoff), shortened
    /// in a box to keep the list within half the shortest side.
    pub fn set_skin(&mut self, skin: Option<f64>) {
        self.skin = skin;
    }

    /// How often the neighbour lists were built (0 without lists).
    pub fn list_builds(&self) -> u64 {
        self.listed.builds()
    }

    /// How many swimmers the neighbour list in use relisted alone.
    pub fn list_relists(&self) -> u64 {
        self.listed.relists()
    }

    /// Leave out pairs further apart than `cutoff` (m); `None` keeps every pair.
    pub fn set_cutoff(&mut self, cutoff: Option<f64>) {
        self.cutoff2 = cutoff.map_or(f64::INFINITY, |c| c * c);
        self.switch = CutoffSwitch::new(cutoff);
    }

    /// Bounds on what one pair at distance `distance` (m) adds to swimmer σ's dR_H/dt (m/s) and
    /// dN/dt (1/s): the error per pair a cutoff at that distance makes (see the type's doc).
    pub fn far_pair_bound(&self, s: usize, distance: f64) -> (f64, f64) {
        let c = &self.coef[s];
        let xi = c.ell / distance;
        let v = 9.0 / 64.0
            * c.v0
            * (28.0 * c.a_r.abs() * c.big_l * xi.powi(3) + 84.0 * c.c_j * xi.powi(4));
        let w = c.w0
            * c.big_l
            * (15.0 / 64.0 * 148.0 * xi.powi(5) + 9.0 / 32.0 * 68.0 * c.a_n.abs() * xi.powi(4));
        (v, w)
    }

    /// Whether the 1D reduction is in use.
    pub fn is_aligned(&self) -> bool {
        self.axis.is_some()
    }

    pub(super) fn center(&self, y: &[f64], s: usize) -> Vector3<f64> {
        self.base[s] + vec3(y, STATE_PER_SWIMMER * s)
    }

    /// The line through all centres, if every orientation lies along it (to 1e-12).
    pub(super) fn common_axis(&self, y: &[f64]) -> Option<Vector3<f64>> {
        let n = self.coef.len();
        if n < 2 || y.len() < STATE_PER_SWIMMER * n {
            return None;
        }
        let axis = vec3(y, 3).normalize();
        let c0 = self.center(y, 0);
        (0..n)
            .all(|s| {
                let dn = vec3(y, STATE_PER_SWIMMER * s + 3).cross(&axis).norm();
                let dc = (self.center(y, s) - c0).cross(&axis).norm() / self.coef[s].ell;
                dn < 1e-12 && dc < 1e-12
            })
            .then_some(axis)
    }

    /// Fill the structure of arrays and the sphere centres (length ℓ) from the state `y`.
    pub(super) fn fill(&mut self, y: &[f64]) {
        for s in 0..self.coef.len() {
            self.fill_swimmer(y, s);
        }
    }

    /// Swimmer `s`'s entries of the arrays and its sphere centres from the state `y`.
    pub(super) fn fill_swimmer(&mut self, y: &[f64], s: usize) {
        let c = self.center(y, s);
        let n = vec3(y, STATE_PER_SWIMMER * s + 3);
        let soa = &mut self.soa;
        (soa.x[s], soa.y[s], soa.z[s]) = (c.x, c.y, c.z);
        (soa.nx[s], soa.ny[s], soa.nz[s]) = (n.x, n.y, n.z);
        let b = n * self.coef[s].ell;
        let (w1, w2) = self.weights[s];
        self.sphere_pos[2 * s] = c - w2 * b;
        self.sphere_pos[2 * s + 1] = c + w1 * b;
    }
}
