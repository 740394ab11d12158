//! Verlet neighbour lists of swimmer centres: each swimmer's partners within a list radius (the
//! interaction's cutoff plus a skin) of its *reference* centre, no pair within the cutoff missing
//! while no centre has moved more than half the skin from its reference. Each swimmer keeps its
//! own reference: one that moved further is *relisted* alone ([`NeighbourList::relist`]: its
//! reference set to where it is, its row found anew, itself entered in its new partners' rows),
//! so a few fast swimmers (a contact, a close pair) do not cost a rebuild of everyone's rows.
//! The invariant: a pair is missing only if its reference centres are further apart than the
//! radius; then its centres are further apart than the cutoff.
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
//! partners in ascending slot order (the pads last), so sums over them do not depend on the
//! thread count. A relisted swimmer leaves stale entries nowhere: its old partners' entries for
//! it are taken out before its new ones go in.

use super::cells::{CellGrid, CellMap};
use super::periodic::{nearest_integer, PeriodicBox};
use super::simd::LANES;

/// Rows of at least this many swimmers are found on rayon's threads.
pub const PARALLEL_ROWS: usize = 256;
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
    /// The box's sides, in a box.
    sides: Option<[f64; 3]>,
    /// Each swimmer's reference centre (unwrapped).
    built: Vec<[f64; 3]>,
    /// Slot k < n holds swimmer `order[k]`; slot n is the pad; ghosts follow.
    pub order: Vec<u32>,
    /// Each swimmer's slot.
    pub slot_of: Vec<u32>,
    /// Per swimmer, the lattice vector that moved its centre into the box at the build (0 in
    /// open space): its slot position is its centre plus this.
    offset: Vec<[f64; 3]>,
    /// Ghost slots n + 1, n + 2, …: (the slot they copy, the lattice vector added to it).
    ghosts: Vec<(u32, [f64; 3])>,
    /// The ghost slot of (slot, image in lattice steps).
    ghost_of: HashMap<(u32, [i8; 3]), u32>,
    /// Each swimmer's ghost slots.
    ghosts_by_swimmer: Vec<Vec<u32>>,
    /// Far rows by slot: partner slots (whole blocks of LANES, the pad last) and their weights.
    far: Vec<(Vec<u32>, Vec<f64>)>,
    /// Near rows by slot: partner slots.
    near: Vec<Vec<u32>>,
    /// The reference slot positions (reference centre plus offset), binned by the radius.
    cells: CellMap,
    /// Swimmers relisted so far.
    pub relists: u64,
}

/// One partner found: its swimmer, the image (lattice steps per axis) it is met at, its weight
/// (`None`: not in the far rows), and whether it is near.
type Found = (u32, [i8; 3], Option<f64>, bool);

/// The pair weight of swimmers (i, j): `None` leaves the pair out of the far rows.
pub type Weight<'a> = &'a (dyn Fn(usize, usize) -> Option<f64> + Sync);

impl NeighbourList {
    /// A list of the centres (`x`, `y`, `z`: unwrapped, swimmer order) in periodic box
    /// `periodic`, if any, every reference where its centre is.
    pub fn build(
        x: &[f64],
        y: &[f64],
        z: &[f64],
        periodic: Option<&PeriodicBox>,
        spec: ListSpec,
        weight: Weight,
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
        let cell = if radius > 0.0 && radius.is_finite() {
            radius
        } else {
            1.0
        };
        let order = CellGrid::build_in(&coords(0), &coords(1), &coords(2), cell, periodic).order;
        let mut slot_of = vec![0u32; n];
        for (k, &s) in order.iter().enumerate() {
            slot_of[s as usize] = k as u32;
        }
        let mut cells = CellMap::new(cell, periodic);
        for s in 0..n {
            cells.insert(at(s, 0), at(s, 1), at(s, 2), s as u32);
        }
        let mut list = NeighbourList {
            spec,
            sides: periodic.map(|b| b.sides()),
            built: centres,
            order,
            slot_of,
            offset,
            ghosts: Vec::new(),
            ghost_of: HashMap::new(),
            ghosts_by_swimmer: vec![Vec::new(); n],
            far: vec![(Vec::new(), Vec::new()); n],
            near: vec![Vec::new(); n],
            cells,
            relists: 0,
        };
        let find = |k: usize| list.find(list.order[k] as usize, weight);
        let rows: Vec<Vec<Found>> = if n >= PARALLEL_ROWS {
            (0..n).into_par_iter().map(find).collect()
        } else {
            (0..n).map(find).collect()
        };
        for (k, row) in rows.into_iter().enumerate() {
            list.set_row(k, row);
        }
        list
    }

