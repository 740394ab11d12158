//! Fixed-step schemes for the Itô systems dy = f(t, y) dt + B(t, y) dW of thermal noise: the
//! Wiener increments every scheme draws, and Platen's explicit weak second-order scheme.
//! Euler-Maruyama is [`super::Euler`] itself: with the noise off it is forward Euler, bit for bit.

use super::philox::StepDraws;
use super::system::{
    check_state, fit, uniform_step, Noise, OdeSystem, Stats, StepFailure, Stepper,
};
use nalgebra::DMatrix;

/// The Wiener increments of step `step`: `noise.dim` independent normals of variance `h`, drawn
/// from the counter-based generator (the same for any thread count and across save and load).
pub(crate) fn wiener_increments(noise: Noise, step: u64, h: f64, dw: &mut Vec<f64>) {
    dw.resize(noise.dim, 0.0);
    StepDraws::new(noise.seed, step).normals(dw);
    let s = h.sqrt();
    dw.iter_mut().for_each(|x| *x *= s);
}

/// Platen's explicit order 2.0 weak scheme for Itô systems with many Wiener processes (Kloeden &
/// Platen, *Numerical Solution of SDEs*, 1992, eq. 15.1.3). With Ῡ = y + fh + BΔW,
/// R±ʲ = y + fh ± bʲ√h and U±ʳ = y ± bʳ√h (bʲ the j-th column of B):
///
/// y ← y + ½(f(Ῡ) + f(y))h
///   + ¼ Σⱼ [(bʲ(R+ʲ) + bʲ(R−ʲ) + 2bʲ)ΔWʲ + (bʲ(R+ʲ) − bʲ(R−ʲ))((ΔWʲ)² − h)/√h]
///   + ¼ Σⱼ Σ_{r≠j} [(bʲ(U+ʳ) + bʲ(U−ʳ) − 2bʲ)ΔWʲ + (bʲ(U+ʳ) − bʲ(U−ʳ))(ΔWʲΔWʳ + V_{rj})/√h],
///
/// V_{rj} = ±h with probability ½ each for r < j, V_{jr} = −V_{rj}. It needs B at 4m + 1 points
/// (m Wiener processes) and f at two: the derivative-free form of the weak Taylor scheme of order
/// 2, correct for noise that does not commute (B depends on the state). Without noise it is
/// Heun's method (second order).
#[derive(Debug, Clone)]
pub struct Platen {
    dt: f64,
    f0: Vec<f64>,
    f1: Vec<f64>,
    point: Vec<f64>,
    drift: Vec<f64>,
    y_new: Vec<f64>,
    dw: Vec<f64>,
    b0: DMatrix<f64>,
    bp: DMatrix<f64>,
    bm: DMatrix<f64>,
}

impl Platen {
    /// A stepper with maximum step `dt`.
    pub fn new(dt: f64) -> Self {
        Platen {
            dt,
            f0: Vec::new(),
            f1: Vec::new(),
            point: Vec::new(),
            drift: Vec::new(),
            y_new: Vec::new(),
            dw: Vec::new(),
            b0: DMatrix::zeros(0, 0),
            bp: DMatrix::zeros(0, 0),
            bm: DMatrix::zeros(0, 0),
        }
    }

    /// B at y (+ the step's drift fh when `drifted`) ± c·(column `col` of b0), into `bp` and `bm`.
    fn pair_at(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        drifted: bool,
        col: usize,
        c: f64,
    ) -> Result<(), StepFailure> {
        for (sign, plus) in [(1.0, true), (-1.0, false)] {
            for i in 0..y.len() {
                let shift = if drifted { self.drift[i] } else { 0.0 };
                self.point[i] = y[i] + shift + sign * c * self.b0[(i, col)];
            }
            let target = if plus { &mut self.bp } else { &mut self.bm };
            sys.diffusion(t, &self.point, target)
                .map_err(|problem| StepFailure { time: t, problem })?;
        }
        Ok(())
    }
}

