//! The benchmark tables as log-log pictures (written next to their CSV files in out/bench/).

use super::backends::Row as BackendRow;
use super::scaling::{self, Row as ScalingRow};
use super::work_precision::Point;
use crate::engine::Model;
use crate::plot::{Figure, Legend, Series, Style};
use std::collections::BTreeMap;

/// Work against precision for one configuration: wall time against the drift's error, one line
/// per model and method family, ordered by error. Exact results (error 0) cannot go on a log
/// axis and are left out of the picture (they stay in the table).
pub fn work_precision(points: &[Point], config: &str) -> Option<Figure> {
    let mut families: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
    for p in points
        .iter()
        .filter(|p| p.config == config && p.err_drift > 0.0)
    {
        let spec = p.spec.to_string();
        let family = spec.split('(').next().unwrap_or(&spec).to_string();
        families
            .entry(format!("{} {family}", p.model.name()))
            .or_default()
            .push((p.err_drift, p.seconds));
    }
    if families.is_empty() {
        return None;
    }
    let series = families
        .into_iter()
        .map(|(label, mut pts)| {
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            let style = if pts.len() > 1 {
                Style::Line
            } else {
                Style::Points
            };
            Series::from_points(label, &pts, style, None)
        })
        .collect();
    Some(log_log(
        format!("work against precision: {config}"),
        "relative error of the drift",
        "wall time [s]",
        series,
        Legend::UpperRight,
    ))
}

/// Seconds per RK4 step against size, CPU and GPU, both models.
pub fn backends(rows: &[BackendRow]) -> Figure {
    let mut series = Vec::new();
    for model in [Model::Micro, Model::Averaged] {
        for (gpu, name) in [(false, "cpu"), (true, "gpu")] {
            let pts: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.model == model)
                .filter_map(|r| Some((r.size as f64, if gpu { r.gpu? } else { r.cpu? })))
                .collect();
            if !pts.is_empty() {
                let label = format!("{} {name}", model.name());
                series.push(Series::from_points(label, &pts, Style::Line, None));
            }
        }
    }
    log_log(
        "time per RK4 step, CPU and GPU".into(),
        "spheres (micro) or swimmers (averaged)",
        "wall time per step [s]",
        series,
        Legend::UpperLeft,
    )
}

/// Cost per period against the number of swimmers, every series, with the fitted power laws.
pub fn scaling(rows: &[ScalingRow]) -> Figure {
    let mut series = Vec::new();
    let gpu = rows
        .iter()
        .any(|r| r.line.backend == crate::engine::Backend::Gpu);
    for (k, line) in scaling::series(gpu).iter().enumerate() {
        let measured: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.line == *line)
            .map(|r| (r.swimmers as f64, r.per_period()))
            .collect();
        if measured.is_empty() {
            continue;
        }
        series.push(Series::from_points(
            scaling::label(line),
            &measured,
            Style::Points,
            Some(k),
        ));
        if let Some((slope, c)) = scaling::fit(rows, line, 256) {
            let fitted: Vec<(f64, f64)> = measured
                .iter()
                .map(|&(x, _)| (x, c * x.powf(slope)))
                .collect();
            let label = format!("{c:.2e} S^{slope:.2} (fit, S >= 256)");
            series.push(Series::from_points(label, &fitted, Style::Line, Some(k)));
        }
    }
    log_log(
        format!(
            "cost per stroke period{}",
            if gpu { ", CPU and GPU" } else { " on the CPU" }
        ),
        "swimmers S",
        "wall time per period [s]",
        series,
        Legend::Outside,
    )
}

/// A figure with both axes logarithmic.
fn log_log(
    title: String,
    x_label: &str,
    y_label: &str,
    series: Vec<Series>,
    legend: Legend,
) -> Figure {
    Figure {
        title,
        x_label: x_label.into(),
        y_label: y_label.into(),
        log_x: true,
        log_y: true,
        series,
        legend,
        ..Figure::default()
    }
}