    /// The reference slot position of swimmer `s` along axis `d`.
    fn reference(&self, s: usize, d: usize) -> f64 {
        self.built[s][d] + self.offset[s][d]
    }

    /// Swimmer `s`'s partners by the references: every swimmer within the radius, at the image
    /// it is met at, in ascending (swimmer, image) order.
    fn find(&self, s: usize, weight: Weight) -> Vec<Found> {
        let r2 = self.spec.radius().powi(2);
        let near2 = (self.spec.contact_reach + self.spec.skin).powi(2);
        let with_near = self.spec.contact_reach > 0.0;
        let p = [0, 1, 2].map(|d| self.reference(s, d));
        let mut found: Vec<Found> = Vec::new();
        self.cells.near(p[0], p[1], p[2], |j, q| {
            let j = j as usize;
            if j == s {
                return true;
            }
            let mut image = [0i8; 3];
            let mut d2 = 0.0;
            for (d, m) in image.iter_mut().enumerate() {
                // q is j's reference slot position, as inserted.
                let mut x = p[d] - q[d];
                if let Some(l) = self.sides {
                    let steps = nearest_integer(x / l[d]);
                    *m = steps as i8;
                    x -= steps * l[d];
                }
                d2 += x * x;
            }
            if d2 <= r2 {
                let w = weight(s, j);
                let near = with_near && d2 <= near2;
                if w.is_some() || near {
                    found.push((j as u32, image, w, near));
                }
            }
            true
        });
        found.sort_unstable_by_key(|f| (f.0, f.1));
        found
    }

    /// The slot where a row meets swimmer `j` at `image`: its own, or a ghost (made if new).
    fn slot_for(&mut self, j: u32, image: [i8; 3]) -> u32 {
        let slot = self.slot_of[j as usize];
        if image == [0; 3] {
            return slot;
        }
        if let Some(&g) = self.ghost_of.get(&(slot, image)) {
            return g;
        }
        let l = self.sides.unwrap_or([0.0; 3]);
        let shift = [0, 1, 2].map(|d| f64::from(image[d]) * l[d]);
        let g = (self.order.len() + 1 + self.ghosts.len()) as u32;
        self.ghosts.push((slot, shift));
        self.ghost_of.insert((slot, image), g);
        self.ghosts_by_swimmer[j as usize].push(g);
        g
    }

    /// Row `k`'s far and near entries from `found`, in ascending slot order, the far ones padded.
    fn set_row(&mut self, k: usize, found: Vec<Found>) {
        let mut far: Vec<(u32, f64)> = Vec::new();
        let mut near: Vec<u32> = Vec::new();
        for (j, image, w, is_near) in found {
            let slot = self.slot_for(j, image);
            if let Some(w) = w {
                far.push((slot, w));
            }
            if is_near {
                near.push(slot);
            }
        }
        far.sort_unstable_by_key(|e| e.0);
        near.sort_unstable();
        let row = &mut self.far[k];
        row.0 = far.iter().map(|e| e.0).collect();
        row.1 = far.iter().map(|e| e.1).collect();
        pad(row, self.order.len() as u32);
        self.near[k] = near;
    }

