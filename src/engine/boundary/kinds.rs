//! The boundary as one value: [`Boundary`], the one match on its kind ([`Boundary::geometry`]),
//! and the rule of which kinds exclude each other.

use super::geometry::Geometry;
use super::open::OpenFluid;
use crate::engine::error::{invalid, unsupported, Result, Setting};
use crate::engine::periodic::PeriodicBox;
use crate::engine::wall::Wall;

/// Open space's geometry, shared by every open boundary.
static OPEN: OpenFluid = OpenFluid;

/// The boundary of a scene's fluid.
///
/// One kind at a time: a box and a wall exclude each other, since the wall's mobility has no
/// periodic images ([`Boundary::check_replace`], the rule written once). Room is left for more
/// kinds, each one arm here and one file beside this one: a slit between two walls (gaps and
/// repulsion from both planes, its own mobility), or a wall in a box periodic along the wall's
/// plane (minimum images in x and y, the wall's image system summed over the periodic images).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Boundary {
    /// The unbounded fluid.
    #[default]
    Open,
    /// A periodic box centred on the origin.
    Periodic(PeriodicBox),
    /// A no-slip plane wall below the fluid.
    Wall(Wall),
}

/// A boundary's kind, without its settings: what a setter brings, for the rule of which kinds
/// exclude each other.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Open space.
    Open,
    /// A periodic box.
    Periodic,
    /// A plane wall.
    Wall,
}

impl Boundary {
    /// What the boundary means for the spheres: the one match on its kind.
    pub fn geometry(&self) -> &dyn Geometry {
        match self {
            Boundary::Open => &OPEN,
            Boundary::Periodic(b) => b,
            Boundary::Wall(w) => w,
        }
    }

    /// The kind, without its settings.
    pub fn kind(&self) -> Kind {
        match self {
            Boundary::Open => Kind::Open,
            Boundary::Periodic(_) => Kind::Periodic,
            Boundary::Wall(_) => Kind::Wall,
        }
    }

    /// The periodic box, if the boundary is one.
    pub fn periodic(&self) -> Option<&PeriodicBox> {
        self.geometry().periodic()
    }

    /// The plane wall, if the boundary is one.
    pub fn wall(&self) -> Option<&Wall> {
        self.geometry().wall()
    }

    /// Whether a boundary of kind `new` may take this one's place, or the error saying why not:
    /// a box and a wall exclude each other (the wall's mobility has no periodic images), so one
    /// is taken away before the other comes.
    pub fn check_replace(&self, new: Kind) -> Result<()> {
        match (self.kind(), new) {
            (Kind::Wall, Kind::Periodic) => Err(unsupported(
                "a periodic box together with a wall is not available (the wall's mobility has no periodic images); remove the wall first",
                &[Setting::NoWall],
            )),
            (Kind::Periodic, Kind::Wall) => Err(unsupported(
                "a wall in a periodic box is not available (the wall's mobility has no periodic images); leave the box first",
                &[Setting::NoBox],
            )),
            _ => Ok(()),
        }
    }

    /// This boundary with the part of kind `kind` taken away (open space in its place); a
    /// boundary of another kind stays.
    pub fn without(self, kind: Kind) -> Self {
        if self.kind() == kind {
            Boundary::Open
        } else {
            self
        }
    }

    /// The boundary a scene file gives by its "box" and "wall" entries, each saved only when
    /// set; both at once are refused by the same rule as [`Boundary::check_replace`].
    pub fn from_saved(periodic: Option<PeriodicBox>, wall: Option<Wall>) -> Result<Self> {
        match (periodic, wall) {
            (Some(_), Some(_)) => Err(invalid!(
                "the scene file has both a wall and a periodic box, which cannot go together; remove one"
            )),
            (Some(b), None) => Ok(Boundary::Periodic(b)),
            (None, Some(w)) => Ok(Boundary::Wall(w)),
            (None, None) => Ok(Boundary::Open),
        }
    }
}
