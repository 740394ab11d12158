//! Drawing with plotters: figures and scene pictures to SVG or PNG.

use super::figure::{Figure, Legend, Series, Style, COLORS};
use super::image::{Format, Image};
use super::ticks::format_number;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// DejaVu Sans, subset to Latin, Greek, super/subscripts and a few signs (assets/fonts).
const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans-subset.ttf");

/// Register the embedded font as "sans-serif" once per process.
pub(super) fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // The bytes are a valid font (checked by the picture tests); a failure would only leave
        // text undrawn, never stop a plot.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// A drawing error as a message. Pictures are drawn in memory (files are written apart, by
/// [`crate::engine::files`]), so this is plotters' own text.
pub(super) fn err<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> String {
    format!("cannot draw the picture: {e}")
}

impl Figure {
    /// Draw in memory, as PNG and SVG.
    pub fn image(&self) -> Result<Image, String> {
        self.validate()?;
        in_memory((self.width, self.height), self)
    }

    /// Draw to `path` (SVG or PNG by its extension); folders are created.
    pub fn save(&self, path: &std::path::Path) -> Result<(), String> {
        self.validate()?;
        let format = Format::of(path)?;
        crate::engine::files::ensure_parent(path).map_err(|e| e.to_string())?;
        figure(self, path, format)
    }
}

/// Draw `f` to `path` in `format`.
pub(super) fn figure(f: &Figure, path: &Path, format: Format) -> Result<(), String> {
    to_file((f.width, f.height), f, path, format)
}

/// Draw `picture` of `size` to `path` in `format`: drawn in memory, then written whole through a
/// temporary file and a rename, as every file swimlab writes (a crash keeps the old picture, and
/// a path that cannot be written gets the message that names it and the fix).
pub(super) fn to_file(
    size: (u32, u32),
    picture: &dyn Drawable,
    path: &Path,
    format: Format,
) -> Result<(), String> {
    register_font();
    let bytes = match format {
        Format::Svg => {
            let mut svg = String::new();
            {
                let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
                picture.draw_svg(&root)?;
                root.present().map_err(err)?;
            }
            svg.into_bytes()
        }
        Format::Png => {
            let mut rgb = vec![0u8; size.0 as usize * size.1 as usize * 3];
            {
                let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
                picture.draw_bitmap(&root)?;
                root.present().map_err(err)?;
            }
            encode_png(&rgb, size)?
        }
    };
    crate::engine::files::write_atomically(path, |w| w.write_all(&bytes)).map_err(|e| e.to_string())
}

/// A picture drawn in memory by `draw` onto an SVG and a bitmap of `size`: the SVG text and the
/// PNG bytes.
pub(super) fn in_memory(size: (u32, u32), picture: &dyn Drawable) -> Result<Image, String> {
    register_font();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        picture.draw_svg(&root)?;
        root.present().map_err(err)?;
    }
    let mut rgb = vec![0u8; size.0 as usize * size.1 as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
        picture.draw_bitmap(&root)?;
        root.present().map_err(err)?;
    }
    Ok(Image {
        png: encode_png(&rgb, size)?,
        svg,
        width: size.0,
        height: size.1,
    })
}

/// What [`in_memory`] draws: a figure or a scene picture, on either backend.
pub(super) trait Drawable {
    fn draw_svg(&self, root: &DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), String>;
    fn draw_bitmap(&self, root: &DrawingArea<BitMapBackend<'_>, Shift>) -> Result<(), String>;
}

impl Drawable for Figure {
    fn draw_svg(&self, root: &DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), String> {
        draw_figure(self, root)
    }
    fn draw_bitmap(&self, root: &DrawingArea<BitMapBackend<'_>, Shift>) -> Result<(), String> {
        draw_figure(self, root)
    }
}

impl Drawable for ScenePicture<'_> {
    fn draw_svg(&self, root: &DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), String> {
        draw_scene(self, root).map(|_| ())
    }
    fn draw_bitmap(&self, root: &DrawingArea<BitMapBackend<'_>, Shift>) -> Result<(), String> {
        draw_scene(self, root).map(|_| ())
    }
}

