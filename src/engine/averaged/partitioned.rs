//! The averaged model as bodies that a multirate method steps apart
//! ([`crate::engine::integrators::Partitioned`]): a few swimmers (a contact, a close pair) take
//! shorter steps while the rest of the suspension is read from an interpolation. The rates of a
//! few swimmers cost what their own rows cost: with neighbour lists, only the slot entries of the
//! swimmers that moved are refreshed.

use super::{list_rows, AveragedSystem, STATE_PER_SWIMMER};
use crate::engine::integrators::{GroupJacobian, Partitioned};

impl Partitioned for AveragedSystem {
    fn body_size(&self) -> usize {
        STATE_PER_SWIMMER
    }

    fn body_errors(
        &self,
        _y: &[f64],
        _y_new: &[f64],
        err: &[f64],
        h: f64,
        f0: &[f64],
        tol: f64,
        bodies: Option<&[usize]>,
        floor: &mut Option<Vec<f64>>,
        out: &mut [f64],
    ) {
        self.swimmer_errors(err, h, f0, tol, bodies, floor, out);
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
        let incremental = self.uses_lists() && self.listed_list().is_some();
        if incremental {
            for &s in changed {
                self.fill_swimmer(y, s);
            }
            // Swimmers that left their lists are relisted (their new ghosts need the slot
            // arrays refilled); the others' slot entries follow their new states.
            let soa = &self.soa;
            let moved: Vec<usize> = self.listed_list().map_or_else(Vec::new, |list| {
                changed
                    .iter()
                    .copied()
                    .filter(|&s| !list.holds(s, soa.x[s], soa.y[s], soa.z[s]))
                    .collect()
            });
            if !moved.is_empty() && self.relist(Some(moved)) {
                self.refill_slots();
            } else {
                for &s in changed {
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
        let mut out = [0.0; STATE_PER_SWIMMER];
        if self.uses_lists() {
            if let Some(st) = self.contacts.steric {
                for &s in bodies {
                    let f = self.steric_of(st, s);
                    self.steric_f[2 * s] = f[0];
                    self.steric_f[2 * s + 1] = f[1];
                }
            }
            for &s in bodies {
                let (list, slots) = self.listed_parts();
                let (v, t) = list_rows::row(self, list, slots, list.slot_of[s] as usize);
                self.finish_rates(s, y, v, t, &mut out);
                dy[STATE_PER_SWIMMER * s..STATE_PER_SWIMMER * (s + 1)].copy_from_slice(&out);
            }
        } else {
            let vector = self.vector_rows();
            for &s in bodies {
                self.row_rates(s, y, vector, &mut out);
                dy[STATE_PER_SWIMMER * s..STATE_PER_SWIMMER * (s + 1)].copy_from_slice(&out);
            }
        }
    }

    fn stiff_groups_of(
        &mut self,
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
}

impl AveragedSystem {
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
