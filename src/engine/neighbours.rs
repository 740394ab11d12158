//! Verlet neighbour lists of swimmer centres: each swimmer's partners within a list radius (the
//! interaction's cutoff plus a skin), kept until some centre has moved more than half the skin
//! since the build, so that no pair within the cutoff can be missing from them.
//!
//! The list also fixes a memory layout for the passes over it. Swimmers sit in *slots* ordered
//! cell by cell ([`super::cells::CellGrid`]), so the partners of one swimmer lie close together
//! in memory. In a periodic box every slot holds its swimmer's centre shifted by a lattice vector
//! that put it into the box at the build, and a partner met across a face is a *ghost* slot: the
//! partner's slot plus the box's lattice vector of that minimum image, fixed at the build. A pass
//! then reads plain differences of slot positions: no minimum image, no rounding, per pair.
//! While the list is valid (radius ≤ L/2 and no centre has moved half the skin) the image fixed at
//! the build is the minimum image of every pair within the cutoff.
//!
//! Two sets of rows are kept per slot: *far* rows (partners within the list radius whose pair
//! weight is not zero, each with that weight, padded to whole blocks of [`LANES`] with a pad slot
//! far away and weight 0) for the vector kernels, and *near* rows (every partner within a contact
//! reach plus the skin, whatever its weight) for steric forces and the contact guard. Rows list
//! partners in ascending slot order, so sums over them do not depend on the thread count.

use super::cells::CellGrid;
use super::periodic::{nearest_integer, PeriodicBox};
use super::simd::LANES;
use rayon::prelude::*;
use std::collections::HashMap;

/// What a list must hold: pairs within `cutoff` for the far rows, within `contact_reach` for
/// the near rows (0: none), both with `skin` in hand.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ListSpec {
    /// The interaction's cutoff (m).
    pub cutoff: f64,
    /// The centre distance within which two swimmers may touch (m); 0 when nothing needs it.
    pub contact_reach: f64,
    /// The skin (m): the list holds pairs within max(cutoff, contact_reach) + skin.
    pub skin: f64,
}

impl ListSpec {
    /// The list radius: the longer of the two reaches plus the skin.
    pub fn radius(&self) -> f64 {
        self.cutoff.max(self.contact_reach) + self.skin
    }

    /// The skin `wanted` (m), shortened so that the radius stays within half the box's shortest
    /// side (where a pair meets one image only); zero if the reaches leave no room.
    pub fn fitted_skin(
        cutoff: f64,
        contact_reach: f64,
        wanted: f64,
        b: Option<&PeriodicBox>,
    ) -> f64 {
        let room = b.map_or(f64::INFINITY, |b| {
            0.5 * b.shortest() - cutoff.max(contact_reach)
        });
        wanted.min(room).max(0.0)
    }
}

/// A Verlet list of swimmer centres (see the module docs).
#[derive(Debug, Clone)]
pub struct NeighbourList {
    spec: ListSpec,
    /// Centres (unwrapped) at the build.
    built: Vec<[f64; 3]>,
    /// Slot k < n holds swimmer `order[k]`.
    pub order: Vec<u32>,
    /// Per swimmer, the lattice vector that moved its centre into the box at the build (0 in
    /// open space): its slot position is its centre plus this.
    pub offset: Vec<[f64; 3]>,
    /// Ghost slots n, n+1, …: (the slot they copy, the lattice vector added to it).
    pub ghosts: Vec<(u32, [f64; 3])>,
    /// Far rows of slot k: `far_partner[far_start[k]..far_start[k + 1]]`, whole blocks of LANES.
    pub far_start: Vec<u32>,
    /// Partner slots (the pad slot, [`NeighbourList::pad_slot`], fills the last block).
    pub far_partner: Vec<u32>,
    /// Each far entry's pair weight (0 for the pad).
    pub far_weight: Vec<f64>,
    /// Near rows of slot k: `near_partner[near_start[k]..near_start[k + 1]]`.
    pub near_start: Vec<u32>,
    /// Partner slots within the contact reach plus the skin.
    pub near_partner: Vec<u32>,
    /// Times this list was built (a rebuild counts).
    pub builds: u64,
}

/// One partner found at a build: its slot, the image (lattice steps per axis) it is met at, its
/// weight (`None`: not in the far rows), and whether it is near.
type Found = (u32, [i8; 3], Option<f64>, bool);