/// RGB pixels as PNG bytes.
fn encode_png(rgb: &[u8], (w, h): (u32, u32)) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut writer = enc
        .write_header()
        .map_err(|e| format!("cannot encode the picture: {e}"))?;
    writer
        .write_image_data(rgb)
        .map_err(|e| format!("cannot encode the picture: {e}"))?;
    writer
        .finish()
        .map_err(|e| format!("cannot encode the picture: {e}"))?;
    Ok(out)
}

/// A tick label with as many digits as the axis span needs ([`format_number`]).
fn tick(v: f64, span: f64) -> String {
    format_number(v, span)
}

/// The span a tick at `v` is judged against: the axis range, or on a log axis the value itself
/// (decades need one digit).
fn axis_span(range: (f64, f64), log: bool, v: f64) -> f64 {
    if log {
        10.0 * v.abs()
    } else {
        range.1 - range.0
    }
}

fn color(k: usize) -> RGBColor {
    let (r, g, b) = COLORS[k % COLORS.len()];
    RGBColor(r, g, b)
}

/// The labels of a figure's legend, with each entry's series.
fn legend_entries(f: &Figure) -> Vec<(usize, &Series)> {
    f.series
        .iter()
        .enumerate()
        .filter(|(_, s)| !s.label.is_empty())
        .collect()
}

/// Width (px) of a legend outside the plot: the longest label at ~7.8 px a character (DejaVu
/// Sans at 14 px), the swatch and margins; at most 40% of the picture.
fn outside_legend_width(f: &Figure) -> u32 {
    let longest = legend_entries(f)
        .iter()
        .map(|(_, s)| s.label.chars().count())
        .max()
        .unwrap_or(0);
    ((longest as f64 * 7.8) as u32 + 60).min(f.width * 2 / 5)
}

/// Draw the legend entries in `area`, top down, from `top` px.
fn draw_outside_legend<DB: DrawingBackend>(
    f: &Figure,
    area: &DrawingArea<DB, Shift>,
    top: i32,
) -> Result<(), String> {
    for (row, (k, s)) in legend_entries(f).into_iter().enumerate() {
        let c = color(s.color.unwrap_or(k));
        let y = top + 22 * row as i32;
        match s.style {
            Style::Line => area
                .draw(&PathElement::new(vec![(6, y), (30, y)], c.stroke_width(2)))
                .map_err(err)?,
            Style::Points => area
                .draw(&Circle::new((18, y), 4, c.filled()))
                .map_err(err)?,
        }
        let style = TextStyle::from(("sans-serif", 14).into_font()).pos(
            plotters::style::text_anchor::Pos::new(
                plotters::style::text_anchor::HPos::Left,
                plotters::style::text_anchor::VPos::Center,
            ),
        );
        area.draw(&Text::new(s.label.clone(), (38, y), style))
            .map_err(err)?;
    }
    Ok(())
}

