//! Refinement: the few swimmers that missed the tolerance in a coarse step, with every swimmer in
//! contact with them, stepped again across the same interval with steps of their own, reading the
//! others from the coarse step; groups that read none of each other apart, on rayon's threads
//! when the system allows (see the module docs of [`super`]).

use super::scratch::{Coarse, Path, Refined, Refinement, Rounds, SubsetStep};
use super::stepper::Suspension;
use crate::engine::integrators::controller::{step_too_small, StepRule};
use crate::engine::integrators::system::{GroupJacobian, Partitioned};
use rayon::prelude::*;

/// Refined groups from this many on are refined on rayon's threads (when the system allows).
pub const PARALLEL_GROUPS: usize = 2;

/// The most steps a refinement may take across one coarse step.
pub const MAX_SUBSTEPS: u32 = 100_000;

/// Why a refinement or a subset step stopped.
#[derive(Debug)]
pub(super) enum Refusal {
    /// A contact forms between the bodies stepped and others: the bodies of every such contact.
    Crossing(Vec<usize>),
    /// The steps shrank to nothing.
    Failed,
    /// The system's neighbour data must change first (read shared, it cannot).
    Relist,
}

/// How a refinement reaches the system: owned (rates through [`Partitioned::rhs_bodies`], which
/// may update the system) or shared among threads (through [`Partitioned::rates_shared`]).
pub(super) enum Access<'a> {
    Own(&'a mut dyn Partitioned),
    Shared(&'a dyn Partitioned),
}

impl Access<'_> {
    pub(super) fn get(&self) -> &dyn Partitioned {
        match self {
            Access::Own(p) => &**p,
            Access::Shared(p) => *p,
        }
    }

    /// The rates of `bodies` at `y` into `dy` (see [`Partitioned::rhs_bodies`]).
    pub(super) fn rates(
        &mut self,
        t: f64,
        y: &[f64],
        bodies: &[usize],
        changed: &[usize],
        dy: &mut [f64],
    ) -> Result<(), Refusal> {
        match self {
            Access::Own(p) => {
                p.rhs_bodies(t, y, bodies, changed, dy);
                Ok(())
            }
            Access::Shared(p) => {
                if p.rates_shared(y, bodies, changed, dy) {
                    Ok(())
                } else {
                    Err(Refusal::Relist)
                }
            }
        }
    }
}

impl Suspension {
    /// This thread's scratch sized to the state `y`, with the working states at `y` (a
    /// refinement that relists a swimmer may read a new partner's state before it sets it).
    pub(super) fn prepare_sub(&mut self, y: &[f64], bodies: usize) {
        self.sub.fit(y.len(), bodies);
        self.sub.yw.copy_from_slice(y);
        self.sub.y0.copy_from_slice(y);
    }

    /// The states of components `read` at time `t0 + θh` from the coarse step from `y`: the
    /// quadratic through y and y_new with slope f0 at the start.
    pub(super) fn coarse_at(
        y: &[f64],
        y_new: &[f64],
        f0: &[f64],
        h: f64,
        read: &[usize],
        yw: &mut [f64],
        theta: f64,
    ) {
        for &i in read {
            let slope = h * f0[i];
            yw[i] = y[i] + theta * slope + theta * theta * (y_new[i] - y[i] - slope);
        }
    }

