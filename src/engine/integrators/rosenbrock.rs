//! ROS34PW2 (Rang & Angermann, BIT 45, 2005): a 4-stage, third-order, L-stable Rosenbrock-W method
//! with an embedded second-order solution, for stiff systems.
//!
//! A W-method keeps its order with *any* matrix in place of the Jacobian. swimlab uses that: the
//! models offer the block-diagonal part of ∂f/∂y that holds the stiffness (each dumbbell's own
//! spring, drag and hydrodynamics, [`OdeSystem::jacobian_blocks`]), and the hydrodynamic coupling
//! between dumbbells stays explicit. A step then costs four right-hand sides (O(S²)), one more for
//! ∂f/∂t, the blocks by finite differences of each dumbbell alone (O(S)), and S small LU solves per
//! stage (O(S)): no dense 6S×6S algebra, and no step limit from the spring. The adaptive
//! controller drives it with the elementary rule of an order-3 pair.
//!
//! Stage equations (Hairer & Wanner, IV.7, with k including the factor h):
//! (I − hγJ) kᵢ = h f(t + cᵢh, y + Σⱼ aᵢⱼ kⱼ) + hJ Σⱼ γᵢⱼ kⱼ + h² γ̂ᵢ ∂f/∂t, y₁ = y + Σ bᵢ kᵢ.

use super::controller::{self, Adaptive, Attempt, Controller, StepRule};
use super::system::{fit, time_derivative, OdeSystem, Problem, Stats, StepFailure, Stepper};
use nalgebra::{DMatrix, DVector};