/// Ticks of a log axis over [a, b]: labelled (bold) at 1, 2, 3 and 5 × 10^k on an axis of up to
/// 2 decades, 1, 2 and 5 × 10^k up to 3, 10^k alone beyond (every third power beyond 12); light
/// lines at every m × 10^k.
fn log_ticks(a: f64, b: f64) -> (Vec<f64>, Vec<f64>) {
    let (lo, hi) = (a.min(b), a.max(b));
    let (k0, k1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let decades = (hi / lo).log10();
    let every = if decades > 12.0 { 3 } else { 1 };
    let (mut bold, mut light) = (Vec::new(), Vec::new());
    for k in k0..=k1 {
        let p = 10f64.powi(k);
        for m in 1..10 {
            let v = m as f64 * p;
            if v < lo * (1.0 - 1e-12) || v > hi * (1.0 + 1e-12) {
                continue;
            }
            light.push(v);
            let labelled = match m {
                1 => k % every == 0,
                2 | 5 => decades <= 3.0,
                3 => decades <= 2.0,
                _ => false,
            };
            if labelled {
                bold.push(v);
            }
        }
    }
    (bold, light)
}

fn draw_figure<DB: DrawingBackend>(
    f: &Figure,
    root: &DrawingArea<DB, Shift>,
) -> Result<(), String> {
    root.fill(&WHITE).map_err(err)?;
    let f = &f.with_offsets();
    if f.legend == Legend::Outside && !legend_entries(f).is_empty() {
        let w = outside_legend_width(f);
        let (plot_area, legend_area) = root.split_horizontally(f.width - w);
        draw_axes(f, &plot_area)?;
        let top = if f.title.is_empty() { 24 } else { 52 };
        return draw_outside_legend(f, &legend_area, top);
    }
    draw_axes(f, root)
}

/// The axes, the series and (inside the plot) the legend.
fn draw_axes<DB: DrawingBackend>(f: &Figure, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
    // Ranges are padded in the axis's own scale (log10 on a log axis), then mapped back.
    let axis = |x_axis: bool, log: bool| {
        let (a, b) = f.range(x_axis);
        if log {
            (10f64.powf(a), 10f64.powf(b))
        } else {
            (a, b)
        }
    };
    let ((x0, x1), (y0, y1)) = (axis(true, f.log_x), axis(false, f.log_y));
    let logged = |a: f64, b: f64| {
        let (bold, light) = log_ticks(a, b);
        (a..b)
            .log_scale()
            .with_key_points(bold)
            .with_light_points(light)
    };
    match (f.log_x, f.log_y) {
        (false, false) => draw_in(f, root, x0..x1, y0..y1),
        (true, false) => draw_in(f, root, logged(x0, x1), y0..y1),
        (false, true) => draw_in(f, root, x0..x1, logged(y0, y1)),
        (true, true) => draw_in(f, root, logged(x0, x1), logged(y0, y1)),
    }
}

fn draw_in<DB, X, Y>(f: &Figure, root: &DrawingArea<DB, Shift>, xr: X, yr: Y) -> Result<(), String>
where
    DB: DrawingBackend,
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y::CoordDescType: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let mut builder = ChartBuilder::on(root);
    builder
        .margin(14)
        .x_label_area_size(48)
        .y_label_area_size(78);
    if !f.title.is_empty() {
        builder.caption(&f.title, ("sans-serif", 22));
    }
    let mut chart = builder.build_cartesian_2d(xr, yr).map_err(err)?;
    let (sx, sy) = (f.range(true), f.range(false));
    let fx = |v: &f64| tick(*v, axis_span(sx, f.log_x, *v));
    let fy = |v: &f64| tick(*v, axis_span(sy, f.log_y, *v));
    chart
        .configure_mesh()
        .x_desc(f.x_label.as_str())
        .y_desc(f.y_label.as_str())
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .light_line_style(RGBColor(238, 238, 238))
        .bold_line_style(RGBColor(215, 215, 215))
        .draw()
        .map_err(err)?;
    for (k, s) in f.series.iter().enumerate() {
        let c = color(s.color.unwrap_or(k));
        let pts: Vec<(f64, f64)> = s.x.iter().copied().zip(s.y.iter().copied()).collect();
        match s.style {
            Style::Line => {
                let a = chart
                    .draw_series(LineSeries::new(pts, c.stroke_width(2)))
                    .map_err(err)?;
                if !s.label.is_empty() {
                    a.label(s.label.as_str()).legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 22, y)], c.stroke_width(2))
                    });
                }
            }
            Style::Points => {
                let a = chart
                    .draw_series(pts.into_iter().map(|p| Circle::new(p, 4, c.filled())))
                    .map_err(err)?;
                if !s.label.is_empty() {
                    a.label(s.label.as_str())
                        .legend(move |(x, y)| Circle::new((x + 11, y), 4, c.filled()));
                }
            }
        }
    }
    let place = match f.legend {
        Legend::UpperRight => SeriesLabelPosition::UpperRight,
        Legend::UpperLeft => SeriesLabelPosition::UpperLeft,
        Legend::LowerRight => SeriesLabelPosition::LowerRight,
        Legend::LowerLeft => SeriesLabelPosition::LowerLeft,
        Legend::Outside | Legend::None => return Ok(()),
    };
    if f.series.iter().any(|s| !s.label.is_empty()) {
        chart
            .configure_series_labels()
            .position(place)
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(160, 160, 160))
            .label_font(("sans-serif", 14))
            .draw()
            .map_err(err)?;
    }
    Ok(())
}

