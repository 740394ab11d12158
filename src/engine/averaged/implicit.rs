//! What the suspension method ([`crate::engine::integrators::Suspension`]) takes from the
//! averaged model: the steric contacts' clusters with their Jacobian blocks, and an error norm
//! against each swimmer's own displacement over the step.
//!
//! A cluster is a connected set of swimmers whose bodies are within [`CONTACT_MARGIN_OF_RANGE`]
//! ranges of the repulsion of one another. Its block is ∂(steric rates)/∂(R_H, N) of its swimmers
//! by forward differences of the force law as it is: zero for a pair not yet in range (a
//! W-method keeps its order with any matrix, but its error constants grow with the matrix's
//! distance from the Jacobian, so a block that carried the law on past the range would cost the
//! swimmers about to touch their steps). The far field stays explicit.

use super::system::AveragedSystem;
use crate::engine::integrators::{ErrorMeasure, GroupJacobian};
use crate::engine::model::{vec3, STATE_PER_SWIMMER};
use crate::engine::periodic::separation;
use nalgebra::Vector3;
use rayon::prelude::*;

/// Contact clusters from this many on have their Jacobian blocks found on rayon's threads.
const PARALLEL_CLUSTERS: usize = 16;

/// Bodies within this many repulsion ranges of touching count as in contact for the Jacobian.
pub const CONTACT_MARGIN_OF_RANGE: f64 = 2.0;

/// Clusters above this many swimmers keep each swimmer's own block only (the W-method stays
/// valid; the couplings inside the cluster are then explicit): a dense LU of 6·200 unknowns is
/// what one step can afford.
pub const MAX_CLUSTER_SWIMMERS: usize = 200;

/// A swimmer's displacement over a step below this fraction of the suspension's RMS
/// displacement is held to that fraction instead: a swimmer that barely moves then weighs no
/// more in the suspension's error than a typical one.
pub const DISPLACEMENT_FLOOR: f64 = 0.1;

/// A contact: swimmers s < r, and the lattice vector that brings r to the image s meets.
type Contact = (usize, usize, Vector3<f64>);

impl AveragedSystem {
    /// Swimmer `s`'s sphere centres at centre `c` and orientation `n` (length ℓ).
    pub(super) fn spheres_at(
        &self,
        s: usize,
        c: Vector3<f64>,
        n: Vector3<f64>,
    ) -> [Vector3<f64>; 2] {
        let b = n * self.coef[s].ell;
        let (w1, w2) = self.weights[s];
        [c - w2 * b, c + w1 * b]
    }

    /// The contacts at state `y` (after `fill`, and `update_list` when lists are in use): pairs
    /// whose bodies are within the margin of the repulsion.
    pub(super) fn contacts_at(&self, y: &[f64]) -> Vec<Contact> {
        self.contacts_among(y, None)
    }

    /// The contacts at `y` of the swimmers `bodies` (all when `None`) with any swimmer.
    pub(super) fn contacts_among(&self, y: &[f64], bodies: Option<&[usize]>) -> Vec<Contact> {
        let Some(st) = self.contacts.steric else {
            return Vec::new();
        };
        let extra = (CONTACT_MARGIN_OF_RANGE - 1.0) * st.range;
        let centre = |s: usize| self.center(y, s);
        let orient = |s: usize| vec3(y, STATE_PER_SWIMMER * s + 3);
        let touching = |s: usize, r: usize, shift: Vector3<f64>| {
            let a = self.spheres_at(s, centre(s), orient(s));
            let b = self.spheres_at(r, centre(r) + shift, orient(r));
            let ra = [self.radii[2 * s], self.radii[2 * s + 1]];
            let rb = [self.radii[2 * r], self.radii[2 * r + 1]];
            let f = st.swimmer_pair_forces_within(a, ra, b, rb, extra);
            f[0] != Vector3::zeros() || f[1] != Vector3::zeros()
        };
        let mut found = Vec::new();
        match self.near_pairs(bodies) {
            Some(pairs) => {
                for (s, r, shift) in pairs {
                    if touching(s, r, shift) {
                        found.push((s, r, shift));
                    }
                }
            }
            None => {
                let n = self.coef.len();
                for s in 0..n {
                    for r in s + 1..n {
                        if bodies.is_some_and(|b| {
                            b.binary_search(&s).is_err() && b.binary_search(&r).is_err()
                        }) {
                            continue;
                        }
                        let d = centre(s) - centre(r);
                        let shift = d - separation(self.periodic.as_ref(), d);
                        if touching(s, r, shift) {
                            found.push((s, r, shift));
                        }
                    }
                }
            }
        }
        found
    }

