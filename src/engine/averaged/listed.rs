//! The averaged system's neighbour lists ([`crate::engine::neighbours`]): kept valid as the
//! centres move (rebuilt once a centre has moved half the skin), their slot arrays refilled at
//! every right-hand side, and the steric forces and the contact guard through their near rows.

use super::arrays::{SlotConst, Soa};
use super::list_rows;
use super::system::{AveragedSystem, DEFAULT_SKIN_OF_CUTOFF, LIST_SWIMMERS, PARALLEL_SWIMMERS};
use super::terms::pair_weight;
use crate::engine::contacts::Steric;
use crate::engine::integrators::Problem;
use crate::engine::model::STATE_PER_SWIMMER;
use crate::engine::neighbours::{ListSpec, NeighbourList};
use nalgebra::Vector3;
use rayon::prelude::*;

/// Above this share of swimmers leaving their lists at once, the whole list is built anew
/// instead of relisting them one by one.
pub const MAX_RELISTED_FRACTION: f64 = 0.1;

impl AveragedSystem {
    /// Whether the cutoff's pairs are summed over neighbour lists.
    pub(super) fn uses_lists(&self) -> bool {
        self.axis.is_none()
            && self.cutoff2.is_finite()
            && self.lists.unwrap_or(self.coef.len() >= LIST_SWIMMERS)
    }

    /// The centre distance within which two swimmers' spheres (or rods) can touch or repel:
    /// each sphere lies within ℓ·max(w1, w2) of its centre.
    fn contact_reach(&self) -> f64 {
        let a_max = self.radii.iter().copied().fold(0.0, f64::max);
        let arm = self
            .coef
            .iter()
            .zip(&self.weights)
            .map(|(c, (w1, w2))| c.ell * w1.max(*w2))
            .fold(0.0, f64::max);
        let range = self.contacts.steric.map_or(0.0, |st| st.range);
        range + 2.0 * a_max + 2.0 * arm
    }

    fn list_spec(&self) -> ListSpec {
        let cutoff = self.cutoff2.sqrt();
        let reach = self.contact_reach();
        let wanted = self.skin.unwrap_or(DEFAULT_SKIN_OF_CUTOFF * cutoff);
        ListSpec {
            cutoff,
            contact_reach: reach,
            skin: ListSpec::fitted_skin(cutoff, reach, wanted, self.periodic.as_ref()),
        }
    }

    /// After `fill`: a list valid for the current centres (swimmers that moved half the skin
    /// from their references relisted, or everyone rebuilt when many did or the spec changed),
    /// and its slot arrays filled from the current state.
    pub(super) fn update_list(&mut self) {
        let spec = self.list_spec();
        let soa = &self.soa;
        let moved = match &self.listed.list {
            Some(l) if l.spec() == spec => Some(l.moved(&soa.x, &soa.y, &soa.z)),
            _ => None,
        };
        self.relist(moved);
        self.refill_slots();
    }

    /// Relist the swimmers `moved` (at their centres in the arrays), or rebuild the whole list
    /// when `None` or when more than [`MAX_RELISTED_FRACTION`] of the swimmers moved. Returns
    /// whether the list was rebuilt (the slot arrays then need refilling; after a relisting,
    /// only the ghost slots it added need filling).
    pub(super) fn relist(&mut self, moved: Option<Vec<usize>>) -> bool {
        let (sin, cos, skip) = (&self.sin_phi, &self.cos_phi, self.skip_zero_phase);
        let weight = |i: usize, j: usize| pair_weight(sin, cos, skip, i, j);
        let soa = &self.soa;
        let n = self.coef.len();
        match (moved, &mut self.listed.list) {
            (Some(m), Some(list)) if (m.len() as f64) <= MAX_RELISTED_FRACTION * n as f64 => {
                for s in m {
                    list.relist(s, [soa.x[s], soa.y[s], soa.z[s]], &weight);
                }
                false
            }
            _ => {
                let spec = self.list_spec();
                let soa = &self.soa;
                let list = NeighbourList::build(
                    &soa.x,
                    &soa.y,
                    &soa.z,
                    self.periodic.as_ref(),
                    spec,
                    &weight,
                );
                self.listed.list = Some(list);
                self.listed.builds += 1;
                true
            }
        }
    }

