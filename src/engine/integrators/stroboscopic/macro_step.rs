//! One macro step of whole periods: Dormand-Prince 5(4) on the slopes, or the closing step by
//! Heun's method; stage states extrapolated with their fast variables set by their rates on the
//! slow manifold; the error norm relative to the change the step makes.

use super::stepper::{Slope, Stroboscopic};
use crate::engine::integrators::dopri5::{A, E};
use crate::engine::integrators::system::{check_state, OdeSystem, Stats};

/// Round-off allowance of the error estimate per period, relative to the size of a component
/// (positions: the swimmer length scale given; orientations: |b| or |N|). The differences of
/// stroboscopic points carry ~1e-16 of those sizes; 1e-15 per period leaves room and, against a
/// drift of ~1e-6 ℓ per period, limits the useful `tol` to ~1e-9.
const NOISE_PER_PERIOD: f64 = 1e-15;

/// base + h Σ_j a_j v_j, component by component.
fn extrapolate(base: &[f64], h: f64, a: &[f64], vs: &[Vec<f64>]) -> Vec<f64> {
    (0..base.len())
        .map(|i| base[i] + h * a.iter().zip(vs).map(|(aj, v)| aj * v[i]).sum::<f64>())
        .collect()
}

impl Stroboscopic {
    /// Max over 3-vectors of |err| / (tol · largest change of that kind + round-off allowance).
    ///
    /// An orientation vector's part along itself is its length: in the spring model the spring's
    /// length, a fast variable that the stages and the solution take from their rates on the slow
    /// manifold ([`OdeSystem::set_fast_variables`]), never from the slopes; in the rigid-stroke
    /// model the norm of a unit vector, which the projection restores. So errors and changes of
    /// orientations are measured across them only. Along them, a stage's length set a little off
    /// the manifold relaxes within the first sample period, and that jump, which says nothing
    /// about the slow flow, would otherwise enter every slope of the orientation and, against a
    /// small tolerance times a slow turn, fail every degree check and every macro step.
    pub(super) fn error_norm(&self, y: &[f64], y_new: &[f64], err: &[f64], m: u64) -> f64 {
        let blocks = y.len() / 3;
        let vec3 = |v: &[f64], b: usize| [v[3 * b], v[3 * b + 1], v[3 * b + 2]];
        let norm = |s: [f64; 3]| (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
        // Block b of v; an orientation block without its part along y's orientation.
        let part = |v: &[f64], b: usize| {
            let s = vec3(v, b);
            if b.is_multiple_of(2) {
                return s;
            }
            let o = vec3(y, b);
            let o2 = o[0] * o[0] + o[1] * o[1] + o[2] * o[2];
            if o2 == 0.0 {
                return s;
            }
            let along = (s[0] * o[0] + s[1] * o[1] + s[2] * o[2]) / o2;
            [
                s[0] - along * o[0],
                s[1] - along * o[1],
                s[2] - along * o[2],
            ]
        };
        let mut change = [0.0f64; 2];
        let mut size = [self.length, 0.0f64];
        let diff: Vec<f64> = y_new.iter().zip(y).map(|(a, b)| a - b).collect();
        for b in 0..blocks {
            change[b % 2] = change[b % 2].max(norm(part(&diff, b)));
            if b % 2 == 1 {
                size[1] = size[1].max(norm(vec3(y, b)));
            }
        }
        // An orientation error δ turns the drift by δ/|b|: it is measured against the larger of
        // the orientations' own change and the positions' change scaled to |b|.
        let moved = [change[0], change[1].max(change[0] * size[1] / self.length)];
        let allowance = |c: usize| self.tol * moved[c] + m as f64 * NOISE_PER_PERIOD * size[c];
        (0..blocks)
            .map(|b| norm(part(err, b)) / allowance(b % 2))
            .fold(0.0, f64::max)
    }

    /// One macro step of `m` periods from (t, y): the new state, its slope and the error norm,
    /// or `None` when a stage state failed a guard (the step is then too long).
    pub(super) fn macro_step(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        k1: &Slope,
        m: u64,
        stats: &mut Stats,
    ) -> Option<(Vec<f64>, Slope, f64)> {
        let h = m as f64 * self.period;
        let n = y.len();
        // The fast variables (springs' lengths) of the stage states are extrapolated by their
        // rates on the slow manifold, the rest of the state by the slopes.
        let mut fast0 = Vec::new();
        sys.fast_variables(y, &mut fast0);
        let mut ks: Vec<Vec<f64>> = vec![k1.0.to_vec()];
        let mut fast_rates: Vec<Vec<f64>> = vec![k1.1.to_vec()];
        for row in 1..6 {
            let a = &A[row][..row];
            let mut z = extrapolate(y, h, a, &ks);
            sys.set_fast_variables(&mut z, &extrapolate(&fast0, h, a, &fast_rates));
            let (k, r) = self.slope_at(sys, t, &z, stats).ok()?;
            ks.push(k);
            fast_rates.push(r);
        }
        // The last row is the solution (first same as last): its slope starts the next step.
        let mut y_new = extrapolate(y, h, &A[6][..6], &ks);
        sys.project(&mut y_new);
        sys.set_fast_variables(&mut y_new, &extrapolate(&fast0, h, &A[6][..6], &fast_rates));
        check_state(sys, t + h, &y_new).ok()?;
        let k_new = self.probed_slope(sys, t, &y_new, stats).ok()?;
        let err: Vec<f64> = (0..n)
            .map(|i| {
                h * E
                    .iter()
                    .zip(ks.iter().chain([&k_new.0]))
                    .map(|(ej, k)| ej * k[i])
                    .sum::<f64>()
            })
            .collect();
        let e = self.error_norm(y, &y_new, &err, m);
        Some((y_new, k_new, e))
    }

    /// The closing step of `m` periods from (t, y) by Heun's method with Euler's embedded: one
    /// new slope, at the Euler stage y + H k1, instead of Dormand-Prince's six; the new state and
    /// the error norm (of the Euler solution, H/2 |k2 − k1|, so the second-order state carried
    /// is measured conservatively), or `None` when the stage failed a guard.
    pub(super) fn heun_step(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        k1: &Slope,
        m: u64,
        stats: &mut Stats,
    ) -> Option<(Vec<f64>, f64)> {
        let h = m as f64 * self.period;
        let mut fast0 = Vec::new();
        sys.fast_variables(y, &mut fast0);
        let mut z = extrapolate(y, h, &[1.0], std::slice::from_ref(&k1.0));
        sys.set_fast_variables(
            &mut z,
            &extrapolate(&fast0, h, &[1.0], std::slice::from_ref(&k1.1)),
        );
        let (k2, r2) = self.slope_at(sys, t, &z, stats).ok()?;
        let half = [0.5, 0.5];
        let mut y_new = extrapolate(y, h, &half, &[k1.0.clone(), k2.clone()]);
        sys.project(&mut y_new);
        sys.set_fast_variables(
            &mut y_new,
            &extrapolate(&fast0, h, &half, &[k1.1.clone(), r2]),
        );
        check_state(sys, t + h, &y_new).ok()?;
        let err: Vec<f64> = k2
            .iter()
            .zip(&k1.0)
            .map(|(b, a)| 0.5 * h * (b - a))
            .collect();
        let e = self.error_norm(y, &y_new, &err, m);
        Some((y_new, e))
    }
}