    /// The steric rates of the swimmers of `cluster` at state `y` (component `moved.0` set to
    /// `moved.1`) from the `contacts` among them: 6 per swimmer, in the cluster's order.
    fn cluster_rates(
        &self,
        y: &[f64],
        moved: Option<(usize, f64)>,
        cluster: &[usize],
        contacts: &[Contact],
        out: &mut [f64],
    ) {
        let Some(st) = self.contacts.steric else {
            return;
        };
        let at = |s: usize| cluster.binary_search(&s).ok();
        let mut forces = vec![[Vector3::zeros(); 2]; cluster.len()];
        // The state with component `moved.0` set to `moved.1`.
        let comp = |i: usize| match moved {
            Some((m, v)) if m == i => v,
            _ => y[i],
        };
        let centre = |s: usize| {
            let i = STATE_PER_SWIMMER * s;
            (
                self.base[s] + Vector3::new(comp(i), comp(i + 1), comp(i + 2)),
                Vector3::new(comp(i + 3), comp(i + 4), comp(i + 5)),
            )
        };
        let body = |s: usize, shift: Vector3<f64>| {
            let (c, n) = centre(s);
            (
                self.spheres_at(s, c + shift, n),
                [self.radii[2 * s], self.radii[2 * s + 1]],
            )
        };
        for &(s, r, shift) in contacts {
            let ((a, ra), (b, rb)) = (body(s, Vector3::zeros()), body(r, shift));
            let on_s = st.swimmer_pair_forces(a, ra, b, rb);
            let on_r = st.swimmer_pair_forces(b, rb, a, ra);
            for (k, f) in [(at(s), on_s), (at(r), on_r)] {
                if let Some(k) = k {
                    forces[k][0] += f[0];
                    forces[k][1] += f[1];
                }
            }
        }
        for (k, &s) in cluster.iter().enumerate() {
            let (v, w) = self.steric_rates_of(s, centre(s).1, forces[k]);
            out[6 * k..6 * k + 3].copy_from_slice(v.as_slice());
            out[6 * k + 3..6 * k + 6].copy_from_slice(w.as_slice());
        }
    }

    /// The steric contacts' clusters at state `y` and their Jacobian blocks by forward
    /// differences (see the module docs).
    pub(super) fn contact_jacobian(&mut self, y: &[f64]) -> GroupJacobian {
        if self.contacts.steric.is_none() || self.coef.is_empty() {
            return GroupJacobian::default();
        }
        self.fill(y);
        if self.uses_lists() {
            self.update_list();
        }
        let contacts = self.contacts_at(y);
        self.jacobian_of(y, &contacts)
    }

    /// The clusters joined by `contacts` and their Jacobian blocks at `y`.
    pub(super) fn jacobian_of(&self, y: &[f64], contacts: &[Contact]) -> GroupJacobian {
        let (clusters, of_contact) = clusters_of(contacts);
        let mut by_cluster: Vec<Vec<Contact>> = vec![Vec::new(); clusters.len()];
        for (c, &k) in contacts.iter().zip(&of_contact) {
            by_cluster[k].push(*c);
        }
        let blocks_of = |(cluster, contacts): (&Vec<usize>, &Vec<Contact>)| {
            let groups: Vec<Vec<usize>> = if cluster.len() > MAX_CLUSTER_SWIMMERS {
                cluster.iter().map(|&s| vec![s]).collect()
            } else {
                vec![cluster.clone()]
            };
            let mut out = Vec::with_capacity(groups.len());
            for group in groups {
                let inside: Vec<Contact> = contacts
                    .iter()
                    .filter(|c| {
                        group.binary_search(&c.0).is_ok() || group.binary_search(&c.1).is_ok()
                    })
                    .copied()
                    .collect();
                let m = 6 * group.len();
                let mut base = vec![0.0; m];
                self.cluster_rates(y, None, &group, &inside, &mut base);
                let mut block = vec![0.0; m * m];
                let mut col = vec![0.0; m];
                for (q, &s) in group.iter().enumerate() {
                    for c in 0..6 {
                        let i = STATE_PER_SWIMMER * s + c;
                        // A millionth of the swimmer's ℓ for a centre, of a radian for an
                        // orientation.
                        let eps = if c < 3 { 1e-6 * self.coef[s].ell } else { 1e-6 };
                        self.cluster_rates(y, Some((i, y[i] + eps)), &group, &inside, &mut col);
                        for r in 0..m {
                            block[r * m + 6 * q + c] = (col[r] - base[r]) / eps;
                        }
                    }
                }
                let idx = group
                    .iter()
                    .flat_map(|&s| (0..6).map(move |c| STATE_PER_SWIMMER * s + c))
                    .collect();
                out.push((idx, block));
            }
            out
        };
        // Clusters are independent: in parallel when there are many, in their order either way.
        let blocks: Vec<Vec<(Vec<usize>, Vec<f64>)>> = if clusters.len() >= PARALLEL_CLUSTERS {
            clusters
                .par_iter()
                .zip(&by_cluster)
                .map(blocks_of)
                .collect()
        } else {
            clusters.iter().zip(&by_cluster).map(blocks_of).collect()
        };
        GroupJacobian {
            groups: blocks.into_iter().flatten().collect(),
        }
    }

