//! The averaged system's arrays: centres and orientations as structure of arrays, each slot's
//! constants and the neighbour list with the arrays in its slot order. Data only, so that the
//! system and the row kernels that fill and read them import it one way.

use crate::engine::neighbours::NeighbourList;
use nalgebra::Vector3;

/// Centres and orientations as structure of arrays, refilled at every right-hand side.
#[derive(Debug, Clone, Default)]
pub(super) struct Soa {
    pub(super) x: Vec<f64>,
    pub(super) y: Vec<f64>,
    pub(super) z: Vec<f64>,
    pub(super) nx: Vec<f64>,
    pub(super) ny: Vec<f64>,
    pub(super) nz: Vec<f64>,
}

/// A swimmer's constants, kept by slot so that a pass in slot order reads them in order.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct SlotConst {
    /// The far rows' prefactors ([`super::lanes::prefactors`]).
    pub(super) pre: [f64; 4],
    /// Its length ℓ (m).
    pub(super) ell: f64,
    /// Its spheres' weights (w1, w2): the spheres sit at −w2ℓN and +w1ℓN from its centre.
    pub(super) w: (f64, f64),
    /// Its sphere radii (m).
    pub(super) a: [f64; 2],
}

/// The list and the arrays in its slot order.
#[derive(Debug, Clone, Default)]
pub(super) struct Listed {
    pub(super) list: Option<NeighbourList>,
    /// Positions and orientations by slot (swimmers, ghosts, the pad).
    pub(super) slots: Soa,
    /// Constants by slot (swimmers, ghosts, the pad), for the list built `consts_of`-th.
    pub(super) consts: Vec<SlotConst>,
    pub(super) consts_of: Option<u64>,
    /// Scratch: rates by slot.
    pub(super) rates: Vec<[f64; 6]>,
    /// Scratch: steric forces on each slot's two spheres.
    pub(super) forces: Vec<[Vector3<f64>; 2]>,
    pub(super) builds: u64,
}

impl Listed {
    /// Lists built so far.
    pub(super) fn builds(&self) -> u64 {
        self.builds
    }

    /// Swimmers relisted so far (in the list in use).
    pub(super) fn relists(&self) -> u64 {
        self.list.as_ref().map_or(0, |l| l.relists)
    }
}