impl NeighbourList {
    /// A list of the centres (`x`, `y`, `z`: unwrapped, swimmer order) in periodic box
    /// `periodic`, if any. `weight(i, j)` is the far-row weight of the pair (swimmer indices),
    /// `None` to leave it out of the far rows.
    pub fn build(
        x: &[f64],
        y: &[f64],
        z: &[f64],
        periodic: Option<&PeriodicBox>,
        spec: ListSpec,
        weight: &(dyn Fn(usize, usize) -> Option<f64> + Sync),
    ) -> Self {
        let n = x.len();
        let centres: Vec<[f64; 3]> = (0..n).map(|s| [x[s], y[s], z[s]]).collect();
        let offset: Vec<[f64; 3]> = centres
            .iter()
            .map(|c| match periodic {
                Some(b) => {
                    let w = b.wrap(nalgebra::Vector3::from(*c));
                    [w.x - c[0], w.y - c[1], w.z - c[2]]
                }
                None => [0.0; 3],
            })
            .collect();
        let at = |s: usize, d: usize| centres[s][d] + offset[s][d];
        let coords = |d: usize| -> Vec<f64> { (0..n).map(|s| at(s, d)).collect() };
        let radius = spec.radius();
        // Cells at least as wide as the radius: every partner is among the 27 cells around.
        let cell = if radius > 0.0 && radius.is_finite() {
            radius
        } else {
            1.0
        };
        let grid = CellGrid::build_in(&coords(0), &coords(1), &coords(2), cell, periodic);
        let order = grid.order.clone();
        let mut slot_of = vec![0u32; n];
        for (k, &s) in order.iter().enumerate() {
            slot_of[s as usize] = k as u32;
        }
        let sides = periodic.map(|b| b.sides());
        let r2 = radius * radius;
        let near2 = (spec.contact_reach + spec.skin).powi(2);
        let with_near = spec.contact_reach > 0.0;
        let find = |k: usize| -> Vec<Found> {
            let i = order[k] as usize;
            let mut runs = Vec::with_capacity(27);
            grid.neighbour_runs(at(i, 0), at(i, 1), at(i, 2), &mut runs);
            let mut found: Vec<Found> = Vec::new();
            for (a, b) in runs {
                for slot in a..b {
                    let j = order[slot as usize] as usize;
                    if j == i {
                        continue;
                    }
                    let mut image = [0i8; 3];
                    let mut d2 = 0.0;
                    for (dim, m) in image.iter_mut().enumerate() {
                        let mut d = at(i, dim) - at(j, dim);
                        if let Some(l) = sides {
                            // Slot positions lie in the box: the nearest image is 0 or ±1 away.
                            let steps = nearest_integer(d / l[dim]);
                            *m = steps as i8;
                            d -= steps * l[dim];
                        }
                        d2 += d * d;
                    }
                    if d2 > r2 {
                        continue;
                    }
                    let w = weight(i, j);
                    let near = with_near && d2 <= near2;
                    if w.is_some() || near {
                        found.push((slot, image, w, near));
                    }
                }
            }
            found.sort_unstable_by_key(|f| (f.0, f.1));
            found
        };
        let rows: Vec<Vec<Found>> = if n >= super::averaged::PARALLEL_SWIMMERS {
            (0..n).into_par_iter().map(find).collect()
        } else {
            (0..n).map(find).collect()
        };
        // Ghost slots in the order rows first meet them: the list depends on the centres only.
        let mut ghosts: Vec<(u32, [f64; 3])> = Vec::new();
        let mut ghost_of: HashMap<(u32, [i8; 3]), u32> = HashMap::new();
        let mut slot_for = |slot: u32, image: [i8; 3]| -> u32 {
            if image == [0; 3] {
                return slot;
            }
            *ghost_of.entry((slot, image)).or_insert_with(|| {
                let l = sides.unwrap_or([0.0; 3]);
                // The row meets the partner at its slot position plus `image` lattice steps.
                let shift = [0, 1, 2].map(|d| f64::from(image[d]) * l[d]);
                ghosts.push((slot, shift));
                (n + ghosts.len() - 1) as u32
            })
        };
        let mut far_start = Vec::with_capacity(n + 1);
        let mut near_start = Vec::with_capacity(n + 1);
        let total: usize = rows.iter().map(Vec::len).sum();
        let mut far_partner = Vec::with_capacity(total + LANES * n);
        let mut far_weight = Vec::with_capacity(total + LANES * n);
        let mut near_partner = Vec::new();
        let mut pads = Vec::new();
        for row in &rows {
            far_start.push(far_partner.len() as u32);
            near_start.push(near_partner.len() as u32);
            for &(slot, image, w, near) in row {
                let s = slot_for(slot, image);
                if let Some(w) = w {
                    far_partner.push(s);
                    far_weight.push(w);
                }
                if near {
                    near_partner.push(s);
                }
            }
            while !(far_partner.len() - *far_start.last().unwrap_or(&0) as usize)
                .is_multiple_of(LANES)
            {
                pads.push(far_partner.len());
                far_partner.push(0);
                far_weight.push(0.0);
            }
        }
        far_start.push(far_partner.len() as u32);
        near_start.push(near_partner.len() as u32);
        let pad = (n + ghosts.len()) as u32;
        for p in pads {
            far_partner[p] = pad;
        }
        NeighbourList {
            spec,
            built: centres,
            order,
            offset,
            ghosts,
            far_start,
            far_partner,
            far_weight,
            near_start,
            near_partner,
            builds: 1,
        }
    }

