//! The averaged model as bodies that a multirate method steps apart
//! ([`crate::engine::integrators::Partitioned`]): a few swimmers (a contact, a close pair) take
//! shorter steps while the rest of the suspension is read from an interpolation. The rates of a
//! few swimmers cost what their own rows cost: with neighbour lists, only the slot entries of the
//! swimmers that moved are refreshed.

use super::system::AveragedSystem;
use crate::engine::integrators::{ErrorMeasure, GroupJacobian, Partitioned};
use crate::engine::model::{vec3, STATE_PER_SWIMMER};
use crate::engine::neighbours::NeighbourList;
use crate::engine::periodic::separation;
use nalgebra::Vector3;

impl Partitioned for AveragedSystem {
    fn body_size(&self) -> usize {
        STATE_PER_SWIMMER
    }

    fn body_errors(
        &self,
        err: &[f64],
        m: &ErrorMeasure,
        bodies: Option<&[usize]>,
        floor: &mut Option<Vec<f64>>,
        out: &mut [f64],
    ) {
        self.swimmer_errors(err, m, bodies, floor, out);
    }

    fn partners(&self, bodies: &[usize], out: &mut Vec<usize>) {
        out.clear();
        match self.listed_list() {
            Some(list) => {
                for &s in bodies {
                    let k = list.slot_of[s] as usize;
                    for &p in list.far_row(k).0.iter().chain(list.near_row(k)) {
                        if p as usize != list.pad_slot() {
                            out.push(list.swimmer_of(p as usize));
                        }
                    }
                }
            }
            None => out.extend(0..self.coef.len()),
        }
        out.sort_unstable();
        out.dedup();
        out.retain(|s| bodies.binary_search(s).is_err());
    }

    fn rhs_bodies(
        &mut self,
        _t: f64,
        y: &[f64],
        bodies: &[usize],
        changed: &[usize],
        dy: &mut [f64],
    ) {
        if self.rates_shared(y, bodies, changed, dy) {
            return;
        }
        if self.shares_rates() {
            // Swimmers that left their lists are relisted (their array and slot entries set from
            // `y` first, as a relisting reads them; new ghosts get their slot entries).
            // Nothing else is written: the rates read the states from `y`.
            let moved: Vec<usize> = changed
                .iter()
                .copied()
                .filter(|&s| !self.holds(y, s))
                .collect();
            for &s in &moved {
                self.fill_swimmer(y, s);
            }
            if self.relist(Some(moved.clone())) {
                self.refill_slots();
            } else {
                self.extend_slots();
                for &s in &moved {
                    self.refresh_slot(s);
                }
            }
        } else {
            // No list: everything from `y`.
            self.fill(y);
            if self.uses_lists() {
                self.update_list();
            } else if let Some(st) = self.contacts.steric {
                self.steric_f.fill(nalgebra::Vector3::zeros());
                let periodic = self.periodic;
                st.add_forces(
                    &self.sphere_pos,
                    &self.radii,
                    periodic.as_ref(),
                    &mut self.steric_f,
                    false,
                );
            }
        }
        match self.listed_list().filter(|_| self.uses_lists()) {
            Some(list) => self.listed_rates(list, y, bodies, dy),
            None => {
                let vector = self.vector_rows();
                let mut out = [0.0; STATE_PER_SWIMMER];
                for &s in bodies {
                    self.row_rates(s, y, vector, &mut out);
                    dy[STATE_PER_SWIMMER * s..STATE_PER_SWIMMER * (s + 1)].copy_from_slice(&out);
                }
            }
        }
    }

    fn stiff_groups_of(
        &self,
        _t: f64,
        y: &[f64],
        bodies: &[usize],
    ) -> Result<GroupJacobian, Vec<usize>> {
        if self.contacts.steric.is_none() {
            return Ok(GroupJacobian::default());
        }
        let contacts = self.contacts_among(y, Some(bodies));
        let inside = |s: usize| bodies.binary_search(&s).is_ok();
        let mut crossing: Vec<usize> = contacts
            .iter()
            .filter(|c| !(inside(c.0) && inside(c.1)))
            .flat_map(|c| [c.0, c.1])
            .collect();
        if !crossing.is_empty() {
            crossing.sort_unstable();
            crossing.dedup();
            return Err(crossing);
        }
        Ok(self.jacobian_of(y, &contacts))
    }

    fn shares_rates(&self) -> bool {
        self.uses_lists() && self.listed_list().is_some()
    }

    fn rates_shared(&self, y: &[f64], bodies: &[usize], changed: &[usize], dy: &mut [f64]) -> bool {
        let Some(list) = self.listed_list().filter(|_| self.uses_lists()) else {
            return false;
        };
        if !changed.iter().all(|&s| self.holds(y, s)) {
            return false;
        }
        self.listed_rates(list, y, bodies, dy);
        true
    }

