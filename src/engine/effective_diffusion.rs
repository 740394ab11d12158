//! Effective diffusion coefficients from recorded series, with their standard errors: the
//! translational one from a mean squared displacement, MSD(t) = 2 d D t in d dimensions, and the
//! rotational one from an orientation autocorrelation, C_l(t) = e^{−l(l+1) D_r t}.
//!
//! The estimator: the window's rows are cut into B blocks of (nearly) equal numbers of rows, each
//! block gives a slope, ΔMSD / (2 d Δt) or −Δln C_l / (l(l+1) Δt), and D is the mean of the B
//! slopes with standard error sd/√B (B − 1 degrees of freedom). A slope over a difference needs
//! no t0, so a transient or a ballistic start before the window drops out. The error holds when
//! the block slopes are uncorrelated: for free diffusion exactly (|R − R0|² − 2 d D t and
//! e^{l(l+1) D_r t} C_l are martingales, whose increments over disjoint blocks are uncorrelated;
//! ln C_l to first order in the noise), and for a swimmer whose motion is persistent once the
//! blocks are longer than its persistence time (1/(2 D_r) for a swimmer turned by noise).
//! Independent runs give independent estimates: their mean and its standard error are the
//! ensemble's.

use super::error::{invalid, Result};

/// What a recorded series measures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Series {
    /// A mean squared displacement in `dims` dimensions (m²): MSD = 2 dims D t.
    Msd {
        /// 1, 2 or 3.
        dims: usize,
    },
    /// An orientation autocorrelation of order `order` (1 or 2): C = e^{−l(l+1) D_r t}.
    Orientation {
        /// l: 1 for ⟨N·N0⟩, 2 for ⟨P2(N·N0)⟩.
        order: u8,
    },
}

/// The most blocks a window is cut into by default.
pub const DEFAULT_BLOCKS: usize = 10;

/// An effective diffusion coefficient from a window of a series.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// D (m²/s) or D_r (1/s): the mean of the block slopes.
    pub value: f64,
    /// Its standard error, sd of the slopes / √B.
    pub error: f64,
    /// Each block's slope.
    pub slopes: Vec<f64>,
    /// The window's first and last recorded times (s).
    pub from: f64,
    /// See `from`.
    pub to: f64,
}

