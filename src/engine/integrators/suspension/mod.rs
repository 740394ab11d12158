//! `suspension(tol)`: ROS34PW2 (Rang & Angermann's Rosenbrock-W method of [`super::Rosenbrock`],
//! order 3 with an embedded order 2, L-stable) made linearly implicit in the system's sparse stiff
//! part alone ([`OdeSystem::stiff_groups`]: in a suspension the steric contacts, a few small
//! clusters) and explicit in the rest, with the system's own error norm
//! ([`OdeSystem::step_error_norm`]: each swimmer's error against its own displacement over the
//! step).
//!
//! Why this method for suspensions: the far field moves a swimmer by ~1e-4ℓ a period and changes
//! over hundreds of periods, while a steric contact relaxes at k/(6πμa) ~ 700/s, nine times a
//! period. An explicit method is held to a step within its stability bound of that rate however
//! slow the motion; a W-method keeps its order with any matrix in place of the Jacobian, so the
//! contacts' own blocks (dense LU per cluster) remove that bound while everything else stays
//! explicit and costs what an explicit stage costs. The error norm then lets the step follow the
//! slow far field: a tolerance relative to each swimmer's displacement is what a suspension's
//! structure is made of, where the default error scale of the averaged model (the closest pair's
//! drift a period) would hold every swimmer to the slowest pair's precision.
//!
//! Individual steps. A close pair or a contact sliding over the kink of the repulsion's force
//! law moves on a time scale of a period or less, while the rest of the suspension could take
//! steps of many periods. A step is therefore taken for every swimmer and judged swimmer by
//! swimmer ([`Partitioned::body_errors`]): when a few swimmers (at most [`MAX_REFINED_FRACTION`]
//! of them, each within [`MAX_REFINED_ERROR`] of the tolerance) miss it and the rest meet it,
//! the rest keep their step, and those few, with every swimmer in contact with them, are stepped
//! again across the same interval by the same method with steps of their own (adaptive, at
//! most [`MAX_SUBSTEPS`]), reading the other swimmers' states from the coarse step (quadratic
//! through its start, its end and its starting rates; their error is within the tolerance).
//! Groups of refined swimmers that read none of each other's states are stepped apart, on
//! rayon's threads when the system can give rates without changing (its neighbour lists still
//! hold the swimmers read). What the few did wrong in the coarse step reaches the rest only
//! through the far field: the neighbours whose rates change, when they read the refined path
//! instead of the coarse one, by more than [`RING_SHARE`] of the tolerance (or by more than
//! their own error leaves to it) are stepped again reading the refined path (the *ring*); a
//! contact forming between the few and the rest during the interval grows the few instead.
//! (Savcenco, Hundsdorfer & Verwer, BIT 47 (2007) 137, refine a coarse step the same way.)
//!
//! Stage equations (with k including the factor h; autonomous systems skip ∂f/∂t):
//! (I − hγJ) kᵢ = h f(t + cᵢh, y + Σⱼ aᵢⱼ kⱼ) + hJ Σⱼ γᵢⱼ kⱼ + h² γ̂ᵢ ∂f/∂t, y₁ = y + Σ bᵢ kᵢ.

use super::controller::{self, step_too_small, Adaptive, Attempt, Controller, StepRule};
use super::rosenbrock::{A, B, B_EMBEDDED, G, GAMMA};
use super::system::{fit, GroupJacobian, OdeSystem, Partitioned, Stats, StepFailure, Stepper};
use rayon::prelude::*;

mod refine;
mod ring;

use refine::{closure, groups_of, path_at};

/// The largest share of swimmers a step refines: more, and the whole step is taken again shorter.
pub const MAX_REFINED_FRACTION: f64 = 0.05;

/// The share of swimmers the step size controller aims to leave to refinement.
pub const REFINED_TARGET_FRACTION: f64 = 0.01;

/// The share of the tolerance by which reading the refined swimmers' path instead of their coarse
/// states may change a neighbour's step before the neighbour is stepped again.
pub const RING_SHARE: f64 = 0.1;

/// Rounds of refining and stepping the ring again before a step is given up (each round adds the
/// ring swimmers that missed the tolerance to the refined ones).
pub const RING_ROUNDS: usize = 4;

/// Refined groups from this many on are refined on rayon's threads (when the system allows).
pub const PARALLEL_GROUPS: usize = 2;

/// The most steps a refinement may take across one coarse step.
pub const MAX_SUBSTEPS: u32 = 100_000;

