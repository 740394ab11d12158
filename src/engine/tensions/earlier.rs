//! The tensions of the last solves, extrapolated in time to the next iteration's start.

use nalgebra::DVector;

/// Solves whose tensions the next iteration's start is extrapolated from (quadratically).
const EXTRAPOLATED_FROM: usize = 3;

/// The largest weight an extrapolation may give one earlier solve: beyond it the times lie too
/// close together for the distance asked (the start would amplify their own residuals), and
/// fewer of them, down to the last tensions alone, are taken.
const MAX_EXTRAPOLATION_WEIGHT: f64 = 8.0;

/// The tensions of the last solves and their times, oldest first: the iteration's start is their
/// polynomial in time at the new solve's time. The tensions follow each stroke's rate, smooth in
/// t, so between a run's stages (a fraction of a period apart) the quadratic through three solves
/// lies far closer to the new tensions than the last alone, and the iteration, which stops at a
/// residual relative to the right side, needs fewer products to get there.
#[derive(Debug, Clone, Default)]
pub(super) struct PastTensions {
    times: Vec<f64>,
    tensions: Vec<DVector<f64>>,
}

impl PastTensions {
    /// Keep `x`, solved at `t`, dropping the oldest beyond [`EXTRAPOLATED_FROM`] (a solve at
    /// the newest one's time replaces it).
    pub(super) fn push(&mut self, t: f64, x: &DVector<f64>) {
        if self.times.last() == Some(&t) {
            self.times.pop();
            self.tensions.pop();
        }
        let mut v = if self.times.len() >= EXTRAPOLATED_FROM {
            self.times.remove(0);
            self.tensions.remove(0)
        } else {
            DVector::zeros(x.len())
        };
        v.copy_from(x);
        self.times.push(t);
        self.tensions.push(v);
    }

    pub(super) fn clear(&mut self) {
        self.times.clear();
        self.tensions.clear();
    }

    /// The polynomial through the newest solves at `t` into `x`: as many of them (from
    /// [`EXTRAPOLATED_FROM`] down to one) as keep every weight within
    /// [`MAX_EXTRAPOLATION_WEIGHT`]. False (x untouched) if there are none.
    pub(super) fn extrapolate(&self, t: f64, x: &mut DVector<f64>) -> bool {
        let n = self.times.len();
        for m in (1..=n).rev() {
            let ts = &self.times[n - m..];
            let weights: Vec<f64> = (0..m)
                .map(|i| {
                    (0..m)
                        .filter(|&j| j != i)
                        .map(|j| (t - ts[j]) / (ts[i] - ts[j]))
                        .product()
                })
                .collect();
            if weights
                .iter()
                .all(|w| w.is_finite() && w.abs() <= MAX_EXTRAPOLATION_WEIGHT)
            {
                x.fill(0.0);
                for (w, v) in weights.iter().zip(&self.tensions[n - m..]) {
                    x.axpy(*w, v, 1.0);
                }
                return true;
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The start is the polynomial through the earlier solves: exact on a quadratic in t from
    /// three solves (to rounding, 1e-12 of its values ~1), the last tensions alone where the
    /// times are too close for the distance asked (weights beyond the bound), a solve at the
    /// newest time replacing it, and nothing from no solves.
    #[test]
    fn the_start_is_extrapolated_from_the_earlier_solves() {
        let f = |t: f64| DVector::from_vec(vec![1.0 + 2.0 * t - 3.0 * t * t, -0.5 * t * t]);
        let mut e = PastTensions::default();
        let mut x = DVector::zeros(2);
        assert!(!e.extrapolate(0.3, &mut x));
        for t in [0.0, 0.1, 0.2] {
            e.push(t, &f(t));
        }
        for t in [0.25, 0.35, 0.15] {
            assert!(e.extrapolate(t, &mut x));
            assert!((&x - f(t)).amax() < 1e-12, "t {t}: {x} vs {}", f(t));
        }
        // Far beyond the solves' span the quadratic's weights exceed the bound, and the linear
        // one's too: the last tensions.
        assert!(e.extrapolate(5.0, &mut x));
        assert_eq!(x, f(0.2));
        // A solve at the newest time replaces it; the oldest drops out beyond three.
        e.push(0.2, &f(0.2));
        e.push(0.3, &f(0.3));
        assert_eq!(e.times, vec![0.1, 0.2, 0.3]);
        assert!(e.extrapolate(0.4, &mut x));
        assert!((&x - f(0.4)).amax() < 1e-12);
    }
}