/// A disc of a scene picture in display units (µm): centre, radius, fill colour.
pub(super) struct Disc {
    pub x: f64,
    pub y: f64,
    pub r: f64,
    pub fill: RGBColor,
}

/// A scene picture: rods (pairs of disc indices) under discs, equal scales on both axes.
pub(super) struct ScenePicture<'a> {
    pub title: &'a str,
    pub axes: (&'a str, &'a str),
    pub size: (u32, u32),
    pub discs: Vec<Disc>,
    pub rods: Vec<(usize, usize)>,
    /// The region shown, (x0, x1, y0, y1) in µm; `None`: the discs' extent, padded.
    pub view: Option<(f64, f64, f64, f64)>,
}

/// An animated GIF of scene pictures, a frame per [`Film::frame`], each written to the file as
/// it is drawn (the gif crate's encoder on the file: a run stopped early leaves the frames so far).
pub(super) struct Film {
    encoder: gif::Encoder<std::fs::File>,
    path: std::path::PathBuf,
    size: (u32, u32),
    /// Between frames, in hundredths of a second (GIF's unit).
    delay: u16,
}

impl Film {
    /// A GIF at `path`, `size` pixels, `delay_ms` between frames.
    pub(super) fn create(path: &Path, size: (u32, u32), delay_ms: u32) -> Result<Self, String> {
        register_font();
        let file = crate::engine::files::create(path).map_err(|e| e.to_string())?;
        let gif_error = |e: gif::EncodingError| gif_error(path, e);
        let mut encoder =
            gif::Encoder::new(file, size.0 as u16, size.1 as u16, &[]).map_err(gif_error)?;
        encoder
            .set_repeat(gif::Repeat::Infinite)
            .map_err(gif_error)?;
        Ok(Film {
            encoder,
            path: path.to_path_buf(),
            size,
            delay: ((delay_ms + 5) / 10).min(u16::MAX as u32) as u16,
        })
    }

    /// Draw `p` as the next frame; returns the region it showed (to hold it for the next ones).
    pub(super) fn frame(&mut self, p: &ScenePicture) -> Result<(f64, f64, f64, f64), String> {
        let (w, h) = self.size;
        let mut rgb = vec![0u8; w as usize * h as usize * 3];
        let view = {
            let root = BitMapBackend::with_buffer(&mut rgb, self.size).into_drawing_area();
            let view = draw_scene(p, &root)?;
            root.present().map_err(err)?;
            view
        };
        let mut frame = gif::Frame::from_rgb_speed(w as u16, h as u16, &rgb, 10);
        frame.delay = self.delay;
        self.encoder
            .write_frame(&frame)
            .map_err(|e| gif_error(&self.path, e))?;
        Ok(view)
    }
}

/// A GIF encoder's error as a message naming the file and the fix.
fn gif_error(path: &Path, e: gif::EncodingError) -> String {
    match e {
        gif::EncodingError::Io(e) => format!(
            "cannot write {}: {e}; check that the folder is writable and the disk not full",
            path.display()
        ),
        other => format!("cannot encode the GIF {}: {other}", path.display()),
    }
}

/// Draw a scene picture to `path`.
pub(super) fn scene(p: &ScenePicture, path: &Path, format: Format) -> Result<(), String> {
    to_file(p.size, p, path, format)
}

/// Draw `p`; returns the region shown (x0, x1, y0, y1) in µm.
fn draw_scene<DB: DrawingBackend>(
    p: &ScenePicture,
    root: &DrawingArea<DB, Shift>,
) -> Result<(f64, f64, f64, f64), String> {
    root.fill(&WHITE).map_err(err)?;
    let (x0, x1, y0, y1) = p.view.unwrap_or_else(|| scene_view(p));
    draw_scene_in(p, root, (x0, x1, y0, y1))?;
    Ok((x0, x1, y0, y1))
}