    fn read_errors(
        &self,
        [before, after]: [&[f64]; 2],
        bodies: &[usize],
        sources: &[usize],
        m: &ErrorMeasure,
        floor: &[f64],
        out: &mut [f64],
    ) {
        let h = m.h;
        let periodic = self.periodic.as_ref();
        let mut partners = Vec::new();
        for &s in bodies {
            // The sources among s's partners.
            self.partners(&[s], &mut partners);
            partners.retain(|r| sources.binary_search(r).is_ok());
            let cs = self.center(before, s);
            let ns = vec3(before, STATE_PER_SWIMMER * s + 3);
            let (mut dv, mut dt) = (Vector3::zeros(), Vector3::zeros());
            for &r in &partners {
                let Some(sin) = self.pair_sin(s, r) else {
                    continue;
                };
                let terms = |y: &[f64]| {
                    let (mut v, mut t) = (Vector3::zeros(), Vector3::zeros());
                    let d = separation(periodic, cs - self.center(y, r));
                    let nr = vec3(y, STATE_PER_SWIMMER * r + 3);
                    self.add_pair_terms(s, ns, d, nr, sin, &mut v, &mut t);
                    (v, t)
                };
                let ((va, ta), (vb, tb)) = (terms(before), terms(after));
                dv += vb - va;
                dt += tb - ta;
            }
            let dn = -(dt - ns * ns.dot(&dt));
            out[s] = self.error_of(s, [dv * h, dn * h], m, floor);
        }
    }
}

impl AveragedSystem {
    /// Whether swimmer `s`, at its centre in state `y`, is still within its list's skin (a list
    /// in use).
    fn holds(&self, y: &[f64], s: usize) -> bool {
        let c = self.center(y, s);
        self.listed_list()
            .is_some_and(|list| list.holds(s, c.x, c.y, c.z))
    }

    /// The rates of `bodies` at state `y` into their blocks of `dy`, through `list` (the one in
    /// use; [`AveragedSystem::rates_from_state`]).
    fn listed_rates(&self, list: &NeighbourList, y: &[f64], bodies: &[usize], dy: &mut [f64]) {
        let mut out = [0.0; STATE_PER_SWIMMER];
        for &s in bodies {
            self.rates_from_state(list, y, s, &mut out);
            dy[STATE_PER_SWIMMER * s..STATE_PER_SWIMMER * (s + 1)].copy_from_slice(&out);
        }
    }

    /// Swimmer `s`'s rates at state `y` (after `update_list`), its partners found through its rows
    /// in `list` and read from `y`, met at their minimum images (the list's images within its radius):
    /// the far field of [`AveragedSystem::add_pair_terms`] over the far row with its weights,
    /// the steric forces over the near row.
    fn rates_from_state(&self, list: &NeighbourList, y: &[f64], s: usize, out: &mut [f64]) {
        let periodic = self.periodic.as_ref();
        let k = list.slot_of[s] as usize;
        let pad = list.pad_slot();
        let cs = self.center(y, s);
        let ns = vec3(y, STATE_PER_SWIMMER * s + 3);
        let orientation = |r: usize| vec3(y, STATE_PER_SWIMMER * r + 3);
        let (mut v, mut t) = (Vector3::zeros(), Vector3::zeros());
        let (partners, weights) = list.far_row(k);
        for (&q, &w) in partners.iter().zip(weights) {
            if q as usize == pad {
                break;
            }
            let r = list.swimmer_of(q as usize);
            let d = separation(periodic, cs - self.center(y, r));
            self.add_pair_terms(s, ns, d, orientation(r), w, &mut v, &mut t);
        }
        let mut dn = -(t - ns * ns.dot(&t));
        if let Some(st) = self.contacts.steric {
            let a = self.spheres_at(s, cs, ns);
            let ra = [self.radii[2 * s], self.radii[2 * s + 1]];
            let mut f = [Vector3::zeros(); 2];
            for &q in list.near_row(k) {
                let r = list.swimmer_of(q as usize);
                let d = separation(periodic, cs - self.center(y, r));
                let b = self.spheres_at(r, cs - d, orientation(r));
                let rb = [self.radii[2 * r], self.radii[2 * r + 1]];
                let df = st.swimmer_pair_forces(a, ra, b, rb);
                f[0] += df[0];
                f[1] += df[1];
            }
            let (vs, ws) = self.steric_rates_of(s, ns, f);
            v += vs;
            dn += ws;
        }
        out[..3].copy_from_slice(v.as_slice());
        out[3..6].copy_from_slice(dn.as_slice());
    }

    /// Swimmer `s`'s slot entries from its entries in state order.
    fn refresh_slot(&mut self, s: usize) {
        let soa = &self.soa;
        let (c, n) = (
            [soa.x[s], soa.y[s], soa.z[s]],
            [soa.nx[s], soa.ny[s], soa.nz[s]],
        );
        self.refresh_slots(s, c, n);
    }
}
