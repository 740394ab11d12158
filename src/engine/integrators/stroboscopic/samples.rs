//! The slopes of the averaged flow from stroboscopic points: the derivative at 0 of the
//! polynomial through them.

use super::stepper::{Slope, Stroboscopic};
use crate::engine::integrators::system::{OdeSystem, Stats, StepFailure};

/// Highest degree of a slope's interpolating polynomial (samples a slope may take).
pub const MAX_DEGREE: usize = 6;

/// The share of the tolerance a slope's own error may take (in the macro error norm).
const SLOPE_ERROR_SHARE: f64 = 0.1;

/// Stroboscopic points Ψ¹(y), Ψ²(y), … of a state y, kept as differences from y (their sums
/// then cancel no large positions), with their fast variables.
pub(super) struct Samples {
    pub(super) y: Vec<f64>,
    /// The last point reached.
    pub(super) z: Vec<f64>,
    pub(super) diffs: Vec<Vec<f64>>,
    pub(super) fast: Vec<Vec<f64>>,
}

impl Samples {
    pub(super) fn new(y: &[f64]) -> Self {
        Samples {
            y: y.to_vec(),
            z: y.to_vec(),
            diffs: Vec::new(),
            fast: Vec::new(),
        }
    }

    /// The slope of degree `d` (≤ the samples taken) and the fast rates from the points 1 … d.
    pub(super) fn slope(&self, period: f64, d: usize) -> Slope {
        let w = derivative_weights(&(0..=d).map(|j| j as f64).collect::<Vec<_>>());
        let n = self.y.len();
        let slope = (0..n)
            .map(|i| (1..=d).map(|j| w[j] * self.diffs[j - 1][i]).sum::<f64>() / period)
            .collect();
        let w = derivative_weights(&(1..=d).map(|j| j as f64).collect::<Vec<_>>());
        let rates = (0..self.fast[0].len())
            .map(|i| (0..d).map(|j| w[j] * self.fast[j][i]).sum::<f64>() / period)
            .collect();
        (slope, rates)
    }
}

impl Stroboscopic {
    /// `periods` stroboscopic periods of `y` from the phase of time `t` (the run's own time is not
    /// changed: Ψ depends on the phase only).
    pub(super) fn psi(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &mut [f64],
        periods: u32,
        stats: &mut Stats,
    ) -> Result<(), StepFailure> {
        for k in 0..periods {
            let (a, b) = (t + k as f64 * self.period, t + (k + 1) as f64 * self.period);
            self.direct(sys, a, y, b, stats, false)?;
            stats.micro_periods += 1;
        }
        Ok(())
    }

    /// The slope of the averaged flow at `y` (phase of `t`) from the stroboscopic points y, Ψ(y),
    /// …, Ψ^d(y), d = the current degree: the derivative at 0 of the polynomial through them
    /// (order d in T); and the fast variables' rates on the slow manifold, the derivative at 0 of
    /// the polynomial through their values at Ψ … Ψ^d, free of whatever y's own fast variables had
    /// to relax.
    pub(super) fn slope_at(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        stats: &mut Stats,
    ) -> Result<Slope, StepFailure> {
        let s = self.samples(sys, t, y, self.degree, stats)?;
        Ok(s.slope(self.period, self.degree))
    }

    /// [`Stroboscopic::slope_at`] that also chooses the degree. The slope of degree d − 1 differs
    /// from that of degree d by about its own error (the series in T/τ, τ the slow time, converges
    /// fast: each degree gains a large factor; the book's design notes). The degree is the lowest,
    /// from one below the current one, whose slope's error so estimated stays within a tenth of
    /// the tolerance in the macro error norm (relative to the drift); the slope returned is the
    /// better one of the pair. Up to [`MAX_DEGREE`].
    pub(super) fn probed_slope(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        stats: &mut Stats,
    ) -> Result<Slope, StepFailure> {
        let lowest = self.degree.saturating_sub(1).max(2);
        let mut s = self.samples(sys, t, y, lowest + 1, stats)?;
        loop {
            let d = s.diffs.len();
            let (hi, below) = (s.slope(self.period, d), s.slope(self.period, d - 1));
            let y_next: Vec<f64> = y
                .iter()
                .zip(&hi.0)
                .map(|(v, k)| v + self.period * k)
                .collect();
            let diff: Vec<f64> =
                hi.0.iter()
                    .zip(&below.0)
                    .map(|(a, b)| self.period * (a - b))
                    .collect();
            if self.error_norm(y, &y_next, &diff, 1) <= SLOPE_ERROR_SHARE || d > MAX_DEGREE {
                self.degree = d - 1;
                return Ok(hi);
            }
            self.sample(sys, t, &mut s, stats)?;
        }
    }

    /// The first `n` stroboscopic points of `y`.
    fn samples(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        n: usize,
        stats: &mut Stats,
    ) -> Result<Samples, StepFailure> {
        let mut s = Samples::new(y);
        for _ in 0..n {
            self.sample(sys, t, &mut s, stats)?;
        }
        Ok(s)
    }

    /// One more stroboscopic point of `s`.
    fn sample(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        s: &mut Samples,
        stats: &mut Stats,
    ) -> Result<(), StepFailure> {
        // Ψ depends on the phase only: each period starts at the phase of t.
        self.psi(sys, t, &mut s.z, 1, stats)?;
        s.diffs
            .push(s.z.iter().zip(&s.y).map(|(a, b)| a - b).collect());
        let mut fast = Vec::new();
        sys.fast_variables(&s.z, &mut fast);
        s.fast.push(fast);
        Ok(())
    }
}

/// Weights w_j with p'(0) = Σ w_j p(x_j) for every polynomial p of degree < the number of
/// distinct nodes x_j (the derivatives at 0 of the Lagrange basis polynomials).
fn derivative_weights(x: &[f64]) -> Vec<f64> {
    (0..x.len())
        .map(|j| {
            // l_j'(0) = Σ_{k≠j} 1/(x_j − x_k) Π_{m≠j,k} (0 − x_m)/(x_j − x_m)
            (0..x.len())
                .filter(|&k| k != j)
                .map(|k| {
                    (0..x.len())
                        .filter(|&m| m != j && m != k)
                        .fold(1.0 / (x[j] - x[k]), |p, m| p * (-x[m]) / (x[j] - x[m]))
                })
                .sum()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::derivative_weights;

    /// The derivative weights at 0: the quadratic through 0, 1, 2 gives the classic
    /// (−3, 4, −1)/2, the line through 1, 2 gives (−1, 1), and the cubic through 0 … 3 is exact
    /// for t³ (derivative 0) and t (derivative 1).
    #[test]
    fn derivative_weights_at_zero() {
        let close = |a: &[f64], b: &[f64]| {
            assert!(
                a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-14),
                "{a:?} against {b:?}"
            );
        };
        close(&derivative_weights(&[0.0, 1.0, 2.0]), &[-1.5, 2.0, -0.5]);
        close(&derivative_weights(&[1.0, 2.0]), &[-1.0, 1.0]);
        let x = [0.0, 1.0, 2.0, 3.0];
        let w = derivative_weights(&x);
        let d = |f: fn(f64) -> f64| w.iter().zip(&x).map(|(w, x)| w * f(*x)).sum::<f64>();
        assert!(d(|t| t * t * t).abs() < 1e-13 && (d(|t| t) - 1.0).abs() < 1e-13);
    }
}