/// The discs' extent, padded by 5% and widened to the plotting area's aspect ratio (equal scales).
pub(super) fn scene_view(p: &ScenePicture) -> (f64, f64, f64, f64) {
    let (mut x0, mut x1, mut y0, mut y1) = p.discs.iter().fold(
        (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ),
        |(a, b, c, d), s| {
            (
                a.min(s.x - s.r),
                b.max(s.x + s.r),
                c.min(s.y - s.r),
                d.max(s.y + s.r),
            )
        },
    );
    if !(x1 > x0 && y1 > y0) {
        (x0, x1, y0, y1) = (-1.0, 1.0, -1.0, 1.0);
    }
    let pad = 0.05 * (x1 - x0).max(y1 - y0);
    (x0, x1, y0, y1) = (x0 - pad, x1 + pad, y0 - pad, y1 + pad);
    // Equal scales: widen the narrower range to the plotting area's aspect ratio.
    let (caption, xl, yl, margin) = (if p.title.is_empty() { 0 } else { 34 }, 45.0, 70.0, 14.0);
    let aw = p.size.0 as f64 - yl - 2.0 * margin;
    let ah = p.size.1 as f64 - xl - 2.0 * margin - caption as f64;
    let (w, h) = (x1 - x0, y1 - y0);
    if w / h < aw / ah {
        let extra = (h * aw / ah - w) / 2.0;
        (x0, x1) = (x0 - extra, x1 + extra);
    } else {
        let extra = (w * ah / aw - h) / 2.0;
        (y0, y1) = (y0 - extra, y1 + extra);
    }
    (x0, x1, y0, y1)
}

fn draw_scene_in<DB: DrawingBackend>(
    p: &ScenePicture,
    root: &DrawingArea<DB, Shift>,
    (x0, x1, y0, y1): (f64, f64, f64, f64),
) -> Result<(), String> {
    let (xl, yl, margin) = (45.0, 70.0, 14.0);
    let mut builder = ChartBuilder::on(root);
    builder
        .margin(margin as u32)
        .x_label_area_size(xl as u32)
        .y_label_area_size(yl as u32);
    if !p.title.is_empty() {
        builder.caption(p.title, ("sans-serif", 20));
    }
    let mut chart = builder.build_cartesian_2d(x0..x1, y0..y1).map_err(err)?;
    let fmt = |v: &f64| tick(*v, (x1 - x0).max(y1 - y0));
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(p.axes.0)
        .y_desc(p.axes.1)
        .x_label_formatter(&fmt)
        .y_label_formatter(&fmt)
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .draw()
        .map_err(err)?;
    let px = chart.plotting_area().get_pixel_range().0;
    let px_per_unit = (px.end - px.start) as f64 / (x1 - x0);
    let grey = RGBColor(90, 90, 90);
    chart
        .draw_series(p.rods.iter().map(|&(a, b)| {
            let (da, db) = (&p.discs[a], &p.discs[b]);
            PathElement::new(vec![(da.x, da.y), (db.x, db.y)], grey.stroke_width(2))
        }))
        .map_err(err)?;
    for d in &p.discs {
        let r = ((d.r * px_per_unit).round() as i32).max(1);
        chart
            .draw_series([
                Circle::new((d.x, d.y), r, d.fill.filled()),
                Circle::new((d.x, d.y), r, BLACK.stroke_width(1)),
            ])
            .map_err(err)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::log_ticks;

    #[test]
    fn log_axes_label_one_two_three_five() {
        let (bold, light) = log_ticks(2.7, 33.0);
        assert_eq!(bold, vec![3.0, 5.0, 10.0, 20.0, 30.0]);
        assert_eq!(light.len(), 10, "3 … 9, 10, 20, 30: {light:?}");
        let (bold, _) = log_ticks(0.5, 500.0);
        assert_eq!(
            bold,
            vec![0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0]
        );
        let (bold, _) = log_ticks(1e-3, 1e5);
        assert_eq!(bold.len(), 9, "powers of ten only over 8 decades: {bold:?}");
    }
}
