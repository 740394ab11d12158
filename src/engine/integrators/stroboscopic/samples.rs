//! The slopes of the averaged flow from stroboscopic points: the derivative at 0 of the
//! polynomial through them.

use super::Slope;

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
