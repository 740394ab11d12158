//! What a boundary means for the spheres, apart from its mobility products: the [`Geometry`]
//! trait; the [`Extent`] that positions (and a boundary's own size) are held to; the settings a
//! boundary's mobility operator is built from.

use crate::engine::error::Result;
use crate::engine::ewald::EwaldMethod;
use crate::engine::integrators::{Problem, Reach};
use crate::engine::mobility::{Mobility, MobilityOperator};
use crate::engine::periodic::{separation, PeriodicBox};
use crate::engine::swimmer::Dumbbell;
use crate::engine::wall::Wall;
use nalgebra::Vector3;

/// How far from the origin a swimmer's centre, a box side and a wall may reach, in units of the
/// scene's smallest sphere radius. A coordinate carries an error of an ulp (2.2e-16 of itself)
/// into every separation, minimum image and wrapped position, so at this reach a sphere is still
/// resolved to 2.2e-8 of its radius; far beyond, spheres merge (a dumbbell at 1e20 m has both at
/// one point) and wrapping returns NaN.
pub const MAX_EXTENT_IN_RADII: f64 = 1e8;

/// How far from the origin positions may lie: [`MAX_EXTENT_IN_RADII`] times the smallest sphere
/// radius.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extent {
    /// The largest |coordinate| (m).
    pub limit: f64,
    /// The smallest sphere radius it is measured in (m).
    pub radius: f64,
}

impl Extent {
    /// The extent of a scene whose smallest sphere has radius `radius` (m).
    pub fn of_radius(radius: f64) -> Self {
        Extent {
            limit: MAX_EXTENT_IN_RADII * radius,
            radius,
        }
    }

    /// The extent of swimmers `ds`; `None` without swimmers (positions are then unbounded).
    pub fn of<'a>(ds: impl IntoIterator<Item = &'a Dumbbell>) -> Option<Self> {
        ds.into_iter()
            .map(|d| d.a1.min(d.a2))
            .reduce(f64::min)
            .map(Extent::of_radius)
    }

    /// Why the limit lies where it does, in words for a message.
    pub fn why(&self) -> String {
        format!(
            "{MAX_EXTENT_IN_RADII:e} times the smallest sphere radius, {:e} m: beyond, f64 no longer resolves the spheres",
            self.radius
        )
    }

    /// The extent as the runs' guard holds each step's centres to it.
    pub fn reach(&self) -> Reach {
        Reach {
            limit: self.limit,
            why: self.why(),
        }
    }
}

/// What a boundary's mobility operator is built from: the fluid's viscosity, the pair tensor,
/// the number of spheres, and how a periodic box sums its images.
#[derive(Debug, Clone, Copy)]
pub struct MobilitySettings {
    /// Viscosity μ (Pa s).
    pub mu: f64,
    /// The pair tensor (RPY or Oseen).
    pub kind: Mobility,
    /// How many spheres the products take (a box's Ewald splitting is chosen for it).
    pub spheres: usize,
    /// Tolerance of a box's Ewald sums.
    pub ewald_tol: f64,
    /// How a box's products are summed.
    pub ewald_method: EwaldMethod,
}

/// What a boundary means for the spheres in it, each kind answering for itself: the defaults
/// are open space's (no images, nothing solid, nothing to fit).
/// How a pair of swimmers' terms of the rigid model's constraint matrix K come from closed-form
/// pair coefficients in a boundary (the tensions' fill): each kind says, so that a new kind
/// cannot be routed to another's fill without a word.
#[derive(Debug, Clone, Copy)]
pub enum PairTerms {
    /// Exactly: open space's pair tensor.
    Open,
    /// Exactly: open space's pair tensor and the wall's image terms, of the spheres lifted and
    /// damped as the wall's mobility takes them ([`Wall::lift`]).
    Wall(Wall),
    /// Not exactly (the box's pair terms are whole Ewald sums): open space's at the minimum
    /// images, a preconditioner for an iteration over the box's mobility products.
    MinimumImages(PeriodicBox),
}

impl PairTerms {
    /// Whether the pair coefficients give K itself (else only its approximation).
    pub fn exact(&self) -> bool {
        !matches!(self, PairTerms::MinimumImages(_))
    }
}

pub trait Geometry: std::fmt::Debug + Send + Sync {
    // ----- the rigid model's constraint matrix ---------------------------------------------

