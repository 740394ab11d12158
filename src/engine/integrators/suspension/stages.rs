//! The W-method's stages: the coarse step of every swimmer, and a step of a subset of them
//! reading the others from a given path (refinement, the ring).

use super::refine::{Access, Refusal};
use super::scratch::{Refinement, SubsetStep};
use super::stepper::Suspension;
use crate::engine::integrators::rosenbrock::{solution, stage_sums, A, G, GAMMA};
use crate::engine::integrators::system::{ErrorMeasure, GroupJacobian, OdeSystem, Stats};

impl Suspension {
    /// The coarse step h from (t, y), implicit in the stiff groups `jac`: fills y_new and err.
    pub(super) fn coarse(
        &mut self,
        sys: &mut dyn OdeSystem,
        jac: &GroupJacobian,
        t: f64,
        y: &[f64],
        h: f64,
        stats: &mut Stats,
    ) {
        let n = y.len();
        let lus = jac.factor_shifted(h * GAMMA);
        for i in 0..4 {
            // Stage argument, and h times the Γ-combination of the earlier stages.
            for m in 0..n {
                let (ya, ga) = stage_sums(&self.k, i, y[m], m);
                self.tmp[m] = ya;
                self.acc[m] = h * ga;
            }
            if i == 0 {
                self.f.copy_from_slice(&self.f0);
            } else {
                let c: f64 = A[i].iter().sum();
                sys.rhs(t + c * h, &self.tmp, &mut self.f);
                stats.rhs_evals += 1;
            }
            let gh = GAMMA + G[i].iter().sum::<f64>();
            let k = &mut self.k[i];
            for m in 0..n {
                k[m] = h * self.f[m];
            }
            if self.with_ft {
                for m in 0..n {
                    k[m] += h * h * gh * self.ft[m];
                }
            }
            jac.add_product(&self.acc, k);
            jac.solve_shifted(&lus, k);
        }
        for m in 0..n {
            (self.y_new[m], self.err[m]) = solution(&self.k, y[m], m);
        }
    }
}
impl Suspension {
    /// One W-method step of `step.bodies` from `step.t0` by `step.h` from their states in
    /// `sub.y0`, the other states they read set by `read(yw, time)`, the system reached through
    /// `p`: fills `sub.y1`, `sub.err`, `sub.f0` for their components and returns the RMS of their
    /// errors, or why not (a contact forming across the edge of `bodies`; shared access that must
    /// relist first).
    pub(super) fn subset_step(
        sub: &mut Refinement,
        p: &mut Access,
        step: &SubsetStep,
        read: &dyn Fn(&mut [f64], f64),
    ) -> Result<f64, Refusal> {
        let SubsetStep {
            t0,
            h,
            tol,
            bodies,
            changed,
            floor,
        } = *step;
        let bs = p.get().body_size();
        let comps = || bodies.iter().flat_map(move |&b| b * bs..(b + 1) * bs);
        for m in comps() {
            sub.yw[m] = sub.y0[m];
        }
        read(&mut sub.yw, t0);
        p.rates(t0, &sub.yw, bodies, changed, &mut sub.f0)?;
        let jac = p
            .get()
            .stiff_groups_of(t0, &sub.yw, bodies)
            .map_err(Refusal::Crossing)?;
        let lus = jac.factor_shifted(h * GAMMA);
        for i in 0..4 {
            for m in comps() {
                let (ya, ga) = stage_sums(&sub.k, i, sub.y0[m], m);
                sub.yw[m] = ya;
                sub.acc[m] = h * ga;
            }
            if i == 0 {
                for m in comps() {
                    sub.f[m] = sub.f0[m];
                }
            } else {
                let c: f64 = A[i].iter().sum();
                read(&mut sub.yw, t0 + c * h);
                p.rates(t0 + c * h, &sub.yw, bodies, changed, &mut sub.f)?;
            }
            let k = &mut sub.k[i];
            for m in comps() {
                k[m] = h * sub.f[m];
            }
            jac.add_product(&sub.acc, k);
            jac.solve_shifted(&lus, k);
        }
        for m in comps() {
            (sub.y1[m], sub.err[m]) = solution(&sub.k, sub.y0[m], m);
        }
        let mut fl = Some(floor.to_vec());
        let m = ErrorMeasure {
            h,
            f0: &sub.f0,
            tol,
        };
        p.get()
            .body_errors(&sub.err, &m, Some(bodies), &mut fl, &mut sub.errors);
        let sum: f64 = bodies.iter().map(|&b| sub.errors[b] * sub.errors[b]).sum();
        Ok((sum / bodies.len().max(1) as f64).sqrt())
    }
}
