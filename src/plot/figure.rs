//! A plot as data: its series, axes, legend and size, the checks before it is drawn, and the
//! ranges and offsets its axes are drawn with.

use super::ticks::format_number;

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// Straight segments between consecutive points.
    Line,
    /// A marker at every point.
    Points,
}

impl Style {
    /// Parse "line" or "points".
    pub fn parse(name: &str) -> Result<Self, String> {
        match name {
            "line" => Ok(Style::Line),
            "points" => Ok(Style::Points),
            other => Err(format!(
                "unknown style \"{other}\"; use \"line\" or \"points\""
            )),
        }
    }
}

/// One named series of (x, y) points.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend entry (empty: none).
    pub label: String,
    /// Abscissae.
    pub x: Vec<f64>,
    /// Ordinates.
    pub y: Vec<f64>,
    /// Line or points.
    pub style: Style,
    /// Palette index into [`COLORS`]; `None`: the series' own index.
    pub color: Option<usize>,
}

impl Series {
    /// A series of (x, y) points.
    pub fn from_points(
        label: impl Into<String>,
        pts: &[(f64, f64)],
        style: Style,
        color: Option<usize>,
    ) -> Self {
        Series {
            label: label.into(),
            x: pts.iter().map(|p| p.0).collect(),
            y: pts.iter().map(|p| p.1).collect(),
            style,
            color,
        }
    }
}

/// A plot: axes with labels (units included by the caller), optional log scales, and series.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Caption above the plot.
    pub title: String,
    /// x axis label, e.g. "time [s]".
    pub x_label: String,
    /// y axis label.
    pub y_label: String,
    /// Logarithmic x axis.
    pub log_x: bool,
    /// Logarithmic y axis.
    pub log_y: bool,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The series, drawn in order with the colours of [`COLORS`].
    pub series: Vec<Series>,
    /// Where the legend goes (if any series has a label).
    pub legend: Legend,
}

/// Legend placement inside the plot area.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Legend {
    /// Top right (the default).
    #[default]
    UpperRight,
    /// Top left.
    UpperLeft,
    /// Bottom right.
    LowerRight,
    /// Bottom left.
    LowerLeft,
    /// Right of the plot, outside the data.
    Outside,
    /// No legend.
    None,
}

impl Legend {
    /// Parse "upper right", "upper left", "lower right", "lower left", "outside" or "none".
    pub fn parse(name: &str) -> Result<Self, String> {
        Ok(match name {
            "upper right" => Legend::UpperRight,
            "upper left" => Legend::UpperLeft,
            "lower right" => Legend::LowerRight,
            "lower left" => Legend::LowerLeft,
            "outside" => Legend::Outside,
            "none" => Legend::None,
            other => {
                return Err(format!(
                    "unknown legend place \"{other}\"; use \"upper right\", \"upper left\", \"lower right\", \"lower left\", \"outside\" (right of the plot) or \"none\""
                ))
            }
        })
    }
}

impl Default for Figure {
    fn default() -> Self {
        Figure {
            title: String::new(),
            x_label: String::new(),
            y_label: String::new(),
            log_x: false,
            log_y: false,
            width: 800,
            height: 500,
            series: Vec::new(),
            legend: Legend::default(),
        }
    }
}

/// Series colours (the "tab10" palette), reused in turn.
pub const COLORS: [(u8, u8, u8); 10] = [
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
];

/// The most decades a log axis may span (its ticks and grid are drawn per decade).
pub const MAX_LOG_DECADES: f64 = 100.0;