pub(super) const GAMMA: f64 = 4.358_665_215_084_59e-1;
pub(super) const A: [[f64; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [8.717_330_430_169_18e-1, 0.0, 0.0],
    [8.445_706_001_536_942e-1, -1.129_906_423_648_418_5e-1, 0.0],
    [0.0, 0.0, 1.0],
];
/// Off-diagonal Γ (the diagonal is GAMMA).
pub(super) const G: [[f64; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [-8.717_330_430_169_18e-1, 0.0, 0.0],
    [-9.033_805_701_304_408e-1, 5.418_067_238_809_533e-2, 0.0],
    [
        2.421_238_070_609_534_6e-1,
        -1.223_250_583_904_514_7,
        5.452_602_553_351_021e-1,
    ],
];
const B: [f64; 4] = [
    2.421_238_070_609_534_6e-1,
    -1.223_250_583_904_514_7,
    1.545_260_255_335_102,
    4.358_665_215_084_59e-1,
];
const B_EMBEDDED: [f64; 4] = [
    3.781_090_314_581_937e-1,
    -9.604_229_221_242_318e-2,
    0.5,
    2.179_332_607_542_295e-1,
];
/// Stage `i`'s argument y0 + Σ_j A_ij k_j and the Γ-combination Σ_j Γ_ij k_j of the earlier
/// stages `k`, at component `m` (state `y0` there).
#[inline]
pub(super) fn stage_sums(k: &[Vec<f64>; 4], i: usize, y0: f64, m: usize) -> (f64, f64) {
    let (mut ya, mut ga) = (y0, 0.0);
    for j in 0..i {
        ya += A[i][j] * k[j][m];
        ga += G[i][j] * k[j][m];
    }
    (ya, ga)
}

/// The step's new state and its embedded error estimate at component `m` from the stages `k`.
#[inline]
pub(super) fn solution(k: &[Vec<f64>; 4], y0: f64, m: usize) -> (f64, f64) {
    let (mut y1, mut e) = (y0, 0.0);
    for i in 0..4 {
        y1 += B[i] * k[i][m];
        e += (B[i] - B_EMBEDDED[i]) * k[i][m];
    }
    (y1, e)
}

/// Adaptive ROS34PW2 with relative tolerance `rtol` (against [`OdeSystem::error_scale`]), or with
/// fixed steps for convergence studies.
#[derive(Debug, Clone)]
pub struct Rosenbrock {
    rtol: f64,
    control: Controller,
    /// Size of the system's Jacobian blocks at this step (0: none).
    bs: usize,
    k: [Vec<f64>; 4],
    f: Vec<f64>,
    f0: Vec<f64>,
    ft: Vec<f64>,
    tmp: Vec<f64>,
    acc: Vec<f64>,
    y_new: Vec<f64>,
    scale: Vec<f64>,
    jac: Vec<f64>,
    /// LU factors of W = I − hγJ per block, for the step size being tried.
    lus: Vec<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>>,
    /// One block's right-hand side, solved in place (no allocation per stage).
    block: DVector<f64>,
}

impl Rosenbrock {
    /// An adaptive stepper with relative tolerance `rtol`.
    pub fn new(rtol: f64) -> Self {
        Rosenbrock {
            rtol,
            control: Controller::adaptive(StepRule::Elementary),
            bs: 0,
            k: Default::default(),
            f: Vec::new(),
            f0: Vec::new(),
            ft: Vec::new(),
            tmp: Vec::new(),
            acc: Vec::new(),
            y_new: Vec::new(),
            scale: Vec::new(),
            jac: Vec::new(),
            lus: Vec::new(),
            block: DVector::zeros(0),
        }
    }

    /// Fixed steps of at most `dt`, no error control (for order studies).
    pub fn fixed_step(dt: f64) -> Self {
        Rosenbrock {
            control: Controller::fixed(StepRule::Elementary, dt),
            ..Rosenbrock::new(1.0)
        }
    }

    /// The stages of a step h from (t, y) with W factored for h: fills y_new, returns the error
    /// norm.
    fn stages(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        h: f64,
        stats: &mut Stats,
    ) -> f64 {
        let (n, bs) = (y.len(), self.bs);
        let gamma_hat = |i: usize| GAMMA + G[i].iter().sum::<f64>();
        let c = |i: usize| A[i].iter().sum::<f64>();
        for i in 0..4 {
            // Stage argument and Γ-combination of the earlier stages.
            for m in 0..n {
                (self.tmp[m], self.acc[m]) = stage_sums(&self.k, i, y[m], m);
            }
            if i == 0 {
                self.f.copy_from_slice(&self.f0);
            } else {
                sys.rhs(t + c(i) * h, &self.tmp, &mut self.f);
                stats.rhs_evals += 1;
            }
            // rhs = h f + h J acc + h² γ̂ᵢ f_t, then solve blockwise with W = I − hγJ.
            let gh = gamma_hat(i);
            for blk in 0..(n.checked_div(bs).unwrap_or(0)) {
                let o = blk * bs;
                let jb = &self.jac[blk * bs * bs..(blk + 1) * bs * bs];
                for r in 0..bs {
                    let mut jv = 0.0;
                    for q in 0..bs {
                        jv += jb[r * bs + q] * self.acc[o + q];
                    }
                    self.block[r] = h * self.f[o + r] + h * jv + h * h * gh * self.ft[o + r];
                }
                if !self.lus[blk].solve_mut(&mut self.block) {
                    self.block.fill(f64::NAN);
                }
                self.k[i][o..o + bs].copy_from_slice(self.block.as_slice());
            }
            if bs == 0 {
                for m in 0..n {
                    self.k[i][m] = h * self.f[m] + h * h * gh * self.ft[m];
                }
            }
        }
        let mut err = 0.0;
        for m in 0..n {
            let e;
            (self.y_new[m], e) = solution(&self.k, y[m], m);
            let r = e / (self.rtol * self.scale[m]);
            err += r * r;
        }
        (err / n.max(1) as f64).sqrt()
    }
}

impl Adaptive for Rosenbrock {
    fn controller(&mut self) -> &mut Controller {
        &mut self.control
    }

    /// Buffers sized to y, the error scale, the rates and their time derivative at (t, y), and
    /// the Jacobian blocks there.
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
                &mut self.scale,
            ],
        );
        let bs = sys.jacobian_block();
        self.bs = bs;
        if self.block.len() != bs {
            self.block = DVector::zeros(bs);
        }
        if bs > 0 && !n.is_multiple_of(bs) {
            return Err(StepFailure {
                time: t,
                problem: Problem {
                    swimmer: None,
                    cause: format!("Jacobian blocks of size {bs} do not tile a state of size {n}"),
                    hint: "this is a bug in the model; use rk4 or dopri5 meanwhile".into(),
                    fixes: Vec::new(),
                },
            });
        }
        sys.error_scale(y, &mut self.scale);
        sys.rhs(t, y, &mut self.f0);
        stats.rhs_evals += 1;
        let h = self.control.h.unwrap_or(1e-6);
        time_derivative(sys, t, y, h, &self.f0, &mut self.ft, stats);
        self.jac.resize(if bs > 0 { n * bs } else { 0 }, 0.0);
        if bs > 0 {
            sys.jacobian_blocks(t, y, &mut self.jac);
        }
        Ok(())
    }

    fn initial_step(
        &mut self,
        _sys: &mut dyn OdeSystem,
        t: f64,
        _y: &[f64],
        t_end: f64,
        _stats: &mut Stats,
    ) -> f64 {
        (t_end - t).min(1e-3 * (t_end - t).max(1e-9))
    }

    fn attempt(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        h: f64,
        stats: &mut Stats,
    ) -> Attempt {
        let (n, bs) = (y.len(), self.bs);
        self.lus = (0..n.checked_div(bs).unwrap_or(0))
            .map(|blk| {
                let jb = &self.jac[blk * bs * bs..(blk + 1) * bs * bs];
                let w = DMatrix::from_fn(bs, bs, |r, q| {
                    f64::from(u8::from(r == q)) - h * GAMMA * jb[r * bs + q]
                });
                w.lu()
            })
            .collect();
        Attempt::of_norm(self.stages(sys, t, y, h, stats))
    }

    fn candidate(&mut self) -> &mut [f64] {
        &mut self.y_new
    }
}

impl Stepper for Rosenbrock {
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
}