    /// Step the swimmers `bodies` again from `t` to `t + h` by steps of their own (scratch
    /// `sub`), the others read from the coarse step (`coarse`, with rates `f0` at its start):
    /// their components, path across the step and the steps taken.
    pub(super) fn refine(
        sub: &mut Refinement,
        p: &mut Access,
        tol: f64,
        step: &Coarse,
        f0: &[f64],
        bodies: &[usize],
    ) -> Result<Refined, Refusal> {
        let Coarse {
            t,
            h,
            y,
            end: coarse,
            floor,
        } = *step;
        let bs = p.get().body_size();
        let mut partners = Vec::new();
        p.get().partners(bodies, &mut partners);
        let read: Vec<usize> = partners
            .iter()
            .flat_map(|&b| b * bs..(b + 1) * bs)
            .collect();
        let comps: Vec<usize> = bodies.iter().flat_map(|&b| b * bs..(b + 1) * bs).collect();
        let mut changed: Vec<usize> = bodies.iter().chain(&partners).copied().collect();
        changed.sort_unstable();
        sub.fit(y.len(), y.len() / bs.max(1));
        for &m in &comps {
            sub.y0[m] = y[m];
        }
        let mut path = vec![(0.0, comps.iter().map(|&m| y[m]).collect::<Vec<f64>>())];
        let at = |yw: &mut [f64], time: f64| {
            Self::coarse_at(y, coarse, f0, h, &read, yw, (time - t) / h)
        };
        let mut tau = 0.0;
        let mut hs = 0.5 * h;
        let mut steps = 0u64;
        let mut attempts = 0u32;
        while tau < h {
            attempts += 1;
            if attempts > MAX_SUBSTEPS {
                return Err(Refusal::Failed);
            }
            let span = h - tau;
            let (h_try, last) = if hs >= span {
                (span, true)
            } else {
                (hs, false)
            };
            let step = SubsetStep {
                t0: t + tau,
                h: h_try,
                tol,
                bodies,
                changed: &changed,
                floor,
            };
            let norm = Self::subset_step(sub, p, &step, &at)?;
            if norm <= 1.0 && norm.is_finite() {
                for &m in &comps {
                    sub.y0[m] = sub.y1[m];
                }
                tau = if last { h } else { tau + h_try };
                path.push((tau, comps.iter().map(|&m| sub.y1[m]).collect()));
                steps += 1;
                if !(last && h_try < hs) {
                    hs = StepRule::Elementary.after_accept(norm, h_try, false);
                }
            } else {
                hs = StepRule::Elementary.after_reject(norm, h_try);
                if step_too_small(hs, t + tau, 0.0) || hs < 1e-12 * h {
                    return Err(Refusal::Failed);
                }
            }
        }
        Ok(Refined { comps, path, steps })
    }

    /// Refine every group of `groups` (see [`Suspension::refine`]) not refined in an earlier
    /// round (`kept`): on rayon's threads, each with scratch of its own, when the system's rates
    /// can be read shared; a group whose swimmers left the system's neighbour data, and every
    /// group otherwise, on this thread. Their new states go into `y_new` and their paths into
    /// `self.paths`, the swimmers of the groups refined now added to `kept.changed`; the steps taken,
    /// or the refusal of the first group refused.
    pub(super) fn refine_groups(
        &mut self,
        p: &mut dyn Partitioned,
        step: &Coarse,
        groups: &[Vec<usize>],
        kept: &mut Rounds,
    ) -> Result<u64, Refusal> {
        let (tol, f0) = (self.tol, &self.f0);
        let new: Vec<&Vec<usize>> = groups
            .iter()
            .filter(|g| !kept.groups.contains_key(*g))
            .collect();
        for changed in [&mut kept.changed, &mut kept.redo_changed] {
            changed.extend(new.iter().flat_map(|g| g.iter().copied()));
            changed.sort_unstable();
            changed.dedup();
        }
        let mut results: Vec<Result<Refined, Refusal>> =
            if new.len() >= PARALLEL_GROUPS && p.shares_rates() {
                let shared: &dyn Partitioned = p;
                let pool = &self.pool;
                new.par_iter()
                    .map(|group| {
                        pool.with(|sub| {
                            Self::refine(sub, &mut Access::Shared(shared), tol, step, f0, group)
                        })
                    })
                    .collect()
            } else {
                new.iter().map(|_| Err(Refusal::Relist)).collect()
            };
        for (group, result) in new.iter().zip(results.iter_mut()) {
            if matches!(result, Err(Refusal::Relist)) {
                *result = Self::refine(&mut self.sub, &mut Access::Own(p), tol, step, f0, group);
            }
        }
        let mut crossing = Vec::new();
        for (group, result) in new.into_iter().zip(results) {
            match result {
                Ok(refined) => {
                    kept.groups.insert(group.clone(), refined);
                }
                Err(Refusal::Crossing(more)) => crossing.extend(more),
                Err(refusal) => return Err(refusal),
            }
        }
        if !crossing.is_empty() {
            return Err(Refusal::Crossing(crossing));
        }
        let mut steps = 0;
        for group in groups {
            let Some(Refined {
                comps,
                path,
                steps: taken,
            }) = kept.groups.get(group)
            else {
                continue;
            };
            if let Some((_, end)) = path.last() {
                for (&m, &v) in comps.iter().zip(end) {
                    self.y_new[m] = v;
                }
            }
            self.paths.push((comps.clone(), path.clone()));
            steps += taken;
        }
        Ok(steps)
    }