/// Adaptive ROS34PW2, implicit in the system's stiff groups, at tolerance `tol` of the system's
/// step norm.
#[derive(Debug, Clone)]
pub struct Suspension {
    tol: f64,
    /// The first step when none is known (s).
    first_step: f64,
    control: Controller,
    /// The stiff groups' Jacobian at the step's start.
    jac: GroupJacobian,
    /// Whether the system depends on t (the stages then take ∂f/∂t, in `ft`).
    with_ft: bool,
    k: [Vec<f64>; 4],
    f: Vec<f64>,
    f0: Vec<f64>,
    ft: Vec<f64>,
    tmp: Vec<f64>,
    acc: Vec<f64>,
    y_new: Vec<f64>,
    err: Vec<f64>,
    /// Scratch of the refinement (full length; only the refined swimmers' entries are used).
    sub: Refinement,
    /// Scratch of refinements on rayon's threads.
    pool: Pool,
    /// States at the step's middle and end, coarse and refined ([`Suspension::ring_of`]).
    views: [(Vec<f64>, Vec<f64>); 2],
    /// Each group of refined swimmers' components and path across the coarse step: (time from
    /// its start, their states).
    paths: Vec<(Vec<usize>, Path)>,
}

/// A refined group's path across a coarse step: (time from its start, the group's states).
type Path = Vec<(f64, Vec<f64>)>;

/// What the rounds of refining one coarse step keep for the next round.
#[derive(Default)]
struct Rounds {
    /// Each group refined so far, by its swimmers.
    groups: std::collections::HashMap<Vec<usize>, Refined>,
    /// The swimmers of the groups refined since the read errors were last found.
    changed: Vec<usize>,
    /// The neighbours' largest read errors so far (see [`Suspension::ring_of`]).
    worst: std::collections::HashMap<usize, f64>,
    /// Scratch of the read errors, by swimmer.
    read: Vec<f64>,
    /// The swimmers of the groups refined since the ring was last stepped again.
    redo_changed: Vec<usize>,
    /// Each part of the ring stepped again so far, by its swimmers: their new states (by
    /// component) and errors.
    ring: std::collections::HashMap<Vec<usize>, RingPart>,
}

/// A part of the ring stepped again: its swimmers' new states (by component) and errors.
type RingPart = (Vec<f64>, Vec<f64>);

/// Scratch of a refinement: the working state (the refined swimmers at their sub-step, the others
/// interpolated), stages and rates.
#[derive(Debug, Clone, Default)]
struct Refinement {
    yw: Vec<f64>,
    y0: Vec<f64>,
    k: [Vec<f64>; 4],
    f: Vec<f64>,
    f0: Vec<f64>,
    acc: Vec<f64>,
    y1: Vec<f64>,
    err: Vec<f64>,
    errors: Vec<f64>,
}

impl Refinement {
    /// Sized to a state of `n` components (and at least `bodies` bodies). Entries are not
    /// reset: a refinement on shared access writes every entry it reads (its bodies' and the
    /// states they read).
    fn fit(&mut self, n: usize, bodies: usize) {
        let [k1, k2, k3, k4] = &mut self.k;
        for v in [
            k1,
            k2,
            k3,
            k4,
            &mut self.yw,
            &mut self.y0,
            &mut self.f,
            &mut self.f0,
            &mut self.acc,
            &mut self.y1,
            &mut self.err,
        ] {
            v.resize(n, 0.0);
        }
        if self.errors.len() < bodies {
            self.errors.resize(bodies, 0.0);
        }
    }
}

/// Scratch for refinements on several threads (a clone starts empty).
#[derive(Debug, Default)]
struct Pool(std::sync::Mutex<Vec<Refinement>>);

impl Clone for Pool {
    fn clone(&self) -> Self {
        Pool::default()
    }
}

/// A refined group's outcome: its state components, its path across the coarse step and the
/// steps it took.
struct Refined {
    comps: Vec<usize>,
    path: Path,
    steps: u64,
}

/// Why a refinement or a subset step stopped.
#[derive(Debug)]
enum Refusal {
    /// A contact forms between the bodies stepped and others: the bodies of every such contact.
    Crossing(Vec<usize>),
    /// The steps shrank to nothing.
    Failed,
    /// The system's neighbour data must change first (read shared, it cannot).
    Relist,
}