    /// The errors of a step (embedded estimate `err`, step `h`, rates `f0` at its start) against each swimmer's own motion, for `bodies` (all when `None`): per swimmer and
    /// kind (centre, orientation) |error| / (tol · max(h·|rate at the start|, floor)), the floor
    /// being DISPLACEMENT_FLOOR × the RMS of that motion over all swimmers (per unit of step in
    /// `floor`, computed when `None`); a swimmer's error is the RMS of its two.
    pub(super) fn swimmer_errors(
        &self,
        err: &[f64],
        m: &ErrorMeasure,
        bodies: Option<&[usize]>,
        floor: &mut Option<Vec<f64>>,
        out: &mut [f64],
    ) {
        let (h, f0) = (m.h, m.f0);
        let n = self.coef.len();
        let norm3 =
            |v: &[f64], i: usize| (v[i] * v[i] + v[i + 1] * v[i + 1] + v[i + 2] * v[i + 2]).sqrt();
        // The motion the rates at the start predict: a scale the candidate state cannot move (a
        // step gone wrong, its displacement and error both huge, must not pass for a small
        // relative error, nor raise the floor of every other swimmer).
        let motion = |i: usize| h * norm3(f0, i);
        let fl = floor.get_or_insert_with(|| {
            let mut f = [0.0; 2];
            for s in 0..n {
                for (kind, f) in f.iter_mut().enumerate() {
                    *f += motion(STATE_PER_SWIMMER * s + 3 * kind).powi(2);
                }
            }
            f.iter()
                .map(|f| DISPLACEMENT_FLOOR * (f / n.max(1) as f64).sqrt() / h)
                .collect()
        });
        let one = |s: usize| {
            let i = STATE_PER_SWIMMER * s;
            let e = [0, 3].map(|o| Vector3::new(err[i + o], err[i + o + 1], err[i + o + 2]));
            self.error_of(s, e, m, fl)
        };
        match bodies {
            Some(b) => b.iter().for_each(|&s| out[s] = one(s)),
            None => (0..n).for_each(|s| out[s] = one(s)),
        }
    }
}

impl AveragedSystem {
    /// Swimmer `s`'s error of a step `h` whose error in its centre and orientation is `e`,
    /// against the motion its rates `f0` predict, floored at `floor` (per unit of step) per
    /// kind: the RMS of the two kinds' |e| / (tol · max(h·|rate|, h·floor)).
    pub(super) fn error_of(
        &self,
        s: usize,
        e: [Vector3<f64>; 2],
        m: &ErrorMeasure,
        floor: &[f64],
    ) -> f64 {
        let (h, f0, tol) = (m.h, m.f0, m.tol);
        let mut sum = 0.0;
        for (kind, fl) in floor.iter().enumerate() {
            let i = STATE_PER_SWIMMER * s + 3 * kind;
            let motion = h * vec3(f0, i).norm();
            let e = e[kind].norm();
            if e > 0.0 {
                sum += (e / (tol * motion.max(fl * h))).powi(2);
            }
        }
        (0.5 * sum).sqrt()
    }
}

/// The connected sets of swimmers joined by `contacts`, each sorted, in order of their smallest
/// swimmer (swimmers in no contact are in none), and for each contact the index of its set.
/// Work and memory follow the contacts, not the swimmer count (a refinement asks for the
/// clusters of a few swimmers many times a step).
fn clusters_of(contacts: &[Contact]) -> (Vec<Vec<usize>>, Vec<usize>) {
    let mut touched: Vec<usize> = contacts.iter().flat_map(|c| [c.0, c.1]).collect();
    touched.sort_unstable();
    touched.dedup();
    let index = |s: usize| touched.binary_search(&s).unwrap_or(0);
    let mut parent: Vec<usize> = (0..touched.len()).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for &(s, r, _) in contacts {
        let (a, b) = (root(&mut parent, index(s)), root(&mut parent, index(r)));
        if a != b {
            parent[a.max(b)] = a.min(b);
        }
    }
    // Roots are the smallest index of their set, so sets come in order of their smallest swimmer.
    let mut set_of_root = vec![usize::MAX; touched.len()];
    let mut sets: Vec<Vec<usize>> = Vec::new();
    for (i, &s) in touched.iter().enumerate() {
        let r = root(&mut parent, i);
        if set_of_root[r] == usize::MAX {
            set_of_root[r] = sets.len();
            sets.push(Vec::new());
        }
        sets[set_of_root[r]].push(s);
    }
    let of_contact = contacts
        .iter()
        .map(|c| set_of_root[root(&mut parent, index(c.0))])
        .collect();
    (sets, of_contact)
}