    /// Into `self.views`, the states at the step's middle and end of the components `comps` (the
    /// only entries set): from the coarse step (`coarse`, quadratic) and, in the second of each
    /// pair, the refined swimmers' from their paths.
    pub(super) fn coarse_and_refined(
        &mut self,
        y: &[f64],
        coarse: &[f64],
        h: f64,
        comps: &[usize],
    ) {
        let n = y.len();
        for (theta, (before, after)) in [0.5, 1.0].into_iter().zip(self.views.iter_mut()) {
            before.resize(n, 0.0);
            after.resize(n, 0.0);
            Self::coarse_at(y, coarse, &self.f0, h, comps, before, theta);
            for &m in comps {
                after[m] = before[m];
            }
            for (path_comps, path) in &self.paths {
                for (&m, v) in path_comps.iter().zip(path_at(path, theta * h)) {
                    after[m] = v;
                }
            }
        }
    }
}

/// A refined path's states at time `tau` from the coarse step's start: linear between its steps.
pub(super) fn path_at(path: &Path, tau: f64) -> impl Iterator<Item = f64> + '_ {
    let j = path
        .partition_point(|(s, _)| *s <= tau)
        .clamp(1, path.len() - 1);
    let ((s0, a), (s1, b)) = (&path[j - 1], &path[j]);
    let w = if s1 > s0 {
        ((tau - s0) / (s1 - s0)).clamp(0.0, 1.0)
    } else {
        1.0
    };
    a.iter().zip(b).map(move |(a, b)| a + w * (b - a))
}

/// The groups of `bodies` (sorted) that read one another's states, directly or through others of
/// them: connected sets under [`Partitioned::partners`].
pub(super) fn groups_of(p: &dyn Partitioned, bodies: &[usize]) -> Vec<Vec<usize>> {
    let mut parent: Vec<usize> = (0..bodies.len()).collect();
    pub(super) fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut partners = Vec::new();
    for (i, &b) in bodies.iter().enumerate() {
        p.partners(&[b], &mut partners);
        for q in &partners {
            if let Ok(j) = bodies.binary_search(q) {
                let (a, c) = (root(&mut parent, i), root(&mut parent, j));
                parent[a.max(c)] = a.min(c);
            }
        }
    }
    let mut groups: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
    for (i, &b) in bodies.iter().enumerate() {
        let r = root(&mut parent, i);
        groups.entry(r).or_default().push(b);
    }
    groups.into_values().collect()
}

/// `bodies` with every body in a stiff group of `jac` with one of them, sorted.
pub(super) fn closure(mut bodies: Vec<usize>, jac: &GroupJacobian, bs: usize) -> Vec<usize> {
    bodies.sort_unstable();
    let mut added = Vec::new();
    for (idx, _) in &jac.groups {
        let members: Vec<usize> = idx.iter().map(|&i| i / bs).collect();
        if members.iter().any(|m| bodies.binary_search(m).is_ok()) {
            added.extend(members);
        }
    }
    bodies.extend(added);
    bodies.sort_unstable();
    bodies.dedup();
    bodies
}