/// D from `times` (s, increasing) and `values` of `series`, over the rows with from ≤ t ≤ to
/// (all rows where a bound is `None`), cut into `blocks` blocks (default: [`DEFAULT_BLOCKS`], or
/// one row interval each when the window has fewer).
pub fn estimate(
    times: &[f64],
    values: &[f64],
    series: Series,
    from: Option<f64>,
    to: Option<f64>,
    blocks: Option<usize>,
) -> Result<Estimate> {
    if times.len() != values.len() {
        return Err(invalid!(
            "the diffusion estimate needs one value per time, got {} times and {} values",
            times.len(),
            values.len()
        ));
    }
    if let Some(k) = (0..times.len()).find(|&k| !(times[k].is_finite() && values[k].is_finite())) {
        return Err(invalid!(
            "row {k} of the series is not finite (t = {}, value {}); give finite numbers",
            times[k],
            values[k]
        ));
    }
    if let Some(k) = (1..times.len()).find(|&k| times[k] <= times[k - 1]) {
        return Err(invalid!(
            "the times must increase, and row {k} (t = {:e} s) does not come after row {} (t = {:e} s)",
            times[k],
            k - 1,
            times[k - 1]
        ));
    }
    let (rate, what) = match series {
        Series::Msd { dims } if (1..=3).contains(&dims) => (2.0 * dims as f64, "MSD"),
        Series::Orientation { order } if (1..=2).contains(&order) => {
            (-f64::from(order * (order + 1)), "ln C")
        }
        Series::Msd { dims } => {
            return Err(invalid!(
                "an MSD is measured in 1, 2 or 3 dimensions, got {dims}"
            ))
        }
        Series::Orientation { order } => {
            return Err(invalid!(
                "the orientation autocorrelation has order 1 or 2, got {order}"
            ))
        }
    };
    let lo = from.unwrap_or(f64::NEG_INFINITY);
    let hi = to.unwrap_or(f64::INFINITY);
    let rows: Vec<usize> = (0..times.len())
        .filter(|&k| times[k] >= lo && times[k] <= hi)
        .collect();
    let intervals = rows.len().saturating_sub(1);
    if intervals < 2 {
        return Err(invalid!(
            "the diffusion estimate needs at least 3 rows in its window (2 blocks give a standard error), and {} of the {} rows lie in it; record more often or widen the window (from, to)",
            rows.len(),
            times.len()
        ));
    }
    let b = blocks.unwrap_or(DEFAULT_BLOCKS.min(intervals));
    if b < 2 || b > intervals {
        return Err(invalid!(
            "the window's {} rows make 2 to {intervals} blocks, got {b}; blocks longer than the motion's correlation time give an honest error",
            rows.len()
        ));
    }
    let y = |k: usize| -> Result<f64> {
        match series {
            Series::Msd { .. } => Ok(values[k]),
            Series::Orientation { .. } if values[k] > 0.0 => Ok(values[k].ln()),
            Series::Orientation { .. } => Err(invalid!(
                "the orientation autocorrelation has fallen to {} at t = {:e} s, where its logarithm has no value: the window reaches past where the correlation is lost in noise; end it earlier (to: a time where C is still well above its error)",
                values[k],
                times[k]
            )),
        }
    };
    let edge = |e: usize| rows[e * intervals / b];
    let mut slopes = Vec::with_capacity(b);
    for e in 0..b {
        let (k0, k1) = (edge(e), edge(e + 1));
        slopes.push((y(k1)? - y(k0)?) / (rate * (times[k1] - times[k0])));
    }
    let mean = slopes.iter().sum::<f64>() / b as f64;
    let var = slopes.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / (b - 1) as f64;
    let estimate = Estimate {
        value: mean,
        error: (var / b as f64).sqrt(),
        slopes,
        from: times[rows[0]],
        to: times[rows[intervals]],
    };
    if !(estimate.value.is_finite() && estimate.error.is_finite()) {
        return Err(invalid!(
            "the {what} slopes of this window do not give a finite diffusion coefficient; check the times and values"
        ));
    }
    Ok(estimate)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Exact series give their coefficient and a zero error, to rounding (the differences of
    /// values ~1e-11 m² lose ~1e-15 of the slope: 1e-12 relative is far above it); a straight
    /// MSD with an offset (a ballistic start before the window) gives the slope alone.
    #[test]
    fn exact_series_give_their_coefficient() {
        let t: Vec<f64> = (0..41).map(|k| 0.5 * k as f64).collect();
        let msd: Vec<f64> = t.iter().map(|t| 7e-12 + 6.0 * 2e-13 * t).collect();
        let e = estimate(&t, &msd, Series::Msd { dims: 3 }, Some(2.0), None, None).unwrap();
        assert!((e.value / 2e-13 - 1.0).abs() < 1e-12, "{e:?}");
        assert!(e.error < 1e-12 * e.value);
        assert_eq!((e.from, e.to, e.slopes.len()), (2.0, 20.0, 10));
        let c: Vec<f64> = t.iter().map(|t| (-6.0 * 0.03 * t).exp()).collect();
        let e = estimate(
            &t,
            &c,
            Series::Orientation { order: 2 },
            None,
            None,
            Some(4),
        )
        .unwrap();
        assert!((e.value / 0.03 - 1.0).abs() < 1e-12, "{e:?}");
        assert_eq!(e.slopes.len(), 4);
    }

    #[test]
    fn bad_series_are_refused() {
        let t = [0.0, 1.0, 2.0, 3.0];
        let m = Series::Msd { dims: 3 };
        let e = |r: Result<Estimate>| r.unwrap_err().to_string();
        assert!(e(estimate(&t, &[0.0; 3], m, None, None, None)).contains("one value per time"));
        assert!(e(estimate(&[0.0, 2.0, 1.0], &[0.0; 3], m, None, None, None)).contains("increase"));
        assert!(e(estimate(&t, &[0.0; 4], m, Some(2.5), None, None)).contains("at least 3 rows"));
        assert!(e(estimate(&t, &[0.0; 4], m, None, None, Some(4))).contains("2 to 3 blocks"));
        let c = [1.0, 0.5, -0.1, 0.2];
        let o = Series::Orientation { order: 1 };
        assert!(e(estimate(&t, &c, o, None, None, None)).contains("end it earlier"));
    }
}
