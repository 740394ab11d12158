//! `swimlab bench ...`: each benchmark's tables printed and written as CSV, with its pictures,
//! under out/bench/. The command line only names the benchmark.

use super::{
    backends, boundaries, contacts, ewald, live_view, pairs, plots, scaling, stability, suspension,
    work_precision,
};
use crate::engine::Model;

/// The benchmarks `swimlab bench` runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Kind {
    /// Every integrator on the Fig-1 pairs: error against work, Pareto front.
    WorkPrecision,
    /// Largest stable step of each explicit method.
    Stability,
    /// CPU against GPU per RK4 step against size.
    Backends,
    /// The CPU pair kernel's interactions per second.
    Pairs,
    /// Cost per period against the number of swimmers.
    Scaling,
    /// The periodic box's mobility product by both Ewald methods against size.
    Ewald,
    /// One right-hand side in a box and above a wall against open space.
    Boundaries {
        /// The box's Ewald tolerance (`None`: the scene's default).
        ewald_tol: Option<f64>,
    },
    /// Whole runs of the accurate models' suspensions in contact: seconds and right-hand sides
    /// a period.
    Contacts,
    /// Bulk suspensions of the averaged model: right-hand side, placement, long runs, accuracy.
    Suspension,
    /// A run with and without a live view attached (and with readers that never read).
    View,
}

/// Run one benchmark, tell `say` its tables line by line (the command line prints them) and
/// write its CSV and pictures under out/bench/. An error is a whole line, "error: ..." (the
/// engine's messages, such as a setting out of range, come without either).
pub fn run(
    which: Kind,
    quick: bool,
    say: &dyn Fn(&str) -> Result<(), String>,
) -> Result<(), String> {
    run_kind(which, quick, say).map_err(|m| {
        if m.ends_with('\n') {
            m
        } else {
            format!("error: {m}\n")
        }
    })
}