    /// Swimmer `s`'s constants.
    fn slot_const(&self, s: usize) -> SlotConst {
        let c = &self.coef[s];
        SlotConst {
            pre: super::lanes::prefactors(self, c),
            ell: c.ell,
            w: self.weights[s],
            a: [self.radii[2 * s], self.radii[2 * s + 1]],
        }
    }

    /// The constants by slot: all of them for a list built since they were filled, else those
    /// of ghost slots added since.
    fn refill_consts(&mut self) {
        let Some(list) = &self.listed.list else {
            return;
        };
        let mut consts = std::mem::take(&mut self.listed.consts);
        if self.listed.consts_of == Some(self.listed.builds) {
            list.extend_values(&mut consts);
        } else {
            list.fill_values(|s| self.slot_const(s), SlotConst::default(), &mut consts);
            self.listed.consts_of = Some(self.listed.builds);
        }
        self.listed.consts = consts;
    }

    /// The slot arrays from the arrays in state order.
    pub(super) fn refill_slots(&mut self) {
        self.refill_consts();
        let Some(list) = &self.listed.list else {
            return;
        };
        let (soa, slots) = (&self.soa, &mut self.listed.slots);
        list.fill_positions(
            [&soa.x, &soa.y, &soa.z],
            [&mut slots.x, &mut slots.y, &mut slots.z],
        );
        for (to, from) in [
            (&mut slots.nx, &soa.nx),
            (&mut slots.ny, &soa.ny),
            (&mut slots.nz, &soa.nz),
        ] {
            list.fill_values(|s| from[s], 0.0, to);
        }
    }

    /// The slot arrays' entries for ghost slots added since they were filled, from the slots
    /// they copy.
    pub(super) fn extend_slots(&mut self) {
        let Some(list) = &self.listed.list else {
            return;
        };
        let slots = &mut self.listed.slots;
        list.extend_positions([&mut slots.x, &mut slots.y, &mut slots.z]);
        for v in [&mut slots.nx, &mut slots.ny, &mut slots.nz] {
            list.extend_values(v);
        }
        self.refill_consts();
    }

    /// The neighbour list in use, if any.
    pub(super) fn listed_list(&self) -> Option<&NeighbourList> {
        self.listed.list.as_ref()
    }

    /// Swimmer `s`'s slot entries (its slot and ghosts) from its centre `c` and orientation `n`.
    pub(super) fn refresh_slots(&mut self, s: usize, c: [f64; 3], n: [f64; 3]) {
        let Some(list) = &self.listed.list else {
            return;
        };
        let slots = &mut self.listed.slots;
        list.set_position(s, c, [&mut slots.x, &mut slots.y, &mut slots.z]);
        list.set_value(s, n[0], &mut slots.nx);
        list.set_value(s, n[1], &mut slots.ny);
        list.set_value(s, n[2], &mut slots.nz);
    }

    /// The sphere centres of the swimmer in slot `k` (length ℓ, as [`AveragedSystem::fill`]).
    fn slot_spheres(&self, slots: &Soa, k: usize) -> [Vector3<f64>; 2] {
        let c = Vector3::new(slots.x[k], slots.y[k], slots.z[k]);
        let SlotConst {
            ell, w: (w1, w2), ..
        } = self.listed.consts[k];
        let b = Vector3::new(slots.nx[k], slots.ny[k], slots.nz[k]) * ell;
        [c - w2 * b, c + w1 * b]
    }

