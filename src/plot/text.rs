//! Quick plots as text for the terminal: each series drawn with its own character on a grid of
//! `cols` × `rows` cells, consecutive points of a line joined, with the ranges and a legend.

use super::figure::{Figure, Style};
use super::ticks::format_number;

/// Markers of the series, in turn.
const MARKS: [char; 6] = ['*', 'o', '+', 'x', '#', '@'];

/// The figure as text `cols` wide and `rows` high (plot area), log axes honoured.
pub fn render_text(f: &Figure, cols: usize, rows: usize) -> Result<String, String> {
    f.validate()?;
    let f = &f.with_offsets();
    let (cols, rows) = (cols.clamp(10, 400), rows.clamp(4, 200));
    let (x0, x1) = f.range(true);
    let (y0, y1) = f.range(false);
    let mut grid = vec![vec![' '; cols]; rows];
    let cell = |x: f64, y: f64| -> (isize, isize) {
        let cx = ((x - x0) / (x1 - x0) * (cols - 1) as f64).round() as isize;
        let cy = ((y1 - y) / (y1 - y0) * (rows - 1) as f64).round() as isize;
        (cx, cy)
    };
    let tr = |v: f64, log: bool| if log { v.log10() } else { v };
    for (k, s) in f.series.iter().enumerate() {
        let mark = MARKS[k % MARKS.len()];
        let pts: Vec<(isize, isize)> =
            s.x.iter()
                .zip(&s.y)
                .map(|(x, y)| cell(tr(*x, f.log_x), tr(*y, f.log_y)))
                .collect();
        let mut put = |(cx, cy): (isize, isize)| {
            if (0..cols as isize).contains(&cx) && (0..rows as isize).contains(&cy) {
                grid[cy as usize][cx as usize] = mark;
            }
        };
        for (i, &p) in pts.iter().enumerate() {
            put(p);
            if s.style == Style::Line && i > 0 {
                // Fill the cells between consecutive points.
                let q = pts[i - 1];
                let n = (p.0 - q.0).abs().max((p.1 - q.1).abs());
                for t in 1..n {
                    let u = t as f64 / n as f64;
                    put((
                        (q.0 as f64 + u * (p.0 - q.0) as f64).round() as isize,
                        (q.1 as f64 + u * (p.1 - q.1) as f64).round() as isize,
                    ));
                }
            }
        }
    }
    let label = |v: f64, log: bool, span: f64| {
        if log {
            format_number(10f64.powf(v), 10.0 * 10f64.powf(v))
        } else {
            format_number(v, span)
        }
    };
    let mut out = String::new();
    if !f.title.is_empty() {
        out += &format!("{}\n", f.title);
    }
    let (top, bottom) = (label(y1, f.log_y, y1 - y0), label(y0, f.log_y, y1 - y0));
    let w = top.len().max(bottom.len());
    for (r, line) in grid.iter().enumerate() {
        let tag = match r {
            0 => top.clone(),
            _ if r == rows - 1 => bottom.clone(),
            _ => String::new(),
        };
        out += &format!("{tag:>w$} |{}\n", line.iter().collect::<String>());
    }
    out += &format!("{:>w$} +{}\n", "", "-".repeat(cols));
    let (left, right) = (label(x0, f.log_x, x1 - x0), label(x1, f.log_x, x1 - x0));
    out += &format!(
        "{:>w$}  {left}{}{right}\n",
        "",
        " ".repeat(cols.saturating_sub(left.len() + right.len()))
    );
    let axes = format!(
        "x: {}{}   y: {}{}",
        f.x_label,
        if f.log_x { " (log)" } else { "" },
        f.y_label,
        if f.log_y { " (log)" } else { "" }
    );
    out += &format!("{:>w$}  {axes}\n", "");
    for (k, s) in f.series.iter().enumerate() {
        if !s.label.is_empty() {
            out += &format!("{:>w$}  {} {}\n", "", MARKS[k % MARKS.len()], s.label);
        }
    }
    Ok(out)
}