    /// Relist swimmer `s`, now at `c` (unwrapped): its reference set there, its entries taken out
    /// of its old partners' rows, its row found anew, and itself entered in its new partners'
    /// rows. Returns whether ghost slots were added (the slot arrays then lack their entries:
    /// [`NeighbourList::extend_positions`], [`NeighbourList::extend_values`]).
    pub fn relist(&mut self, s: usize, c: [f64; 3], weight: Weight) -> bool {
        let ghosts_before = self.ghosts.len();
        let k = self.slot_of[s] as usize;
        let p = [0, 1, 2].map(|d| self.reference(s, d));
        self.cells.remove(p[0], p[1], p[2], s as u32);
        // Its old partners' entries for it (its slot or a ghost of it) go.
        let own: Vec<u32> = std::iter::once(k as u32)
            .chain(self.ghosts_by_swimmer[s].iter().copied())
            .collect();
        let old: Vec<usize> = self.far[k]
            .0
            .iter()
            .chain(&self.near[k])
            .filter(|&&q| (q as usize) != self.order.len())
            .map(|&q| self.swimmer_of(q as usize))
            .collect();
        let pad_slot = self.order.len() as u32;
        for j in old {
            let kj = self.slot_of[j] as usize;
            let row = &mut self.far[kj];
            unpad(row, pad_slot);
            let mut i = 0;
            while i < row.0.len() {
                if own.contains(&row.0[i]) {
                    row.0.remove(i);
                    row.1.remove(i);
                } else {
                    i += 1;
                }
            }
            pad(row, pad_slot);
            self.near[kj].retain(|q| !own.contains(q));
        }
        self.built[s] = c;
        let p = [0, 1, 2].map(|d| self.reference(s, d));
        self.cells.insert(p[0], p[1], p[2], s as u32);
        let found = self.find(s, weight);
        // Each new partner j meets s at the opposite image.
        let back: Vec<(usize, [i8; 3], Option<f64>, bool)> = found
            .iter()
            .map(|&(j, image, _, near)| {
                let j = j as usize;
                (j, image.map(|m| -m), weight(j, s), near)
            })
            .collect();
        self.set_row(k, found);
        for (j, image, w, near) in back {
            let slot = self.slot_for(s as u32, image);
            let kj = self.slot_of[j] as usize;
            if let Some(w) = w {
                let row = &mut self.far[kj];
                unpad(row, pad_slot);
                let at = row.0.partition_point(|&q| q < slot);
                row.0.insert(at, slot);
                row.1.insert(at, w);
                pad(row, pad_slot);
            }
            if near {
                let row = &mut self.near[kj];
                let at = row.partition_point(|&q| q < slot);
                row.insert(at, slot);
            }
        }
        self.relists += 1;
        self.ghosts.len() > ghosts_before
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

    /// Slots in all: swimmers, the pad, and ghosts.
    pub fn slots(&self) -> usize {
        self.order.len() + 1 + self.ghosts.len()
    }

    /// The pad slot: far away from every swimmer, weight 0 in every row it fills.
    pub fn pad_slot(&self) -> usize {
        self.order.len()
    }

    /// Slot `k`'s far row: partner slots (whole blocks of LANES) and their weights.
    pub fn far_row(&self, k: usize) -> (&[u32], &[f64]) {
        let (p, w) = &self.far[k];
        (p, w)
    }

    /// Slot `k`'s near row: partner slots.
    pub fn near_row(&self, k: usize) -> &[u32] {
        &self.near[k]
    }

    /// Far entries in all (pads included).
    pub fn far_entries(&self) -> usize {
        self.far.iter().map(|r| r.0.len()).sum()
    }

    /// The swimmers whose centres (`x`, `y`, `z`: unwrapped, swimmer order) have moved more than
    /// half the skin from their references (with no skin, at all).
    pub fn moved(&self, x: &[f64], y: &[f64], z: &[f64]) -> Vec<usize> {
        (0..self.built.len())
            .filter(|&s| !self.holds(s, x[s], y[s], z[s]))
            .collect()
    }

    /// Whether swimmer `s` at (x, y, z) is still within half the skin of its reference.
    pub fn holds(&self, s: usize, x: f64, y: f64, z: f64) -> bool {
        let b = self.built[s];
        (x - b[0]).powi(2) + (y - b[1]).powi(2) + (z - b[2]).powi(2)
            <= 0.25 * self.spec.skin * self.spec.skin
    }

    /// Fill `out` (each resized to [`NeighbourList::slots`]) with the slot positions of the centres
    /// `x`, `y`, `z` (unwrapped, swimmer order): swimmers, the pad far away, ghosts.
    pub fn fill_positions(&self, centres: [&[f64]; 3], mut out: [&mut Vec<f64>; 3]) {
        for (d, v) in out.iter_mut().enumerate() {
            v.clear();
            v.extend(self.order.iter().map(|&s| {
                let s = s as usize;
                centres[d][s] + self.offset[s][d]
            }));
            v.push(PAD_POSITION);
        }
        self.extend_positions(out);
    }

    /// Append to `out` (filled by [`NeighbourList::fill_positions`] before ghost slots were
    /// added) the positions of the ghost slots they lack, from the slots they copy.
    pub fn extend_positions(&self, out: [&mut Vec<f64>; 3]) {
        let first = self.order.len() + 1;
        for (d, v) in out.into_iter().enumerate() {
            for g in v.len().max(first)..self.slots() {
                let (slot, shift) = self.ghosts[g - first];
                let p = v[slot as usize] + shift[d];
                v.push(p);
            }
        }
    }

    /// Fill `v` (resized to [`NeighbourList::slots`]) with per-swimmer values in slot order: the
    /// pad `pad`, a ghost its swimmer's value.
    pub fn fill_values<T: Copy>(&self, of: impl Fn(usize) -> T, pad: T, v: &mut Vec<T>) {
        v.clear();
        v.extend(self.order.iter().map(|&s| of(s as usize)));
        v.push(pad);
        self.extend_values(v);
    }

    /// Append to `v` (filled by [`NeighbourList::fill_values`] before ghost slots were added) the
    /// values of the ghost slots it lacks, their swimmers'.
    pub fn extend_values<T: Copy>(&self, v: &mut Vec<T>) {
        let first = self.order.len() + 1;
        for g in v.len().max(first)..self.slots() {
            let x = v[self.ghosts[g - first].0 as usize];
            v.push(x);
        }
    }

    /// Set swimmer `s`'s entries of the slot arrays `out` (filled by
    /// [`NeighbourList::fill_positions`]) from its centre `c` (unwrapped): its slot and its ghosts.
    pub fn set_position(&self, s: usize, c: [f64; 3], out: [&mut [f64]; 3]) {
        let slot = self.slot_of[s] as usize;
        for (d, v) in out.into_iter().enumerate() {
            let p = c[d] + self.offset[s][d];
            v[slot] = p;
            for &g in &self.ghosts_by_swimmer[s] {
                v[g as usize] = p + self.ghosts[g as usize - self.order.len() - 1].1[d];
            }
        }
    }

    /// Set swimmer `s`'s value `x` in per-slot values `v` (filled by
    /// [`NeighbourList::fill_values`]): its slot and its ghosts.
    pub fn set_value<T: Copy>(&self, s: usize, x: T, v: &mut [T]) {
        v[self.slot_of[s] as usize] = x;
        for &g in &self.ghosts_by_swimmer[s] {
            v[g as usize] = x;
        }
    }

    /// The swimmer in slot `slot` (a ghost's is its original's; not the pad).
    pub fn swimmer_of(&self, slot: usize) -> usize {
        let n = self.order.len();
        let slot = if slot > n {
            self.ghosts[slot - n - 1].0 as usize
        } else {
            slot
        };
        self.order[slot] as usize
    }
}

/// Take a far row's trailing pad entries off (the pad slot sorts before ghost slots, so the
/// row's real entries are those before its trailing pads).
fn unpad(row: &mut (Vec<u32>, Vec<f64>), pad_slot: u32) {
    while row.0.last() == Some(&pad_slot) {
        row.0.pop();
        row.1.pop();
    }
}

/// Fill a far row up to whole blocks of LANES with the pad slot, weight 0.
fn pad(row: &mut (Vec<u32>, Vec<f64>), pad_slot: u32) {
    while !row.0.len().is_multiple_of(LANES) {
        row.0.push(pad_slot);
        row.1.push(0.0);
    }
}

/// Where the pad slot sits (m): further from any swimmer than any cutoff, with a squared distance
/// that stays finite (≈ 1e300).
pub const PAD_POSITION: f64 = 1e150;
