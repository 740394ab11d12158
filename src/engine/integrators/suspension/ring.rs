//! The ring: the neighbours of refined swimmers whose rates change, when they read the refined
//! path instead of the coarse step, by more than their share of the tolerance; they are stepped
//! again reading that path (see the module docs of [`super`]).

use super::refine::{closure, groups_of, path_at, Access, Refusal, PARALLEL_GROUPS};
use super::scratch::{Coarse, Path, Refinement, RingPart, Rounds, SubsetStep};
use super::stepper::Suspension;
use crate::engine::integrators::system::{ErrorMeasure, GroupJacobian, Partitioned};
use rayon::prelude::*;

/// The share of the tolerance by which reading the refined swimmers' path instead of their coarse
/// states may change a neighbour's step before the neighbour is stepped again.
pub const RING_SHARE: f64 = 0.1;

impl Suspension {
    /// The swimmers to step again around the refined ones (`refined`, their paths in
    /// `self.paths`, their coarse states in `coarse`): those whose rates change, when they read
    /// the refined path instead of the coarse one (at the step's middle and end), by more than
    /// [`RING_SHARE`] of the tolerance, or by more than their coarse error `e` leaves to it; with
    /// every swimmer in a stiff group of `jac` with one of them, none refined. Read errors found
    /// in an earlier round (`kept`) stand for swimmers none of whose partners were refined anew
    /// (`kept.changed`).
    pub(super) fn ring_of(
        &mut self,
        p: &dyn Partitioned,
        step: &Coarse,
        refined: &[usize],
        e: &[f64],
        jac: &GroupJacobian,
        kept: &mut Rounds,
    ) -> Vec<usize> {
        let Coarse {
            h,
            y,
            end: coarse,
            floor,
            ..
        } = *step;
        let bs = p.body_size();
        let mut near = Vec::new();
        p.partners(refined, &mut near);
        let mut anew = Vec::new();
        p.partners(&std::mem::take(&mut kept.changed), &mut anew);
        anew.retain(|b| refined.binary_search(b).is_err());
        let comps: Vec<usize> = refined
            .iter()
            .chain(&anew)
            .flat_map(|&b| b * bs..(b + 1) * bs)
            .collect();
        self.coarse_and_refined(y, coarse, h, &comps);
        kept.read.resize(e.len(), 0.0);
        for &b in &anew {
            kept.worst.insert(b, 0.0);
        }
        for (before, after) in &self.views {
            let m = ErrorMeasure {
                h,
                f0: &self.f0,
                tol: self.tol,
            };
            p.read_errors([before, after], &anew, refined, &m, floor, &mut kept.read);
            for &b in &anew {
                if let Some(w) = kept.worst.get_mut(&b) {
                    *w = w.max(kept.read[b]);
                }
            }
        }
        let moved: Vec<usize> = near
            .into_iter()
            .filter(|&b| {
                // A swimmer near the refined ones is near a group refined anew or was near one
                // in an earlier round.
                let r = kept.worst.get(&b).copied().unwrap_or(f64::NAN);
                r.is_nan() || r > RING_SHARE || r + e[b] > 1.0
            })
            .collect();
        closure(moved, jac, bs)
            .into_iter()
            .filter(|b| refined.binary_search(b).is_err())
            .collect()
    }

