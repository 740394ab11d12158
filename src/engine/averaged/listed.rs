//! The averaged system's neighbour lists ([`crate::engine::neighbours`]): kept valid as the
//! centres move (rebuilt once a centre has moved half the skin), their slot arrays refilled at
//! every right-hand side, and the steric forces and the contact guard through their near rows.

use super::{
    list_rows, vec3, AveragedSystem, Problem, Soa, DEFAULT_SKIN_OF_CUTOFF, LIST_SWIMMERS,
    PARALLEL_SWIMMERS, STATE_PER_SWIMMER,
};
use crate::engine::contacts::Steric;
use crate::engine::neighbours::{ListSpec, NeighbourList};
use nalgebra::Vector3;
use rayon::prelude::*;

/// The list and the arrays in its slot order.
#[derive(Debug, Clone, Default)]
pub(super) struct Listed {
    list: Option<NeighbourList>,
    /// Positions and orientations by slot (swimmers, ghosts, the pad).
    slots: Soa,
    /// Scratch: rates by slot.
    rates: Vec<[f64; 6]>,
    /// Scratch: steric forces on each slot's two spheres.
    forces: Vec<[Vector3<f64>; 2]>,
    builds: u64,
}

impl Listed {
    /// Lists built so far.
    pub(super) fn builds(&self) -> u64 {
        self.builds
    }
}

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

    /// After `fill`: a list valid for the current centres (rebuilt when a centre has moved half
    /// the skin since its build), and its slot arrays filled from the current state.
    pub(super) fn update_list(&mut self) {
        let spec = self.list_spec();
        let soa = &self.soa;
        let valid = self
            .listed
            .list
            .as_ref()
            .is_some_and(|l| l.spec() == spec && l.is_valid_for(&soa.x, &soa.y, &soa.z));
        if !valid {
            let weight = |i: usize, j: usize| self.pair_sin(i, j);
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
        }
        let Some(list) = &self.listed.list else {
            return;
        };
        let slots = &mut self.listed.slots;
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

    /// Swimmer `s`'s sphere centres if it sat in slot `k` (length ℓ, as [`AveragedSystem::fill`]).
    fn slot_spheres(&self, slots: &Soa, k: usize, s: usize) -> [Vector3<f64>; 2] {
        let c = Vector3::new(slots.x[k], slots.y[k], slots.z[k]);
        let b = Vector3::new(slots.nx[k], slots.ny[k], slots.nz[k]) * self.coef[s].ell;
        let (w1, w2) = self.weights[s];
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
        let one = |k: usize, f: &mut [Vector3<f64>; 2]| {
            let s = list.order[k] as usize;
            let a = self.slot_spheres(slots, k, s);
            let ra = [self.radii[2 * s], self.radii[2 * s + 1]];
            *f = [Vector3::zeros(); 2];
            let (from, to) = (list.near_start[k] as usize, list.near_start[k + 1] as usize);
            for &p in &list.near_partner[from..to] {
                let r = list.swimmer_of(p as usize);
                let b = self.slot_spheres(slots, p as usize, r);
                let rb = [self.radii[2 * r], self.radii[2 * r + 1]];
                let df = st.swimmer_pair_forces(a, ra, b, rb);
                f[0] += df[0];
                f[1] += df[1];
            }
        };
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

    /// Fill `dy` from the far rows (and the steric rates), slot by slot in parallel.
    pub(super) fn rows_by_list(&mut self, y: &[f64], dy: &mut [f64]) {
        let Some(list) = &self.listed.list else {
            return;
        };
        let slots = &self.listed.slots;
        let mut rates = std::mem::take(&mut self.listed.rates);
        rates.resize(list.len(), [0.0; 6]);
        let one = |k: usize, out: &mut [f64; 6]| {
            let s = list.order[k] as usize;
            let (mut v, t) = list_rows::row(self, list, slots, k);
            let n = vec3(y, STATE_PER_SWIMMER * s + 3);
            let mut dn = -(t - n * n.dot(&t));
            if self.contacts.steric.is_some() {
                let (vs, ns) = self.steric_rates(s);
                v += vs;
                dn += ns;
            }
            out[..3].copy_from_slice(v.as_slice());
            out[3..].copy_from_slice(dn.as_slice());
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

    /// The contact guard through the near rows (after `update_list`): two interacting swimmers
    /// at the same centre (the pair of smallest indices), else the overlap of smallest gap
    /// (then smallest sphere indices), as the all-pairs guard names them.
    pub(super) fn check_by_list(&self) -> Result<(), Problem> {
        let Some(list) = &self.listed.list else {
            return Ok(());
        };
        let (soa, slots) = (&self.soa, &self.listed.slots);
        let partners = |k: usize| {
            let (from, to) = (list.near_start[k] as usize, list.near_start[k + 1] as usize);
            list.near_partner[from..to]
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
            return Err(super::shared_centre_problem(s, r));
        }
        if self.contacts.allow_overlap {
            return Ok(());
        }
        let closest = |k: usize| -> Option<(f64, usize, usize)> {
            let s = list.order[k] as usize;
            let a = self.slot_spheres(slots, k, s);
            let mut best: Option<(f64, usize, usize)> = None;
            for (p, r) in partners(k).filter(|&(_, r)| r > s) {
                let b = self.slot_spheres(slots, p, r);
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
