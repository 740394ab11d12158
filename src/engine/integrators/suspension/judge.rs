//! The coarse step judged swimmer by swimmer: whether it stands as it is, stands after refining
//! a few swimmers (and stepping their ring again), or is taken again shorter; and the error the
//! controller sizes the next step by.

use super::refine::{closure, groups_of, Refusal};
use super::scratch::{Coarse, Rounds};
use super::stepper::Suspension;
use crate::engine::integrators::system::{ErrorMeasure, GroupJacobian, OdeSystem, Stats};

/// The largest share of swimmers a step refines: more, and the whole step is taken again shorter.
pub const MAX_REFINED_FRACTION: f64 = 0.05;

/// The share of swimmers the step size controller aims to leave to refinement.
pub const REFINED_TARGET_FRACTION: f64 = 0.01;

/// Rounds of refining and stepping the ring again before a step is given up (each round adds the
/// ring swimmers that missed the tolerance to the refined ones).
pub const RING_ROUNDS: usize = 4;

impl Suspension {
    /// The coarse step's error for the controller and whether it stands, after refining a few
    /// swimmers where that lets it stand (see the module docs).
    pub(super) fn judge(
        &mut self,
        sys: &mut dyn OdeSystem,
        jac: &GroupJacobian,
        t: f64,
        y: &[f64],
        h: f64,
        stats: &mut Stats,
    ) -> (f64, bool) {
        let norm = sys.step_error_norm(y, &self.y_new, &self.err, h, &self.f0, self.tol);
        let whole = (norm, norm <= 1.0 && norm.is_finite());
        let Some(p) = sys.as_partitioned() else {
            return whole;
        };
        let bs = p.body_size();
        let n = y.len() / bs.max(1);
        let mut e = vec![0.0; n];
        let mut floor = None;
        let m = ErrorMeasure {
            h,
            f0: &self.f0,
            tol: self.tol,
        };
        p.body_errors(&self.err, &m, None, &mut floor, &mut e);
        let fast: Vec<usize> = (0..n).filter(|&b| e[b].is_nan() || e[b] > 1.0).collect();
        if fast.is_empty() {
            return whole;
        }
        // The controller aims at a step that leaves REFINED_TARGET_FRACTION of the swimmers to
        // refine: the error of the swimmer at that quantile.
        let quantile = {
            let mut sorted = e.clone();
            let at = ((1.0 - REFINED_TARGET_FRACTION) * n as f64).floor() as usize;
            *sorted
                .select_nth_unstable_by(at.min(n - 1), f64::total_cmp)
                .1
        };
        let most = (MAX_REFINED_FRACTION * n as f64).floor() as usize;
        if fast.len() > most {
            return (quantile.max(1.0 + f64::EPSILON), false);
        }
        let floor = floor.unwrap_or_default();
        // The fast swimmers with their contacts, refined; around them the swimmers that read
        // them, stepped again; a ring swimmer that then misses the tolerance joins the refined.
        let worst =
            fast.iter().map(|&b| e[b]).fold(
                0.0,
                |m: f64, x| {
                    if x.is_nan() {
                        f64::INFINITY
                    } else {
                        m.max(x)
                    }
                },
            );
        let mut refined = closure(fast, jac, bs);
        let mut ring = Vec::new();
        let mut steps = 0;
        let mut settled = false;
        // The coarse step's states: refinement overwrites the refined swimmers' in `y_new`.
        let coarse = self.y_new.clone();
        // What a round keeps for the next: a group's refinement reads only the coarse step, and a
        // neighbour's read error only its refined partners' paths, so both stand until the
        // refined swimmers around them change.
        let mut kept = Rounds::default();
        let step = Coarse {
            t,
            h,
            y,
            end: &coarse,
            floor: &floor,
        };
        for _ in 0..RING_ROUNDS {
            // Swimmers that read none of each other's states take their own steps.
            self.prepare_sub(y, n);
            self.paths.clear();
            steps = 0;
            // A contact forming between a group and a swimmer outside it: both join the refined
            // swimmers and the round is taken again.
            let groups = groups_of(p, &refined);
            match self.refine_groups(p, &step, &groups, &mut kept) {
                Ok(taken) => steps = taken,
                Err(Refusal::Crossing(more)) => {
                    refined = closure(refined.into_iter().chain(more).collect(), jac, bs);
                    continue;
                }
                Err(_) => return (f64::INFINITY, false),
            }
            ring = self.ring_of(p, &step, &refined, &e, jac, &mut kept);
            if refined.len() + ring.len() > most.max(1) * 8 {
                // Stepping again a ring this large costs more than a shorter step for all: the
                // step the fast swimmers need unrefined.
                return (worst, false);
            }
            let missed = self.redo_ring(p, &step, &refined, &ring, &mut kept);
            if missed.is_empty() {
                settled = true;
                break;
            }
            refined = closure(refined.into_iter().chain(missed).collect(), jac, bs);
        }
        if !settled {
            return (f64::INFINITY, false);
        }
        stats.refined_steps += steps;
        let slow = {
            let done =
                |b: &usize| refined.binary_search(b).is_ok() || ring.binary_search(b).is_ok();
            let rest: Vec<usize> = (0..n).filter(|b| !done(b)).collect();
            let sum: f64 = rest.iter().map(|&b| e[b] * e[b]).sum();
            (sum / rest.len().max(1) as f64).sqrt()
        };
        (slow.max(quantile), slow <= 1.0)
    }
}
