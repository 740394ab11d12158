//! `swimlab bench ...`: each benchmark's tables printed and written as CSV, with its pictures,
//! under out/bench/. The command line only names the benchmark.

use super::{backends, ewald, pairs, plots, scaling, stability, work_precision};
use crate::engine::Model;

/// The benchmarks `swimlab bench` runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
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
}

/// Run one benchmark, print its tables and write its CSV and pictures under out/bench/.
pub fn run(which: Kind, quick: bool) -> Result<(), String> {
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
                println!("\n{label}, {periods} periods (errors relative to the converged reference; * = Pareto front):\n{}", t.render());
                println!(
                    "\nfastest method per error level of the drift:\n{}",
                    work_precision::winners(&points).render()
                );
                t.write_csv(&std::path::Path::new("out/bench").join(file))
                    .map_err(io)?;
                for (k, (config, ..)) in work_precision::CONFIGS.iter().enumerate() {
                    if let Some(f) = plots::work_precision(&points, config) {
                        let png = format!("out/bench/{}_{k}.png", file.trim_end_matches(".csv"));
                        f.save(std::path::Path::new(&png))?;
                        println!("picture: {png}");
                    }
                }
            }
            let long = if quick { 200.0 } else { 1e4 };
            let points = work_precision::long_horizon(long);
            let t = work_precision::table(&points);
            println!("\nlong horizon, spring model, {long} periods (errors against dopri5(1e-10) run directly; * = Pareto front):\n{}", t.render());
            t.write_csv(std::path::Path::new("out/bench/work_precision_long.csv"))
                .map_err(io)?;
            if let Some(p) = points.first() {
                if let Some(f) = plots::work_precision(&points, &p.config) {
                    let png = "out/bench/work_precision_long.png";
                    f.save(std::path::Path::new(png))?;
                    println!("picture: {png}");
                }
            }
            println!("\nCSV written to out/bench/");
        }
        Kind::Stability => {
            let rows = stability::run(quick);
            let t = stability::table(&rows);
            println!("largest stable step (bisection on dt*rate, 4 periods of an isolated asymmetric dumbbell):\n{}", t.render());
            t.write_csv(std::path::Path::new("out/bench/stability.csv"))
                .map_err(io)?;
            println!("\nCSV written to out/bench/stability.csv");
        }
        Kind::Pairs => {
            let n = 4096;
            let t = pairs::run(n, if quick { 3 } else { 11 });
            println!(
                "RPY product u_i = sum_j H_ij F_j, N = {n} spheres, N(N-1) interactions per product, vector unit {} (medians):\n{}",
                crate::engine::simd::vector_unit(),
                t.render()
            );
            t.write_csv(std::path::Path::new("out/bench/pairs.csv"))
                .map_err(io)?;
            println!("\nCSV written to out/bench/pairs.csv");
        }
        Kind::Ewald => {
            let tol = crate::engine::ewald::DEFAULT_EWALD_TOL;
            let (max, beenakker_max) = if quick { (512, 512) } else { (15625, 4096) };
            let rows = ewald::run(max, beenakker_max, tol)?;
            let t = ewald::table(&rows);
            println!(
                "periodic RPY product u = M F in a cube, tolerance {tol:e}, one sphere per (8 um)^3 on a jittered lattice ({} threads; medians of 3-5; open space: the all-pairs kernel at the same positions):\n{}",
                rayon::current_num_threads(),
                t.render()
            );
            match ewald::crossover(&rows) {
                Some(n) => println!("spectral is faster from {n} spheres in this table; \"auto\" switches at {}", ewald::auto_threshold()),
                None => println!("spectral is not faster at any size measured with both; \"auto\" switches at {}", ewald::auto_threshold()),
            }
            t.write_csv(std::path::Path::new("out/bench/ewald.csv"))
                .map_err(io)?;
            println!("\nCSV written to out/bench/ewald.csv");
        }
        Kind::Scaling => {
            let rows = scaling::run(if quick { 256 } else { 4096 })?;
            let t = scaling::table(&rows);
            let gpu = rows
                .iter()
                .any(|r| r.line.backend == crate::engine::Backend::Gpu);
            println!(
                "cost per stroke period ({} CPU threads{}; lattice scenes 3 ell apart, RK4: micro at its default step, averaged one step per period; the cutoff series up to 8x larger):\n{}",
                rayon::current_num_threads(),
                match crate::engine::gpu::device() {
                    Ok(d) => format!("; gpu: {}", d.describe()),
                    Err(_) => "; no GPU adapter: CPU series only".into(),
                },
                t.render()
            );
            for line in scaling::series(gpu) {
                for from in [2, 256] {
                    if let Some((k, c)) = scaling::fit(&rows, &line, from) {
                        println!(
                            "{}: cost per period ~ {c:.2e} s * S^{k:.2} (fit over S >= {from})",
                            scaling::label(&line)
                        );
                    }
                }
            }
            t.write_csv(std::path::Path::new("out/bench/scaling.csv"))
                .map_err(io)?;
            plots::scaling(&rows).save(std::path::Path::new("out/bench/scaling.png"))?;
            println!("picture: out/bench/scaling.png");
            println!("\nCSV written to out/bench/scaling.csv");
        }
        Kind::Backends => {
            match crate::engine::gpu::device() {
                Ok(d) => println!("GPU adapter: {}", d.describe()),
                Err(e) => println!("GPU: {e}"),
            }
            let rows = backends::run(if quick { 1024 } else { 16384 });
            let t = backends::table(&rows);
            println!("wall time per RK4 step (one process, medians not taken; '-' = over the time budget or no adapter):\n{}", t.render());
            for m in [Model::Micro, Model::Averaged] {
                match backends::measured_crossover(&rows, m) {
                    Some(n) => println!("{}: the GPU is faster from {n} in this table", m.name()),
                    None => println!(
                        "{}: the GPU is not faster at any size in this table",
                        m.name()
                    ),
                }
            }
            for (m, detail) in backends::auto_thresholds() {
                println!("auto calibration, {}: {detail}", m.name());
            }
            t.write_csv(std::path::Path::new("out/bench/backends.csv"))
                .map_err(io)?;
            plots::backends(&rows).save(std::path::Path::new("out/bench/backends.png"))?;
            println!("picture: out/bench/backends.png");
            println!("\nCSV written to out/bench/backends.csv");
        }
    }
    Ok(())
}
