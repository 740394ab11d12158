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

use super::rosenbrock::{A, B, B_EMBEDDED, G, GAMMA};
use super::system::{
    check_state, fit, stalled, step_too_small, tolerance_failure, GroupJacobian, OdeSystem,
    Partitioned, Stats, StepFailure, Stepper,
};
use rayon::prelude::*;

const MAX_REJECTS: u32 = 60;

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
    h: Option<f64>,
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
            h: None,
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

    /// One attempt with step h from (t, y): fills y_new and err.
    #[allow(clippy::too_many_arguments)]
    fn attempt(
        &mut self,
        sys: &mut dyn OdeSystem,
        jac: &GroupJacobian,
        t: f64,
        y: &[f64],
        h: f64,
        with_ft: bool,
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
            if with_ft {
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

    /// This thread's scratch sized to the state `y`, with the working states at `y` (a
    /// refinement that relists a swimmer may read a new partner's state before it sets it).
    fn prepare_sub(&mut self, y: &[f64], bodies: usize) {
        self.sub.fit(y.len(), bodies);
        self.sub.yw.copy_from_slice(y);
        self.sub.y0.copy_from_slice(y);
    }

    /// The states of components `read` at time `t0 + θh` from the coarse step from `y`: the
    /// quadratic through y and y_new with slope f0 at the start.
    fn coarse_at(
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
    #[allow(clippy::too_many_arguments)]
    fn refine(
        sub: &mut Refinement,
        p: &mut Access,
        tol: f64,
        t: f64,
        h: f64,
        y: &[f64],
        coarse: &[f64],
        f0: &[f64],
        bodies: &[usize],
        floor: &[f64],
    ) -> Result<Refined, Refusal> {
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
            let norm =
                Self::subset_step(sub, p, tol, t + tau, h_try, bodies, &changed, floor, &at)?;
            let fac = controller_factor(norm);
            if norm <= 1.0 && norm.is_finite() {
                for &m in &comps {
                    sub.y0[m] = sub.y1[m];
                }
                tau = if last { h } else { tau + h_try };
                path.push((tau, comps.iter().map(|&m| sub.y1[m]).collect()));
                steps += 1;
                if !(last && h_try < hs) {
                    hs = h_try * fac;
                }
            } else {
                hs = h_try * fac.min(0.9);
                if step_too_small(hs, t + tau) || hs < 1e-12 * h {
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
    #[allow(clippy::too_many_arguments)]
    fn refine_groups(
        &mut self,
        p: &mut dyn Partitioned,
        t: f64,
        h: f64,
        y: &[f64],
        coarse: &[f64],
        groups: &[Vec<usize>],
        floor: &[f64],
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
                let pool = &self.pool.0;
                new.par_iter()
                    .map(|group| {
                        // Scratch from the pool (a thread working on two groups at once, as
                        // rayon may nest, takes a second).
                        let mut sub = pool
                            .lock()
                            .ok()
                            .and_then(|mut v| v.pop())
                            .unwrap_or_default();
                        let r = Self::refine(
                            &mut sub,
                            &mut Access::Shared(shared),
                            tol,
                            t,
                            h,
                            y,
                            coarse,
                            f0,
                            group,
                            floor,
                        );
                        if let Ok(mut v) = pool.lock() {
                            v.push(sub);
                        }
                        r
                    })
                    .collect()
            } else {
                new.iter().map(|_| Err(Refusal::Relist)).collect()
            };
        for (group, result) in new.iter().zip(results.iter_mut()) {
            if matches!(result, Err(Refusal::Relist)) {
                *result = Self::refine(
                    &mut self.sub,
                    &mut Access::Own(p),
                    tol,
                    t,
                    h,
                    y,
                    coarse,
                    f0,
                    group,
                    floor,
                );
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
    fn coarse_and_refined(&mut self, y: &[f64], coarse: &[f64], h: f64, comps: &[usize]) {
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

    /// The swimmers to step again around the refined ones (`refined`, their paths in
    /// `self.paths`, their coarse states in `coarse`): those whose rates change, when they read
    /// the refined path instead of the coarse one (at the step's middle and end), by more than
    /// [`RING_SHARE`] of the tolerance, or by more than their coarse error `e` leaves to it; with
    /// every swimmer in a stiff group of `jac` with one of them, none refined. Read errors found
    /// in an earlier round (`kept`) stand for swimmers none of whose partners were refined anew
    /// (`kept.changed`).
    #[allow(clippy::too_many_arguments)]
    fn ring_of(
        &mut self,
        p: &dyn Partitioned,
        h: f64,
        y: &[f64],
        coarse: &[f64],
        refined: &[usize],
        e: &[f64],
        floor: &[f64],
        jac: &GroupJacobian,
        kept: &mut Rounds,
    ) -> Vec<usize> {
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
            p.read_errors(
                before,
                after,
                &anew,
                refined,
                h,
                &self.f0,
                self.tol,
                floor,
                &mut kept.read,
            );
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
    #[allow(clippy::too_many_arguments)]
    fn redo_ring(
        &mut self,
        p: &mut dyn Partitioned,
        t: f64,
        h: f64,
        y: &[f64],
        refined: &[usize],
        ring: &[usize],
        floor: &[f64],
        kept: &mut Rounds,
    ) -> Vec<usize> {
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
        let mut results: Vec<Result<RingPart, Refusal>> =
            if todo.len() >= PARALLEL_GROUPS && p.shares_rates() {
                let shared: &dyn Partitioned = p;
                let pool = &self.pool.0;
                todo.par_iter()
                    .map(|part| {
                        let mut sub = pool
                            .lock()
                            .ok()
                            .and_then(|mut v| v.pop())
                            .unwrap_or_default();
                        let r = ctx.step_part(&mut sub, &mut Access::Shared(shared), part);
                        if let Ok(mut v) = pool.lock() {
                            v.push(sub);
                        }
                        r
                    })
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
        Suspension::subset_step(sub, access, self.tol, t, h, part, &changed, self.floor, &at)?;
        let states = comps().map(|m| sub.y1[m]).collect();
        let errors = part.iter().map(|&b| sub.errors[b]).collect();
        Ok((states, errors))
    }
}

/// A refined path's states at time `tau` from the coarse step's start: linear between its steps.
fn path_at(path: &Path, tau: f64) -> impl Iterator<Item = f64> + '_ {
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

/// The groups of `bodies` (sorted) that read one another's states, directly or through others of
/// them: connected sets under [`Partitioned::partners`].
fn groups_of(p: &dyn Partitioned, bodies: &[usize]) -> Vec<Vec<usize>> {
    let mut parent: Vec<usize> = (0..bodies.len()).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
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
fn closure(mut bodies: Vec<usize>, jac: &GroupJacobian, bs: usize) -> Vec<usize> {
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

/// The step-size factor after an attempt of error norm `err` (order 3 with an embedded 2): 0.9
/// err^(−1/3), within 0.2 and 5.
fn controller_factor(err: f64) -> f64 {
    if err.is_finite() && err > 0.0 {
        (0.9 * err.powf(-1.0 / 3.0)).clamp(0.2, 5.0)
    } else if err == 0.0 {
        5.0
    } else {
        0.2
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
        let with_ft = !sys.autonomous();
        if with_ft {
            // ∂f/∂t by a forward difference (W-methods need only an approximation).
            let dt_probe = 1e-7 * (t.abs() + self.h.unwrap_or(self.first_step)).max(1e-12);
            sys.rhs(t + dt_probe, y, &mut self.ft);
            stats.rhs_evals += 1;
            for m in 0..n {
                self.ft[m] = (self.ft[m] - self.f0[m]) / dt_probe;
            }
        }
        let jac = sys.stiff_groups(t, y);
        let mut h = self.h.unwrap_or(self.first_step);
        let mut rejects = 0;
        loop {
            let span = t_end - t;
            let (h_try, last) = if h >= span { (span, true) } else { (h, false) };
            self.attempt(sys, &jac, t, y, h_try, with_ft, stats);
            let (err, accept) = self.judge(sys, &jac, t, y, h_try, stats);
            let t_new = if last { t_end } else { t + h_try };
            let guard = if accept {
                sys.project(&mut self.y_new);
                check_state(sys, t_new, &self.y_new)
            } else {
                Ok(())
            };
            let fac = controller_factor(err);
            match (accept, guard) {
                (true, Ok(())) => {
                    y.copy_from_slice(&self.y_new);
                    stats.steps += 1;
                    let h_next = h_try * fac;
                    // A step clipped to land on t_end says nothing about the natural step size.
                    self.h = Some(if last && h_try < h {
                        h.max(h_next)
                    } else {
                        h_next
                    });
                    return Ok(t_new);
                }
                (true, Err(failure)) => {
                    stats.rejected += 1;
                    stats.rejected_by_guard += 1;
                    rejects += 1;
                    if rejects >= MAX_REJECTS {
                        return Err(failure);
                    }
                    h = h_try * 0.25;
                    // Crawling towards the event the guard refuses: stop with it once the step no
                    // longer advances the time.
                    if step_too_small(h, t) {
                        self.h = Some(h_try);
                        return Err(failure);
                    }
                }
                (false, _) => {
                    stats.rejected += 1;
                    rejects += 1;
                    if rejects >= MAX_REJECTS {
                        return Err(tolerance_failure(t_new, h_try, MAX_REJECTS));
                    }
                    h = h_try * fac.min(0.9);
                    if step_too_small(h, t) {
                        return Err(stalled(t_new, h));
                    }
                }
            }
        }
    }

    fn reset(&mut self) {}
}