    /// The spec the list was built for.
    pub fn spec(&self) -> ListSpec {
        self.spec
    }

    /// Swimmers in the list.
    pub fn len(&self) -> usize {
        self.order.len()
    }

    /// Whether it holds no swimmer.
    pub fn is_empty(&self) -> bool {
        self.order.is_empty()
    }

    /// Slots in all: swimmers, ghosts, and the pad.
    pub fn slots(&self) -> usize {
        self.order.len() + self.ghosts.len() + 1
    }

    /// The pad slot: far away from every swimmer, weight 0 in every row it fills.
    pub fn pad_slot(&self) -> usize {
        self.slots() - 1
    }

    /// Far entries in all (pads included).
    pub fn far_entries(&self) -> usize {
        self.far_partner.len()
    }

    /// Whether the list still holds every pair for the centres `x`, `y`, `z` (unwrapped, swimmer
    /// order): no centre has moved more than half the skin since the build (with no skin, none
    /// has moved at all).
    pub fn is_valid_for(&self, x: &[f64], y: &[f64], z: &[f64]) -> bool {
        if x.len() != self.built.len() {
            return false;
        }
        let limit = 0.25 * self.spec.skin * self.spec.skin;
        self.built.iter().enumerate().all(|(s, b)| {
            let d2 = (x[s] - b[0]).powi(2) + (y[s] - b[1]).powi(2) + (z[s] - b[2]).powi(2);
            d2 <= limit
        })
    }

    /// Fill `out` (each resized to [`NeighbourList::slots`]) with the slot positions of the centres
    /// `x`, `y`, `z` (unwrapped, swimmer order): swimmers, ghosts, and the pad far away.
    pub fn fill_positions(&self, centres: [&[f64]; 3], out: [&mut Vec<f64>; 3]) {
        let mut out = out;
        for (d, v) in out.iter_mut().enumerate() {
            v.clear();
            v.extend(self.order.iter().map(|&s| {
                let s = s as usize;
                centres[d][s] + self.offset[s][d]
            }));
        }
        for &(slot, shift) in &self.ghosts {
            for (d, v) in out.iter_mut().enumerate() {
                let p = v[slot as usize] + shift[d];
                v.push(p);
            }
        }
        for v in out.iter_mut() {
            v.push(PAD_POSITION);
        }
    }

    /// Fill `v` (resized to [`NeighbourList::slots`]) with per-swimmer values in slot order: a
    /// ghost takes its swimmer's value, the pad `pad`.
    pub fn fill_values<T: Copy>(&self, of: impl Fn(usize) -> T, pad: T, v: &mut Vec<T>) {
        v.clear();
        v.extend(self.order.iter().map(|&s| of(s as usize)));
        for &(slot, _) in &self.ghosts {
            let x = v[slot as usize];
            v.push(x);
        }
        v.push(pad);
    }

    /// The swimmer in slot `slot` (a ghost's is its original's).
    pub fn swimmer_of(&self, slot: usize) -> usize {
        let n = self.order.len();
        let slot = if slot >= n && slot < n + self.ghosts.len() {
            self.ghosts[slot - n].0 as usize
        } else {
            slot
        };
        self.order[slot] as usize
    }
}

/// Where the pad slot sits (m): its squared distance from any swimmer overflows to infinity, so
/// every cutoff test leaves it out.
pub const PAD_POSITION: f64 = 1e300;
