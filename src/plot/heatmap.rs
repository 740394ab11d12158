//! Heat maps: a 2D array of values as coloured cells (a field's slice), with a colour bar.

use super::image::{Format, Image};
use super::render::{err, in_memory, register_font, to_file, Drawable};
use super::ticks::format_number;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// A heat map: `values` row by row from the bottom, `cols` each, over the extents `x` and `y`.
#[derive(Debug, Clone, PartialEq)]
pub struct HeatMap {
    /// Title above the map (may be empty).
    pub title: String,
    /// Axis labels.
    pub x_desc: String,
    /// Label of the vertical axis.
    pub y_desc: String,
    /// What the colours mean, beside the colour bar.
    pub value_desc: String,
    /// Columns.
    pub cols: usize,
    /// Rows.
    pub rows: usize,
    /// Row by row from the bottom.
    pub values: Vec<f64>,
    /// Extent across.
    pub x: (f64, f64),
    /// Extent up.
    pub y: (f64, f64),
    /// Picture size in pixels.
    pub size: (u32, u32),
}

/// Viridis at nine stops (matplotlib's, perceptually uniform), interpolated linearly.
const VIRIDIS: [(u8, u8, u8); 9] = [
    (68, 1, 84),
    (71, 44, 122),
    (59, 81, 139),
    (44, 113, 142),
    (33, 144, 141),
    (39, 173, 129),
    (92, 200, 99),
    (170, 220, 50),
    (253, 231, 37),
];

fn viridis(t: f64) -> RGBColor {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (VIRIDIS.len() - 1) as f64;
    let i = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let f = x - i as f64;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    let mix = |p: u8, q: u8| (p as f64 + f * (q as f64 - p as f64)).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

impl HeatMap {
    fn check(&self) -> Result<(), String> {
        if self.cols == 0 || self.rows == 0 || self.values.len() != self.cols * self.rows {
            return Err("a heat map needs a non-empty grid of values".into());
        }
        if !(self.x.1 > self.x.0 && self.y.1 > self.y.0) {
            return Err("a heat map needs extents of positive width".into());
        }
        Ok(())
    }

    /// Draw to `path` (SVG or PNG by its extension); folders are created.
    pub fn save(&self, path: &Path) -> Result<(), String> {
        self.check()?;
        let format = Format::of(path)?;
        crate::engine::files::ensure_parent(path).map_err(|e| e.to_string())?;
        to_file(self.size, self, path, format)
    }

    /// Draw in memory (PNG and SVG).
    pub fn image(&self) -> Result<Image, String> {
        self.check()?;
        in_memory(self.size, self)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        register_font();
        root.fill(&WHITE).map_err(err)?;
        let (lo, hi) = self
            .values
            .iter()
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(*v), b.max(*v))
            });
        let (lo, hi) = if lo.is_finite() { (lo, hi) } else { (0.0, 1.0) };
        let span = if hi > lo { hi - lo } else { 1.0 };
        let (map_area, bar_area) = root.split_horizontally(self.size.0.saturating_sub(120));
        let mut builder = ChartBuilder::on(&map_area);
        builder
            .margin(14)
            .x_label_area_size(45)
            .y_label_area_size(70);
        if !self.title.is_empty() {
            builder.caption(&self.title, ("sans-serif", 20));
        }
        let (x, y) = (self.x, self.y);
        let mut chart = builder
            .build_cartesian_2d(x.0..x.1, y.0..y.1)
            .map_err(err)?;
        let fmt = |v: &f64| format_number(*v, (x.1 - x.0).max(y.1 - y.0));
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(self.x_desc.as_str())
            .y_desc(self.y_desc.as_str())
            .x_label_formatter(&fmt)
            .y_label_formatter(&fmt)
            .label_style(("sans-serif", 14))
            .axis_desc_style(("sans-serif", 16))
            .draw()
            .map_err(err)?;
        let (dx, dy) = (
            (x.1 - x.0) / self.cols as f64,
            (y.1 - y.0) / self.rows as f64,
        );
        chart
            .draw_series((0..self.rows).flat_map(|j| {
                (0..self.cols).map(move |i| {
                    let v = self.values[i + self.cols * j];
                    let (x0, y0) = (x.0 + i as f64 * dx, y.0 + j as f64 * dy);
                    Rectangle::new(
                        [(x0, y0), (x0 + dx, y0 + dy)],
                        viridis((v - lo) / span).filled(),
                    )
                })
            }))
            .map_err(err)?;
        // The colour bar: the value range bottom to top.
        let mut bar = ChartBuilder::on(&bar_area);
        bar.margin(14)
            .margin_top(if self.title.is_empty() { 14 } else { 48 })
            .x_label_area_size(45)
            .y_label_area_size(0)
            .right_y_label_area_size(70);
        let mut c = bar
            .build_cartesian_2d(0.0..1.0, lo..(lo + span))
            .map_err(err)?
            .set_secondary_coord(0.0..1.0, lo..(lo + span));
        let steps = 64;
        c.draw_series((0..steps).map(|k| {
            let (a, b) = (k as f64 / steps as f64, (k + 1) as f64 / steps as f64);
            Rectangle::new(
                [(0.0, lo + a * span), (1.0, lo + b * span)],
                viridis((a + b) / 2.0).filled(),
            )
        }))
        .map_err(err)?;
        let vfmt = |v: &f64| format_number(*v, span);
        c.configure_secondary_axes()
            .y_desc(self.value_desc.as_str())
            .y_label_formatter(&vfmt)
            .label_style(("sans-serif", 12))
            .axis_desc_style(("sans-serif", 14))
            .draw()
            .map_err(err)?;
        Ok(())
    }
}

impl Drawable for HeatMap {
    fn draw_svg(&self, root: &DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), String> {
        self.draw(root)
    }
    fn draw_bitmap(&self, root: &DrawingArea<BitMapBackend<'_>, Shift>) -> Result<(), String> {
        self.draw(root)
    }
}