fn run_kind(
    which: Kind,
    quick: bool,
    say: &dyn Fn(&str) -> Result<(), String>,
) -> Result<(), String> {
    let io = |e: std::io::Error| format!("error: cannot write the CSV: {e}\n");
    match which {
        Kind::WorkPrecision => {
            let (periods, repeats) = if quick { (5.0, 1) } else { (100.0, 5) };
            for (label, models, file) in [
                (
                    "microscopic model (spring and rigid-stroke)",
                    vec![Model::Micro, Model::Rigid],
                    "work_precision_micro.csv",
                ),
                (
                    "averaged model",
                    vec![Model::Averaged],
                    "work_precision_averaged.csv",
                ),
            ] {
                let points = work_precision::run(&models, periods, repeats, quick);
                let t = work_precision::table(&points);
                say(&format!("\n{label}, {periods} periods (errors relative to the converged reference; * = Pareto front):\n{}", t.render()))?;
                say(&format!(
                    "\nfastest method per error level of the drift:\n{}",
                    work_precision::winners(&points).render()
                ))?;
                t.write_csv(&std::path::Path::new("out/bench").join(file))
                    .map_err(io)?;
                for (k, (config, ..)) in work_precision::CONFIGS.iter().enumerate() {
                    if let Some(f) = plots::work_precision(&points, config) {
                        let png = format!("out/bench/{}_{k}.png", file.trim_end_matches(".csv"));
                        f.save(std::path::Path::new(&png))?;
                        say(&format!("picture: {png}"))?;
                    }
                }
            }
            let long = if quick { 200.0 } else { 1e4 };
            let points = work_precision::long_horizon(long);
            let t = work_precision::table(&points);
            say(&format!("\nlong horizon, spring model, {long} periods (errors against dopri5(1e-10) run directly; * = Pareto front):\n{}", t.render()))?;
            t.write_csv(std::path::Path::new("out/bench/work_precision_long.csv"))
                .map_err(io)?;
            if let Some(p) = points.first() {
                if let Some(f) = plots::work_precision(&points, &p.config) {
                    let png = "out/bench/work_precision_long.png";
                    f.save(std::path::Path::new(png))?;
                    say(&format!("picture: {png}"))?;
                }
            }
            say("\nCSV written to out/bench/")?;
        }
        Kind::Stability => {
            let rows = stability::run(quick);
            let t = stability::table(&rows);
            say(&format!("largest stable step (bisection on dt*rate, 4 periods of an isolated asymmetric dumbbell):\n{}", t.render()))?;
            t.write_csv(std::path::Path::new("out/bench/stability.csv"))
                .map_err(io)?;
            say("\nCSV written to out/bench/stability.csv")?;
        }
        Kind::Pairs => {
            let n = 4096;
            let t = pairs::run(n, if quick { 3 } else { 11 });
            say(&format!(
                "RPY product u_i = sum_j H_ij F_j, N = {n} spheres, N(N-1) interactions per product, vector unit {} (medians):\n{}",
                crate::engine::simd::vector_unit(),
                t.render()
            ))?;
            t.write_csv(std::path::Path::new("out/bench/pairs.csv"))
                .map_err(io)?;
            say("\nCSV written to out/bench/pairs.csv")?;
        }
        Kind::Ewald => {
            let tol = crate::engine::ewald::DEFAULT_EWALD_TOL;
            let (max, beenakker_max) = if quick { (512, 512) } else { (15625, 15625) };
            let rows = ewald::run(max, beenakker_max, tol)?;
            let t = ewald::table(&rows);
            say(&format!(
                "periodic RPY product u = M F in a cube, tolerance {tol:e}, one sphere per (8 um)^3 on a jittered lattice ({} threads; medians of 3-5; open space: the all-pairs kernel at the same positions):\n{}",
                rayon::current_num_threads(),
                t.render()
            ))?;
            match ewald::crossover(&rows) {
                Some(n) => say(&format!("spectral is faster from {n} spheres in this table; \"auto\" switches at {}", ewald::auto_threshold()))?,
                None => say(&format!("spectral is not faster at any size measured with both; \"auto\" switches at {}", ewald::auto_threshold()))?,
            }
            t.write_csv(std::path::Path::new("out/bench/ewald.csv"))
                .map_err(io)?;
            say("\nCSV written to out/bench/ewald.csv")?;
        }
        Kind::Boundaries { ewald_tol } => {
            let sizes: &[usize] = if quick {
                &[100]
            } else {
                &[16, 64, 100, 256, 1000]
            };
            let rows = boundaries::run(sizes, ewald_tol)?;
            let t = boundaries::table(&rows);
            say(&format!(
                "one right-hand side, random Fig-1 swimmers at sphere volume fraction {}, the same state in open space, a periodic box (its sums to ewald_tol: {}) and above a wall ({} threads; medians):\n{}",
                boundaries::PHI,
                match ewald_tol {
                    Some(t) => format!("{t:e}, as asked"),
                    None => "the default, a tenth of the default integrator's drift tolerance".into(),
                },
                rayon::current_num_threads(),
                t.render()
            ))?;
            t.write_csv(std::path::Path::new("out/bench/boundaries.csv"))
                .map_err(io)?;
            say("\nCSV written to out/bench/boundaries.csv")?;
        }
        Kind::Scaling => {
            let rows = scaling::run(if quick { 256 } else { 4096 })?;
            let t = scaling::table(&rows);
            let gpu = rows
                .iter()
                .any(|r| r.line.backend == crate::engine::Backend::Gpu);
            say(&format!(
                "cost per stroke period ({} CPU threads{}; lattice scenes 3 ell apart, RK4: micro at its default step, averaged one step per period; the cutoff series up to 8x larger):\n{}",
                rayon::current_num_threads(),
                match crate::engine::gpu::device() {
                    Ok(d) => format!("; gpu: {}", d.describe()),
                    Err(_) => "; no GPU adapter: CPU series only".into(),
                },
                t.render()
            ))?;
            for line in scaling::series(gpu) {
                for from in [2, 256] {
                    if let Some((k, c)) = scaling::fit(&rows, &line, from) {
                        say(&format!(
                            "{}: cost per period ~ {c:.2e} s * S^{k:.2} (fit over S >= {from})",
                            scaling::label(&line)
                        ))?;
                    }
                }
            }
            t.write_csv(std::path::Path::new("out/bench/scaling.csv"))
                .map_err(io)?;
            plots::scaling(&rows).save(std::path::Path::new("out/bench/scaling.png"))?;
            say("picture: out/bench/scaling.png")?;
            say("\nCSV written to out/bench/scaling.csv")?;
        }
        Kind::Contacts => {
            let rows = contacts::run(quick)?;
            let t = contacts::table(&rows);
            say(&format!(
                "whole runs from placement at auto({}), the density study's swimmers and contact law at sphere volume fraction {}, seed 1001 ({} threads):\n{}",
                contacts::TOL,
                contacts::PHI,
                rayon::current_num_threads(),
                t.render()
            ))?;
            t.write_csv(std::path::Path::new("out/bench/contacts.csv"))
                .map_err(io)?;
            say("\nCSV written to out/bench/contacts.csv")?;
        }
        Kind::Suspension => run_suspension(quick, say)?,
        Kind::View => {
            let (n, steps, rounds) = if quick {
                (1000, 20, 1)
            } else {
                (10_000, 100, 3)
            };
            let t = live_view::run(n, steps, rounds).map_err(|e| e.to_string())?;
            say(&format!(
                "\n{n} swimmers (averaged model, box at phi = 0.1%, cutoff), {steps} RK4 steps of T/20, median of {rounds} rounds; frames at most 30 a second:\n{}",
                t.render()
            ))?;
            let (secs, bytes) = live_view::encoding(n).map_err(|e| e.to_string())?;
            say(&format!(
                "encoding one frame of {n} swimmers: {:.2} ms, {:.2} MB",
                secs * 1e3,
                bytes as f64 / 1e6
            ))?;
            t.write_csv(std::path::Path::new("out/bench/view.csv"))
                .map_err(io)?;
            say("\nCSV written to out/bench/view.csv")?;
        }
        Kind::Backends => {
            match crate::engine::gpu::device() {
                Ok(d) => say(&format!("GPU adapter: {}", d.describe()))?,
                Err(e) => say(&format!("GPU: {e}"))?,
            }
            let rows = backends::run(if quick { 1024 } else { 16384 });
            let t = backends::table(&rows);
            say(&format!("wall time per RK4 step (one process, medians not taken; '-' = over the time budget or no adapter):\n{}", t.render()))?;
            for m in [Model::Micro, Model::Averaged] {
                match backends::measured_crossover(&rows, m) {
                    Some(n) => say(&format!(
                        "{}: the GPU is faster from {n} in this table",
                        m.name()
                    ))?,
                    None => say(&format!(
                        "{}: the GPU is not faster at any size in this table",
                        m.name()
                    ))?,
                }
            }
            for (m, detail) in backends::auto_thresholds() {
                say(&format!("auto calibration, {}: {detail}", m.name()))?;
            }
            t.write_csv(std::path::Path::new("out/bench/backends.csv"))
                .map_err(io)?;
            plots::backends(&rows).save(std::path::Path::new("out/bench/backends.png"))?;
            say("picture: out/bench/backends.png")?;
            say("\nCSV written to out/bench/backends.csv")?;
        }
    }
    Ok(())
}