impl Stepper for Platen {
    fn step(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &mut [f64],
        t_end: f64,
        stats: &mut Stats,
    ) -> Result<f64, StepFailure> {
        let n = y.len();
        fit(
            n,
            &mut [
                &mut self.f0,
                &mut self.f1,
                &mut self.point,
                &mut self.drift,
                &mut self.y_new,
            ],
        );
        let (h, last) = uniform_step(t, t_end, self.dt);
        let t_new = if last { t_end } else { t + h };
        sys.rhs(t, y, &mut self.f0);
        let noise = sys.noise();
        if let Some(noise) = noise {
            let m = noise.dim;
            wiener_increments(noise, stats.noisy_steps, h, &mut self.dw);
            for b in [&mut self.b0, &mut self.bp, &mut self.bm] {
                if b.shape() != (n, m) {
                    *b = DMatrix::zeros(n, m);
                }
            }
            sys.diffusion(t, y, &mut self.b0)
                .map_err(|problem| StepFailure { time: t, problem })?;
            for i in 0..n {
                let bdw: f64 = (0..m).map(|j| self.b0[(i, j)] * self.dw[j]).sum();
                self.point[i] = y[i] + h * self.f0[i] + bdw;
            }
        } else {
            for i in 0..n {
                self.point[i] = y[i] + h * self.f0[i];
            }
        }
        sys.rhs(t_new, &self.point, &mut self.f1);
        stats.rhs_evals += 2;
        for i in 0..n {
            self.y_new[i] = y[i] + 0.5 * h * (self.f0[i] + self.f1[i]);
        }
        if let Some(noise) = noise {
            let m = noise.dim;
            let sq = h.sqrt();
            let draws = StepDraws::new(noise.seed, stats.noisy_steps);
            for (d, f) in self.drift.iter_mut().zip(&self.f0) {
                *d = h * f;
            }
            // The R± terms: column j of B at y + fh ± bʲ√h.
            for j in 0..m {
                self.pair_at(sys, t, y, true, j, sq)?;
                let dwj = self.dw[j];
                for i in 0..n {
                    let (p, q, b) = (self.bp[(i, j)], self.bm[(i, j)], self.b0[(i, j)]);
                    self.y_new[i] +=
                        0.25 * (p + q + 2.0 * b) * dwj + 0.25 * (p - q) * (dwj * dwj - h) / sq;
                }
            }
            // The U± terms: every column j ≠ r of B at y ± bʳ√h.
            for r in 0..m {
                self.pair_at(sys, t, y, false, r, sq)?;
                for j in (0..m).filter(|&j| j != r) {
                    let v = if r < j {
                        h * draws.sign((r * m + j) as u64)
                    } else {
                        -h * draws.sign((j * m + r) as u64)
                    };
                    let (dwj, dwr) = (self.dw[j], self.dw[r]);
                    for i in 0..n {
                        let (p, q, b) = (self.bp[(i, j)], self.bm[(i, j)], self.b0[(i, j)]);
                        self.y_new[i] +=
                            0.25 * (p + q - 2.0 * b) * dwj + 0.25 * (p - q) * (dwj * dwr + v) / sq;
                    }
                }
            }
        }
        accept(sys, t_new, &mut self.y_new, y, stats, noise.is_some())
    }
}

/// Finish a fixed step: project and check the new state, take it, count the step (and the noise
/// draw, whose counter it advances). On `Err` the state `y` is unchanged.
pub(crate) fn accept(
    sys: &mut dyn OdeSystem,
    t_new: f64,
    y_new: &mut [f64],
    y: &mut [f64],
    stats: &mut Stats,
    noisy: bool,
) -> Result<f64, StepFailure> {
    sys.project(y_new);
    check_state(sys, t_new, y_new)?;
    y.copy_from_slice(y_new);
    stats.steps += 1;
    if noisy {
        stats.noisy_steps += 1;
    }
    Ok(t_new)
}