    /// Take the coarse step again for the swimmers `ring` that read the refined ones, now reading
    /// those along their refined path (linear between their steps) and the rest from the coarse
    /// step: what the refined swimmers' coarse states did to them is undone. The ring's parts
    /// that read none of each other's states are stepped apart (on rayon's threads as the
    /// refined groups are); a part stepped in an earlier round (`kept`) stands while none of its
    /// partners was refined anew. The ring swimmers that
    /// then miss the tolerance (all of a part's when a contact forms with a swimmer outside it);
    /// when none does, their new states go into `y_new`.
    pub(super) fn redo_ring(
        &mut self,
        p: &mut dyn Partitioned,
        step: &Coarse,
        refined: &[usize],
        ring: &[usize],
        kept: &mut Rounds,
    ) -> Vec<usize> {
        let Coarse { t, h, y, floor, .. } = *step;
        if ring.is_empty() {
            return Vec::new();
        }
        let bs = p.body_size();
        let mut partners = Vec::new();
        // Parts whose partners were refined anew read other paths now.
        let changed = std::mem::take(&mut kept.redo_changed);
        kept.ring.retain(|part, _| {
            p.partners(part, &mut partners);
            !partners.iter().any(|b| changed.binary_search(b).is_ok())
        });
        let parts = groups_of(p, ring);
        let todo: Vec<&Vec<usize>> = parts
            .iter()
            .filter(|part| !kept.ring.contains_key(*part))
            .collect();
        let ctx = RingContext {
            t,
            h,
            tol: self.tol,
            y,
            y_new: &self.y_new,
            f0: &self.f0,
            paths: &self.paths,
            refined,
            floor,
        };
        let mut results: Vec<Result<RingPart, Refusal>> = if todo.len() >= PARALLEL_GROUPS
            && p.shares_rates()
        {
            let shared: &dyn Partitioned = p;
            let pool = &self.pool;
            todo.par_iter()
                .map(|part| pool.with(|sub| ctx.step_part(sub, &mut Access::Shared(shared), part)))
                .collect()
        } else {
            todo.iter().map(|_| Err(Refusal::Relist)).collect()
        };
        for (part, result) in todo.iter().zip(results.iter_mut()) {
            if matches!(result, Err(Refusal::Relist)) {
                *result = ctx.step_part(&mut self.sub, &mut Access::Own(&mut *p), part);
            }
        }
        let mut missed = Vec::new();
        for (part, result) in todo.into_iter().zip(results) {
            match result {
                Ok(done) => {
                    kept.ring.insert(part.clone(), done);
                }
                // The part's swimmers and outsiders of contacts forming across its edge.
                Err(Refusal::Crossing(crossing)) => missed.extend(
                    crossing
                        .into_iter()
                        .filter(|b| refined.binary_search(b).is_err()),
                ),
                Err(_) => missed.extend(part.iter().copied()),
            }
        }
        for part in &parts {
            if let Some((_, errors)) = kept.ring.get(part) {
                missed.extend(
                    part.iter()
                        .zip(errors)
                        .filter(|(_, e)| e.is_nan() || **e > 1.0)
                        .map(|(b, _)| *b),
                );
            }
        }
        if missed.is_empty() {
            for part in &parts {
                if let Some((states, _)) = kept.ring.get(part) {
                    let comps = part.iter().flat_map(|&b| b * bs..(b + 1) * bs);
                    for (m, &v) in comps.zip(states) {
                        self.y_new[m] = v;
                    }
                }
            }
        }
        missed.sort_unstable();
        missed.dedup();
        missed
    }
}

/// What stepping a part of the ring again reads (see [`Suspension::redo_ring`]): the coarse step
/// from (t, y) by h (its end `y_new`, its starting rates `f0`), the refined groups' paths.
struct RingContext<'a> {
    t: f64,
    h: f64,
    tol: f64,
    y: &'a [f64],
    y_new: &'a [f64],
    f0: &'a [f64],
    paths: &'a [(Vec<usize>, Path)],
    refined: &'a [usize],
    floor: &'a [f64],
}

impl RingContext<'_> {
    /// Step the ring swimmers `part` again across the coarse step (scratch `sub`), reading their
    /// refined partners along their paths and the others from the coarse step: their new states
    /// (by component) and errors, or why not.
    fn step_part(
        &self,
        sub: &mut Refinement,
        access: &mut Access,
        part: &[usize],
    ) -> Result<RingPart, Refusal> {
        let (y, t, h) = (self.y, self.t, self.h);
        let bs = access.get().body_size();
        let mut partners = Vec::new();
        access.get().partners(part, &mut partners);
        let others: Vec<usize> = partners
            .iter()
            .filter(|b| self.refined.binary_search(b).is_err())
            .flat_map(|&b| b * bs..(b + 1) * bs)
            .collect();
        // The refined paths this part reads.
        let read_paths: Vec<&(Vec<usize>, Path)> = self
            .paths
            .iter()
            .filter(|(comps, _)| {
                comps
                    .iter()
                    .step_by(bs)
                    .any(|m| partners.binary_search(&(m / bs)).is_ok())
            })
            .collect();
        let mut changed: Vec<usize> = part.iter().chain(&partners).copied().collect();
        changed.sort_unstable();
        changed.dedup();
        sub.fit(y.len(), y.len() / bs.max(1));
        let comps = || part.iter().flat_map(|&b| b * bs..(b + 1) * bs);
        for m in comps() {
            sub.y0[m] = y[m];
        }
        let (y_new, f0) = (self.y_new, self.f0);
        let at = |yw: &mut [f64], time: f64| {
            Suspension::coarse_at(y, y_new, f0, h, &others, yw, (time - t) / h);
            let tau = time - t;
            for (comps, path) in &read_paths {
                for (&m, v) in comps.iter().zip(path_at(path, tau)) {
                    yw[m] = v;
                }
            }
        };
        let step = SubsetStep {
            t0: t,
            h,
            tol: self.tol,
            bodies: part,
            changed: &changed,
            floor: self.floor,
        };
        Suspension::subset_step(sub, access, &step, &at)?;
        let states = comps().map(|m| sub.y1[m]).collect();
        let errors = part.iter().map(|&b| sub.errors[b]).collect();
        Ok((states, errors))
    }
}