    /// The steric forces on every sphere (`steric_f`, swimmer order) from the near rows: each
    /// swimmer sums its partners in slot order, so the forces do not depend on the thread count.
    pub(super) fn steric_by_list(&mut self, st: Steric) {
        let Some(list) = &self.listed.list else {
            return;
        };
        let slots = &self.listed.slots;
        let mut forces = std::mem::take(&mut self.listed.forces);
        forces.resize(list.len(), [Vector3::zeros(); 2]);
        let one = |k: usize, f: &mut [Vector3<f64>; 2]| *f = self.slot_steric(st, list, slots, k);
        if list.len() >= PARALLEL_SWIMMERS {
            forces
                .par_iter_mut()
                .enumerate()
                .for_each(|(k, f)| one(k, f));
        } else {
            forces.iter_mut().enumerate().for_each(|(k, f)| one(k, f));
        }
        for (k, f) in forces.iter().enumerate() {
            let s = list.order[k] as usize;
            self.steric_f[2 * s] = f[0];
            self.steric_f[2 * s + 1] = f[1];
        }
        self.listed.forces = forces;
    }

    /// The steric forces on the spheres of the swimmer in slot `k` from its near partners.
    fn slot_steric(
        &self,
        st: Steric,
        list: &NeighbourList,
        slots: &Soa,
        k: usize,
    ) -> [Vector3<f64>; 2] {
        let consts = &self.listed.consts;
        let a = self.slot_spheres(slots, k);
        let ra = consts[k].a;
        let mut f = [Vector3::zeros(); 2];
        for &p in list.near_row(k) {
            let b = self.slot_spheres(slots, p as usize);
            let rb = consts[p as usize].a;
            let df = st.swimmer_pair_forces(a, ra, b, rb);
            f[0] += df[0];
            f[1] += df[1];
        }
        f
    }

    /// Fill `dy` from the far rows (and the steric rates), slot by slot in parallel.
    pub(super) fn rows_by_list(&mut self, dy: &mut [f64]) {
        let Some(list) = &self.listed.list else {
            return;
        };
        let slots = &self.listed.slots;
        let mut rates = std::mem::take(&mut self.listed.rates);
        rates.resize(list.len(), [0.0; 6]);
        let (consts, forces) = (&self.listed.consts, &self.listed.forces);
        let steric = self.contacts.steric.is_some();
        // The rates in slot order, from the slot arrays (equal to the state's entries) and the
        // steric forces by slot: dN/dt = −(1 − NNᵀ)T, plus the steric rates.
        let one = |k: usize, out: &mut [f64; 6]| {
            let (mut v, t) = list_rows::row(self, list, slots, consts, k);
            let n = Vector3::new(slots.nx[k], slots.ny[k], slots.nz[k]);
            let mut dn = -(t - n * n.dot(&t));
            if steric {
                let c = consts[k];
                let (vs, ns) = self.steric_rates_with(c.a, c.ell, n, forces[k]);
                v += vs;
                dn += ns;
            }
            out[..3].copy_from_slice(v.as_slice());
            out[3..6].copy_from_slice(dn.as_slice());
        };
        if list.len() >= PARALLEL_SWIMMERS {
            rates
                .par_iter_mut()
                .enumerate()
                .for_each(|(k, out)| one(k, out));
        } else {
            rates
                .iter_mut()
                .enumerate()
                .for_each(|(k, out)| one(k, out));
        }
        for (k, r) in rates.iter().enumerate() {
            let s = list.order[k] as usize;
            dy[STATE_PER_SWIMMER * s..STATE_PER_SWIMMER * (s + 1)].copy_from_slice(r);
        }
        self.listed.rates = rates;
    }