impl Figure {
    /// Check that the figure can be drawn: at least one series, x and y of equal length, finite
    /// values, and positive values on log axes; sizes between 100 and 8000 pixels.
    pub fn validate(&self) -> Result<(), String> {
        if self.series.is_empty() {
            return Err("a plot needs at least one series, e.g. #{ x: [1, 2], y: [3, 4] }".into());
        }
        for (w, what) in [(self.width, "width"), (self.height, "height")] {
            if !(100..=8000).contains(&w) {
                return Err(format!("plot {what} must be 100 to 8000 pixels, got {w}"));
            }
        }
        for (k, s) in self.series.iter().enumerate() {
            let name = if s.label.is_empty() {
                format!("series {k}")
            } else {
                format!("series {k} (\"{}\")", s.label)
            };
            if s.x.len() != s.y.len() {
                return Err(format!(
                    "{name} has {} x values but {} y values; give both the same length",
                    s.x.len(),
                    s.y.len()
                ));
            }
            if s.x.is_empty() {
                return Err(format!("{name} has no points"));
            }
            for (axis, v, log) in [("x", &s.x, self.log_x), ("y", &s.y, self.log_y)] {
                if let Some(i) = v.iter().position(|v| !v.is_finite()) {
                    return Err(format!(
                        "{name}: {axis}[{i}] is {}, not a finite number",
                        v[i]
                    ));
                }
                if log {
                    if let Some(i) = v.iter().position(|v| *v <= 0.0) {
                        return Err(format!(
                            "{name}: {axis}[{i}] = {} cannot go on a log axis; use positive values (e.g. abs) or log_{axis}: false",
                            v[i]
                        ));
                    }
                }
            }
        }
        for (x_axis, axis, log) in [(true, "x", self.log_x), (false, "y", self.log_y)] {
            let (lo, hi) = self.range(x_axis);
            if log && hi - lo > MAX_LOG_DECADES {
                return Err(format!(
                    "the {axis} values span {:.0} decades; a log axis can show at most {MAX_LOG_DECADES}: leave out the extreme values",
                    hi - lo
                ));
            }
            if !log && !(hi - lo).is_finite() {
                let (a, b) = self.data_range(x_axis);
                return Err(format!(
                    "the {axis} values span from {a:e} to {b:e}, wider than f64 can draw; leave out the extreme values or divide them by a common scale"
                ));
            }
        }
        Ok(())
    }

    /// Smallest and largest value on one axis.
    fn data_range(&self, x_axis: bool) -> (f64, f64) {
        self.series
            .iter()
            .flat_map(|s| if x_axis { &s.x } else { &s.y })
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(*v), b.max(*v))
            })
    }

    /// The figure as drawn: a linear axis whose values sit far from zero compared with their spread
    /// (a separation of 50 µm changing by 1e-10 m) is drawn relative to a round offset, named in
    /// its label ("separation [m] − 5.0000104e-5"), so the ticks stay short and readable.
    pub fn with_offsets(&self) -> Figure {
        let mut f = self.clone();
        for x_axis in [true, false] {
            let log = if x_axis { f.log_x } else { f.log_y };
            let (lo, hi) = f.range(x_axis);
            let (center, span) = ((lo + hi) / 2.0, hi - lo);
            if log || span.is_nan() || span <= 0.0 || center.abs() < 1e3 * span {
                continue;
            }
            let step = 10f64.powf(span.log10().floor());
            let offset = (center / step).round() * step;
            for sr in &mut f.series {
                let v = if x_axis { &mut sr.x } else { &mut sr.y };
                v.iter_mut().for_each(|x| *x -= offset);
            }
            let label = if x_axis {
                &mut f.x_label
            } else {
                &mut f.y_label
            };
            *label = format!("{label} − {}", format_number(offset, step));
        }
        f
    }

    /// Data range of all series on one axis, after the log transform; padded by 5% (a single
    /// value gets a unit-wide range).
    pub(super) fn range(&self, x_axis: bool) -> (f64, f64) {
        let log = if x_axis { self.log_x } else { self.log_y };
        // log10 is monotonic: the range of the logs is the log of the range.
        let (lo, hi) = self.data_range(x_axis);
        let (lo, hi) = if log {
            (lo.log10(), hi.log10())
        } else {
            (lo, hi)
        };
        if hi > lo {
            let pad = 0.05 * (hi - lo);
            (lo - pad, hi + pad)
        } else {
            let w = if lo == 0.0 { 1.0 } else { 0.05 * lo.abs() };
            (lo - w, hi + w)
        }
    }
}