    /// How K's pair terms come from pair coefficients here ([`PairTerms`]).
    fn pair_terms(&self) -> PairTerms;

    // ----- minimum images ------------------------------------------------------------------

    /// The periodic box whose minimum images separations take; `None` where separations are
    /// taken as they are.
    fn periodic(&self) -> Option<&PeriodicBox> {
        None
    }

    /// Separation `r` as the pair passes see it: its minimum image in a box.
    fn separation(&self, r: Vector3<f64>) -> Vector3<f64> {
        separation(self.periodic(), r)
    }

    /// Position `p` as shown (snapshots, trajectories): wrapped into a box.
    fn shown(&self, p: Vector3<f64>) -> Vector3<f64> {
        p
    }

    // ----- the solid part ------------------------------------------------------------------

    /// Whether the boundary has a solid part that repels spheres and that they must not reach.
    fn solid(&self) -> bool {
        false
    }

    /// The no-slip plane wall, when the boundary is one (its settings, as saved and shown).
    fn wall(&self) -> Option<&Wall> {
        None
    }

    /// The height of the solid plane below the fluid (m), which heights are measured from.
    fn floor(&self) -> Option<f64> {
        None
    }

    /// The gap between the solid part and the surface of a sphere of radius `a` at `x` (m);
    /// infinite where nothing is solid.
    fn gap(&self, _x: &Vector3<f64>, _a: f64) -> f64 {
        f64::INFINITY
    }

    /// Whether spheres `(x, a)` all lie more than `margin` (m) clear of the solid part (the
    /// many draws of a random placement: no message).
    fn clear(&self, _spheres: &[(Vector3<f64>, f64)], _margin: f64) -> bool {
        true
    }

    /// Add the solid part's repulsion on each sphere to `forces`; `false` (nothing added) where
    /// nothing is solid.
    fn add_forces(
        &self,
        _pos: &[Vector3<f64>],
        _radii: &[f64],
        _forces: &mut [Vector3<f64>],
    ) -> bool {
        false
    }

    /// The runs' guard: the sphere closest to the solid part if it touches it (gap ≤ 0), as the
    /// problem to report, naming it by `owner` (sphere index → its swimmer and its number in
    /// the swimmer, from 1); `None` where nothing is solid or nothing touches.
    fn touching(
        &self,
        _pos: &[Vector3<f64>],
        _radii: &[f64],
        _owner: &dyn Fn(usize) -> (usize, usize),
    ) -> Option<Problem> {
        None
    }

    /// Sphere `sphere` (1 or 2) of a swimmer being placed, radius `a` at `x`: the error if it
    /// would not lie more than `margin` (m) clear of the solid part.
    fn check_placed(&self, _sphere: usize, _x: &Vector3<f64>, _a: f64, _margin: f64) -> Result<()> {
        Ok(())
    }

    /// Sphere `sphere` (1 or 2) of swimmer `swimmer`, radius `a` at `x`, where the scene holds
    /// it: the error if it is not clear of the solid part (the boundary set, a phase changed, a
    /// file loaded).
    fn check_present(
        &self,
        _swimmer: usize,
        _sphere: usize,
        _x: &Vector3<f64>,
        _a: f64,
    ) -> Result<()> {
        Ok(())
    }

    // ----- what fits, and how far it reaches -----------------------------------------------

    /// Swimmer `d` fits: in a box it must never meet its own image.
    fn check_fits(&self, _d: &Dumbbell) -> Result<()> {
        Ok(())
    }

    /// A repeating cell within `extent`: a box side longer cannot carry the spheres across it.
    /// Asked where the cell or a swimmer comes, and on load.
    fn check_cell(&self, _extent: &Extent) -> Result<()> {
        Ok(())
    }

    /// A solid part within `extent`: a wall far beyond overflows its mobility. Asked where the
    /// boundary comes, on load, and where every run starts (swimmers added later may shrink
    /// the extent).
    fn check_reach(&self, _extent: &Extent) -> Result<()> {
        Ok(())
    }

    // ----- its fluid -------------------------------------------------------------------------

    /// The mobility operator of spheres in this boundary's fluid.
    fn mobility(&self, settings: &MobilitySettings) -> Result<Box<dyn MobilityOperator>>;

    /// What of this boundary the device kernels lack, in words for "… runs on the CPU only";
    /// `None` where the device runs it.
    fn off_device(&self) -> Option<&'static str> {
        None
    }
}