    /// The near pairs (s < r) of the list, each with the lattice vector that brings r's centre
    /// to the image s meets, of the swimmers `bodies` (sorted; all when `None`); `None` without a
    /// list.
    pub(super) fn near_pairs(
        &self,
        bodies: Option<&[usize]>,
    ) -> Option<Vec<(usize, usize, Vector3<f64>)>> {
        if !self.uses_lists() {
            return None;
        }
        let list = self.listed.list.as_ref()?;
        let (soa, slots) = (&self.soa, &self.listed.slots);
        let at = |v: &Soa, i: usize| Vector3::new(v.x[i], v.y[i], v.z[i]);
        let mut out = Vec::new();
        let row = |k: usize, out: &mut Vec<_>| {
            let s = list.order[k] as usize;
            for &p in list.near_row(k) {
                let r = list.swimmer_of(p as usize);
                let shift = (at(slots, p as usize) - at(slots, k)) - (at(soa, r) - at(soa, s));
                if r > s {
                    out.push((s, r, shift));
                } else if bodies.is_some_and(|b| b.binary_search(&r).is_err()) {
                    // Seen from r, which is not among the bodies: its own row is not read.
                    out.push((r, s, -shift));
                }
            }
        };
        match bodies {
            None => (0..list.len()).for_each(|k| row(k, &mut out)),
            Some(b) => b
                .iter()
                .for_each(|&s| row(list.slot_of[s] as usize, &mut out)),
        }
        Some(out)
    }

    /// The contact guard through the near rows (after `update_list`): two interacting swimmers
    /// at the same centre (the pair of smallest indices), else the overlap of smallest gap
    /// (then smallest sphere indices), as the all-pairs guard names them.
    pub(super) fn check_by_list(&self) -> Result<(), Problem> {
        let Some(list) = &self.listed.list else {
            return Ok(());
        };
        let (soa, slots) = (&self.soa, &self.listed.slots);
        let partners = |k: usize| {
            list.near_row(k)
                .iter()
                .map(|&p| (p as usize, list.swimmer_of(p as usize)))
        };
        let shared = |k: usize| -> Option<(usize, usize)> {
            let s = list.order[k] as usize;
            partners(k)
                .map(|(_, r)| r)
                .filter(|&r| {
                    r > s
                        && soa.x[s] == soa.x[r]
                        && soa.y[s] == soa.y[r]
                        && soa.z[s] == soa.z[r]
                        && self.pair_sin(s, r).is_some()
                })
                .map(|r| (s, r))
                .min()
        };
        let rows = 0..list.len();
        let found = if list.len() >= PARALLEL_SWIMMERS {
            rows.clone().into_par_iter().filter_map(shared).min()
        } else {
            rows.clone().filter_map(shared).min()
        };
        if let Some((s, r)) = found {
            return Err(super::ode::shared_centre_problem(s, r));
        }
        if self.contacts.allow_overlap {
            return Ok(());
        }
        let closest = |k: usize| -> Option<(f64, usize, usize)> {
            let s = list.order[k] as usize;
            let a = self.slot_spheres(slots, k);
            let mut best: Option<(f64, usize, usize)> = None;
            for (p, r) in partners(k).filter(|&(_, r)| r > s) {
                let b = self.slot_spheres(slots, p);
                for (i, x) in a.iter().enumerate() {
                    for (j, z) in b.iter().enumerate() {
                        let gap = (x - z).norm() - self.radii[2 * s + i] - self.radii[2 * r + j];
                        let cand = (gap, 2 * s + i, 2 * r + j);
                        if gap <= 0.0 && best.is_none_or(|b| lexically_less(cand, b)) {
                            best = Some(cand);
                        }
                    }
                }
            }
            best
        };
        let pick = |a: Option<(f64, usize, usize)>, b: Option<(f64, usize, usize)>| match (a, b) {
            (Some(x), Some(y)) => Some(if lexically_less(y, x) { y } else { x }),
            (x, None) => x,
            (None, y) => y,
        };
        let found = if list.len() >= PARALLEL_SWIMMERS {
            rows.into_par_iter().map(closest).reduce(|| None, pick)
        } else {
            rows.map(closest).fold(None, pick)
        };
        match found {
            Some((gap, a, b)) => Err(crate::engine::spheres::overlap_problem(gap, a, b)),
            None => Ok(()),
        }
    }
}

/// Whether (gap, i, j) comes before `b`: a smaller gap, then a smaller i, then a smaller j.
fn lexically_less(a: (f64, usize, usize), b: (f64, usize, usize)) -> bool {
    a.0 < b.0 || (a.0 == b.0 && (a.1, a.2) < (b.1, b.2))
}