/// `swimlab bench suspension`: the figures of the bulk suspension (see [`suspension`]).
fn run_suspension(quick: bool, say: &dyn Fn(&str) -> Result<(), String>) -> Result<(), String> {
    let e = |e: crate::engine::EngineError| e.to_string();
    let io = |e: std::io::Error| format!("error: cannot write the CSV: {e}\n");
    let d = crate::engine::Dumbbell::default();
    let (n, m, rounds) = if quick {
        (2000, 256, 3)
    } else {
        (10_000, 1024, 9)
    };
    say(&format!(
        "one right-hand side, {n} swimmers at phi = 0.1% in a box, cutoff 6 ell (neighbour lists), against {m} swimmers all pairs (lanes), {} threads, vector unit {}, alternating rounds of 5:",
        rayon::current_num_threads(),
        crate::engine::simd::vector_unit()
    ))?;
    let bulk = suspension::bulk_scene(n, d, 1e-3, 2026).map_err(e)?;
    let dense = suspension::dense_scene(m, d).map_err(e)?;
    let r = suspension::rhs_rounds(&bulk, &dense, rounds, 5).map_err(e)?;
    let t = suspension::rhs_table(n, m, &r);
    say(&t.render())?;
    say(&format!(
        "median ratio {:.3}",
        suspension::median(r.iter().map(|r| r.suspension / r.dense).collect())
    ))?;
    t.write_csv(std::path::Path::new("out/bench/suspension_rhs.csv"))
        .map_err(io)?;
    let placed = if quick { 10_000 } else { 100_000 };
    let secs = suspension::placement_seconds(placed, d, 1e-3, 7).map_err(e)?;
    say(&format!(
        "\nadd_random of {placed} swimmers in a box at phi = 0.1% with gap: ell: {secs:.2} s"
    ))?;
    let (periods, tols): (f64, &[f64]) = if quick {
        (10.0, &[1e-2, 1e-3])
    } else {
        (100.0, &[1e-2, 1e-3, 1e-4, 1e-5])
    };
    let (reference, rows) = suspension::accuracy(periods, tols).map_err(e)?;
    let mut t = crate::bench::table::Table::new(&[
        "tol",
        "error / rms displacement",
        "steps",
        "rhs",
        "seconds",
    ]);
    for (tol, err, steps, rhs, secs) in &rows {
        t.rows.push(vec![
            format!("{tol:e}"),
            format!("{err:.3e}"),
            steps.to_string(),
            rhs.to_string(),
            format!("{secs:.2}"),
        ]);
    }
    say(&format!(
        "\naccuracy: 1,000 swimmers at phi = 0.3% placed ell/2 apart, {periods} periods, suspension(tol) against rk4(T/128) (which differs from rk4(T/256) by {reference:.2e}):\n{}",
        t.render()
    ))?;
    for w in rows.windows(2) {
        let order = (w[0].1 / w[1].1).ln() / (w[1].2 as f64 / w[0].2 as f64).ln();
        say(&format!(
            "error against steps from tol {:e} to {:e}: order {order:.2}",
            w[0].0, w[1].0
        ))?;
    }
    t.write_csv(std::path::Path::new("out/bench/suspension_accuracy.csv"))
        .map_err(io)?;
    let plan: &[(usize, f64, usize)] = if quick {
        &[(500, 200.0, 2), (2000, 200.0, 2)]
    } else {
        &[(1000, 1e4, 10), (10_000, 1e4, 10), (100_000, 1e3, 1)]
    };
    let first = if quick { 200.0 } else { 1000.0 };
    let per_first = format!("s per swimmer-period (first {first} periods)");
    let mut integrator = String::new();
    let mut t = crate::bench::table::Table::new(&[
        "swimmers",
        "periods",
        "seconds",
        &per_first,
        "steps",
        "rejected",
        "rhs",
        "refined steps",
    ]);

    for &(n, periods, stretches) in plan {
        let run = suspension::run_bulk(n, periods, stretches, 2026).map_err(e)?;
        let (_, secs) = *run.stretches.last().unwrap_or(&(0.0, 0.0));
        let st = run.stats;
        if integrator.is_empty() {
            say(&format!("integrator: {}", run.integrator))?;
            integrator = run.integrator.clone();
        }
        say(&format!("{n} swimmers, {periods} periods: {secs:.1} s"))?;
        t.rows.push(vec![
            n.to_string(),
            format!("{periods}"),
            format!("{secs:.1}"),
            run.cost_per_swimmer_period(first)
                .map_or("-".into(), |c| format!("{c:.3e}")),
            st.steps.to_string(),
            st.rejected.to_string(),
            st.rhs_evals.to_string(),
            st.refined_steps.to_string(),
        ]);
    }
    say(&format!("\nbulk suspensions at phi = 0.1% (box, cutoff 6 ell, steric rods, the default integrator):\n{}", t.render()))?;
    t.write_csv(std::path::Path::new("out/bench/suspension_runs.csv"))
        .map_err(io)?;
    say("\nCSV written to out/bench/suspension_*.csv")?;
    Ok(())
}