/// How a refinement reaches the system: owned (rates through [`Partitioned::rhs_bodies`], which
/// may update the system) or shared among threads (through [`Partitioned::rates_shared`]).
enum Access<'a> {
    Own(&'a mut dyn Partitioned),
    Shared(&'a dyn Partitioned),
}

impl Access<'_> {
    fn get(&self) -> &dyn Partitioned {
        match self {
            Access::Own(p) => &**p,
            Access::Shared(p) => *p,
        }
    }

    /// The rates of `bodies` at `y` into `dy` (see [`Partitioned::rhs_bodies`]).
    fn rates(
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

    /// The coarse step h from (t, y), implicit in the stiff groups `jac`: fills y_new and err.
    fn coarse(
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
    /// The coarse step's error for the controller and whether it stands, after refining a few
    /// swimmers where that lets it stand (see the module docs).
    fn judge(
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
        p.body_errors(
            y,
            &self.y_new,
            &self.err,
            h,
            &self.f0,
            self.tol,
            None,
            &mut floor,
            &mut e,
        );
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
        for _ in 0..RING_ROUNDS {
            // Swimmers that read none of each other's states take their own steps.
            self.prepare_sub(y, n);
            self.paths.clear();
            steps = 0;
            // A contact forming between a group and a swimmer outside it: both join the refined
            // swimmers and the round is taken again.
            let groups = groups_of(p, &refined);
            match self.refine_groups(p, t, h, y, &coarse, &groups, &floor, &mut kept) {
                Ok(taken) => steps = taken,
                Err(Refusal::Crossing(more)) => {
                    refined = closure(refined.into_iter().chain(more).collect(), jac, bs);
                    continue;
                }
                Err(_) => return (f64::INFINITY, false),
            }
            ring = self.ring_of(p, h, y, &coarse, &refined, &e, &floor, jac, &mut kept);
            if refined.len() + ring.len() > most.max(1) * 8 {
                // Stepping again a ring this large costs more than a shorter step for all: the
                // step the fast swimmers need unrefined.
                return (worst, false);
            }
            let missed = self.redo_ring(p, t, h, y, &refined, &ring, &floor, &mut kept);
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

    /// One W-method step of `bodies` from `t0` by `h` from their states in `sub.y0`, the other
    /// states they read set by `read(yw, time)`, the system reached through `p`: fills `sub.y1`,
    /// `sub.err`, `sub.f0` for their components and returns the RMS of their errors, or why not
    /// (a contact forming across the edge of `bodies`; shared access that must relist first).
    #[allow(clippy::too_many_arguments)]
    fn subset_step(
        sub: &mut Refinement,
        p: &mut Access,
        tol: f64,
        t0: f64,
        h: f64,
        bodies: &[usize],
        changed: &[usize],
        floor: &[f64],
        read: &dyn Fn(&mut [f64], f64),
    ) -> Result<f64, Refusal> {
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
        p.get().body_errors(
            &sub.y0,
            &sub.y1,
            &sub.err,
            h,
            &sub.f0,
            tol,
            Some(bodies),
            &mut fl,
            &mut sub.errors,
        );
        let sum: f64 = bodies.iter().map(|&b| sub.errors[b] * sub.errors[b]).sum();
        Ok((sum / bodies.len().max(1) as f64).sqrt())
    }
}

/// Stage `i`'s argument y0 + Σ_j A_ij k_j and the Γ-combination Σ_j Γ_ij k_j of the earlier
/// stages `k`, at component `m` (state `y0` there).
#[inline]
fn stage_sums(k: &[Vec<f64>; 4], i: usize, y0: f64, m: usize) -> (f64, f64) {
    let (mut ya, mut ga) = (y0, 0.0);
    for j in 0..i {
        ya += A[i][j] * k[j][m];
        ga += G[i][j] * k[j][m];
    }
    (ya, ga)
}

/// The step's new state and its embedded error estimate at component `m` from the stages `k`.
#[inline]
fn solution(k: &[Vec<f64>; 4], y0: f64, m: usize) -> (f64, f64) {
    let (mut y1, mut e) = (y0, 0.0);
    for i in 0..4 {
        y1 += B[i] * k[i][m];
        e += (B[i] - B_EMBEDDED[i]) * k[i][m];
    }
    (y1, e)
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
            // ∂f/∂t by a forward difference (W-methods need only an approximation).
            let h = self.control.h.unwrap_or(self.first_step);
            let dt_probe = 1e-7 * (t.abs() + h).max(1e-12);
            sys.rhs(t + dt_probe, y, &mut self.ft);
            stats.rhs_evals += 1;
            for m in 0..n {
                self.ft[m] = (self.ft[m] - self.f0[m]) / dt_probe;
            }
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
