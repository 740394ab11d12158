//! The suspension stepper: its state between steps, and the coarse step's attempt as the
//! adaptive controller asks for it (see the module docs of [`super`]).

use super::scratch::{Path, Pool, Refinement};
use crate::engine::integrators::controller::{self, Adaptive, Attempt, Controller, StepRule};
use crate::engine::integrators::system::{
    fit, time_derivative, GroupJacobian, OdeSystem, Stats, StepFailure, Stepper,
};

/// Adaptive ROS34PW2, implicit in the system's stiff groups, at tolerance `tol` of the system's
/// step norm.
#[derive(Debug, Clone)]
pub struct Suspension {
    pub(super) tol: f64,
    /// The first step when none is known (s).
    first_step: f64,
    control: Controller,
    /// The stiff groups' Jacobian at the step's start.
    jac: GroupJacobian,
    /// Whether the system depends on t (the stages then take ∂f/∂t, in `ft`).
    pub(super) with_ft: bool,
    pub(super) k: [Vec<f64>; 4],
    pub(super) f: Vec<f64>,
    pub(super) f0: Vec<f64>,
    pub(super) ft: Vec<f64>,
    pub(super) tmp: Vec<f64>,
    pub(super) acc: Vec<f64>,
    pub(super) y_new: Vec<f64>,
    pub(super) err: Vec<f64>,
    /// Scratch of the refinement (full length; only the refined swimmers' entries are used).
    pub(super) sub: Refinement,
    /// Scratch of refinements on rayon's threads.
    pub(super) pool: Pool,
    /// States at the step's middle and end, coarse and refined ([`Suspension::ring_of`]).
    pub(super) views: [(Vec<f64>, Vec<f64>); 2],
    /// Each group of refined swimmers' components and path across the coarse step: (time from
    /// its start, their states).
    pub(super) paths: Vec<(Vec<usize>, Path)>,
}

impl Suspension {
    /// A stepper at tolerance `tol` whose first step is `first_step` (s).
    pub fn new(tol: f64, first_step: f64) -> Self {
        Suspension {
            tol,
            first_step,
            control: Controller::adaptive(StepRule::Elementary),
            jac: GroupJacobian::default(),
            with_ft: false,
            k: Default::default(),
            f: Vec::new(),
            f0: Vec::new(),
            ft: Vec::new(),
            tmp: Vec::new(),
            acc: Vec::new(),
            y_new: Vec::new(),
            err: Vec::new(),
            sub: Refinement::default(),
            pool: Default::default(),
            views: Default::default(),
            paths: Vec::new(),
        }
    }
}

impl Adaptive for Suspension {
    fn controller(&mut self) -> &mut Controller {
        &mut self.control
    }

    /// Buffers sized to y, the rates (and unless the system is autonomous their time
    /// derivative) at (t, y), and the stiff groups there.
    fn prepare(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        stats: &mut Stats,
    ) -> Result<(), StepFailure> {
        let n = y.len();
        let [k1, k2, k3, k4] = &mut self.k;
        fit(
            n,
            &mut [
                k1,
                k2,
                k3,
                k4,
                &mut self.f,
                &mut self.f0,
                &mut self.ft,
                &mut self.tmp,
                &mut self.acc,
                &mut self.y_new,
                &mut self.err,
            ],
        );
        sys.rhs(t, y, &mut self.f0);
        stats.rhs_evals += 1;
        self.with_ft = !sys.autonomous();
        if self.with_ft {
            let h = self.control.h.unwrap_or(self.first_step);
            time_derivative(sys, t, y, h, &self.f0, &mut self.ft, stats);
        }
        self.jac = sys.stiff_groups(t, y);
        Ok(())
    }

    fn initial_step(
        &mut self,
        _sys: &mut dyn OdeSystem,
        _t: f64,
        _y: &[f64],
        _t_end: f64,
        _stats: &mut Stats,
    ) -> f64 {
        self.first_step
    }

    /// The coarse step, judged swimmer by swimmer (a few refined where that lets it stand).
    fn attempt(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        h: f64,
        stats: &mut Stats,
    ) -> Attempt {
        // The step's Jacobian, lent to the attempt (which borrows the stepper whole).
        let jac = std::mem::take(&mut self.jac);
        self.coarse(sys, &jac, t, y, h, stats);
        let (err, within) = self.judge(sys, &jac, t, y, h, stats);
        self.jac = jac;
        Attempt { err, within }
    }

    fn candidate(&mut self) -> &mut [f64] {
        &mut self.y_new
    }
}

impl Stepper for Suspension {
    fn step(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &mut [f64],
        t_end: f64,
        stats: &mut Stats,
    ) -> Result<f64, StepFailure> {
        controller::step(self, sys, t, y, t_end, stats)
    }

    fn reset(&mut self) {}
}
