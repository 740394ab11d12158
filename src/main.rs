//! The `swimlab` command line: a thin layer over `swimlab::script` and `swimlab::repl`.

use clap::{Parser, Subcommand};
use rhai::{Dynamic, Scope};
use std::path::PathBuf;
use std::process::ExitCode;

/// The experiment run by `swimlab run` without a file: the paper's Fig-1 pair.
const DEFAULT_SCRIPT: &str = include_str!("../scripts/pair.rhai");

/// The paper's figure scripts, built in for `swimlab make-figures`.
const PAPER_SCRIPTS: &[(&str, &str)] = &[
    (
        "scripts/paper/fig1a.rhai",
        include_str!("../scripts/paper/fig1a.rhai"),
    ),
    (
        "scripts/paper/fig1b.rhai",
        include_str!("../scripts/paper/fig1b.rhai"),
    ),
    (
        "scripts/paper/fig2a.rhai",
        include_str!("../scripts/paper/fig2a.rhai"),
    ),
    (
        "scripts/paper/fig2b.rhai",
        include_str!("../scripts/paper/fig2b.rhai"),
    ),
    (
        "scripts/paper/fig3.rhai",
        include_str!("../scripts/paper/fig3.rhai"),
    ),
    (
        "scripts/paper/fig4.rhai",
        include_str!("../scripts/paper/fig4.rhai"),
    ),
];

#[derive(Parser)]
#[command(
    name = "swimlab",
    version,
    about = "Low-Reynolds-number dumbbell swimmers (Putz & Dunkel 2010), scriptable with Rhai",
    long_about = "swimlab simulates pairs and suspensions of oscillating dumbbell swimmers in Stokes flow, \
with the microscopic model (spheres, springs, Rotne-Prager-Yamakawa mobility) and the paper's \
stroke-averaged model, driven by Rhai experiment scripts.\n\n\
Without arguments it starts the interactive shell (also on piped standard input)."
)]
struct Cli {
    /// Evaluate EXPR (Rhai), print its value, and exit.
    #[arg(short = 'e', long = "eval", value_name = "EXPR")]
    eval: Option<String>,
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Benchmarks: work against precision, stability limits. Tables are printed and written as CSV
    /// to out/bench/.
    Bench {
        #[command(subcommand)]
        which: BenchKind,
        /// A short version (fewer methods and repeats).
        #[arg(long, global = true)]
        quick: bool,
    },
    /// Run an experiment script (without FILE: the built-in Fig-1 pair experiment, scripts/pair.rhai).
    Run {
        /// The .rhai script to run.
        file: Option<PathBuf>,
        /// Ask the script for its quick variant (scripts read it as `quick()`).
        #[arg(long)]
        quick: bool,
        /// Define a constant for the script: --set D=10 --set name=mirror (integers, floats,
        /// true/false, or strings). For sweeps run as job arrays.
        #[arg(long = "set", value_name = "NAME=VALUE")]
        set: Vec<String>,
    },
    /// Render every figure of the paper (scripts/paper, built in): CSV and PNG to out/paper/,
    /// and the PNGs also to --out if given (e.g. docs/figures for the README).
    MakeFigures {
        /// The scripts' quick variants (fewer points and periods).
        #[arg(long)]
        quick: bool,
        /// Also copy the pictures here.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
}

#[derive(Subcommand)]
enum BenchKind {
    /// Every integrator on the Fig-1 pairs over 100 periods: error of drift and separation change
    /// against a converged reference, wall time (median of 5), right-hand sides, steps, Pareto front.
    WorkPrecision,
    /// Largest stable step of each explicit method against 2/rate and 2.785/rate.
    Stability,
    /// CPU against GPU: time per RK4 step against size (8 … 16,384 spheres or swimmers; --quick:
    /// up to 1,024), transfers included, both models; the crossover and the "auto" calibration.
    Backends,
    /// The CPU pair kernel: RPY interactions per second at N = 4,096 spheres, serial and on 1 …
    /// all cores, against the ~1e9 per core bound.
    Pairs,
    /// Cost per stroke period against the number of swimmers (2 … 4,096; --quick: up to 256),
    /// microscopic and averaged models on the CPU, with fitted power-law exponents.
    Scaling,
}

fn bench(which: BenchKind, quick: bool) -> Result<(), String> {
    use swimlab::bench::{backends, pairs, plots, scaling, stability, work_precision};
    use swimlab::engine::Model;
    let io = |e: std::io::Error| format!("error: cannot write the CSV: {e}\n");
    match which {
        BenchKind::WorkPrecision => {
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
            println!("\nCSV written to out/bench/");
        }
        BenchKind::Stability => {
            let rows = stability::run(quick);
            let t = stability::table(&rows);
            println!("largest stable step (bisection on dt*rate, 4 periods of an isolated asymmetric dumbbell):\n{}", t.render());
            t.write_csv(std::path::Path::new("out/bench/stability.csv"))
                .map_err(io)?;
            println!("\nCSV written to out/bench/stability.csv");
        }
        BenchKind::Pairs => {
            let n = 4096;
            let t = pairs::run(n, if quick { 3 } else { 11 });
            println!(
                "RPY product u_i = sum_j H_ij F_j, N = {n} spheres, N(N-1) interactions per product, vector unit {} (medians):\n{}",
                swimlab::engine::pairs::vector_unit(),
                t.render()
            );
            t.write_csv(std::path::Path::new("out/bench/pairs.csv"))
                .map_err(io)?;
            println!("\nCSV written to out/bench/pairs.csv");
        }
        BenchKind::Scaling => {
            let rows = scaling::run(if quick { 256 } else { 4096 })?;
            let t = scaling::table(&rows);
            println!(
                "cost per stroke period on the CPU ({} threads; lattice scenes, RK4: micro at its default step, averaged one step per period):\n{}",
                rayon::current_num_threads(),
                t.render()
            );
            for m in [Model::Micro, Model::Averaged] {
                for from in [2, 256] {
                    if let Some((k, c)) = scaling::fit(&rows, m, from) {
                        println!(
                            "{}: cost per period ~ {c:.2e} s * S^{k:.2} (fit over S >= {from})",
                            m.name()
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
        BenchKind::Backends => {
            match swimlab::engine::gpu::device() {
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

/// Parse `NAME=VALUE` into a Rhai constant.
fn parse_set(item: &str) -> Result<(String, Dynamic), String> {
    let (name, value) = item
        .split_once('=')
        .ok_or_else(|| format!("error: --set {item}: expected NAME=VALUE, such as --set D=10"))?;
    let valid = name
        .chars()
        .next()
        .is_some_and(|c| c.is_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_alphanumeric() || c == '_');
    if !valid {
        return Err(format!(
            "error: --set {item}: \"{name}\" is not a valid variable name (letters, digits, _)"
        ));
    }
    let v = if let Ok(i) = value.parse::<i64>() {
        Dynamic::from_int(i)
    } else if let Ok(f) = value.parse::<f64>() {
        Dynamic::from_float(f)
    } else if let Ok(b) = value.parse::<bool>() {
        Dynamic::from_bool(b)
    } else {
        Dynamic::from(value.to_string())
    };
    Ok((name.to_string(), v))
}

/// Run the built-in figure scripts and copy their pictures to `out`.
fn make_figures(quick: bool, out: Option<&std::path::Path>) -> Result<(), String> {
    if quick {
        std::env::set_var("SWIMLAB_QUICK", "1");
    }
    for (name, source) in PAPER_SCRIPTS {
        let start = std::time::Instant::now();
        swimlab::script::run_source(name, source, &mut Scope::new())?;
        println!("{name}: {:.1} s", start.elapsed().as_secs_f64());
    }
    if let Some(dir) = out {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
        let entries =
            std::fs::read_dir("out/paper").map_err(|e| format!("cannot read out/paper: {e}"))?;
        for entry in entries.flatten() {
            let path = entry.path();
            if path.extension().is_some_and(|e| e == "png") {
                let to = dir.join(entry.file_name());
                std::fs::copy(&path, &to)
                    .map_err(|e| format!("cannot copy to {}: {e}", to.display()))?;
                println!("copied {}", to.display());
            }
        }
    }
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = if let Some(expr) = cli.eval {
        swimlab::script::interrupt::install_batch_handler();
        swimlab::script::eval_expression(&expr).map(|shown| {
            if let Some(v) = shown {
                println!("{v}");
            }
        })
    } else {
        match cli.command {
            Some(Command::Bench { which, quick }) => bench(which, quick),
            Some(Command::MakeFigures { quick, out }) => {
                swimlab::script::interrupt::install_batch_handler();
                make_figures(quick, out.as_deref())
            }
            Some(Command::Run { file, quick, set }) => {
                swimlab::script::interrupt::install_batch_handler();
                if quick {
                    // Read by `quick()` in scripts; set before any other thread exists.
                    std::env::set_var("SWIMLAB_QUICK", "1");
                }
                set.iter()
                    .map(|item| parse_set(item))
                    .collect::<Result<Vec<_>, String>>()
                    .map_err(|e| format!("{e}\n"))
                    .and_then(|sets| match file {
                        Some(path) => swimlab::script::run_file_with(&path, &sets),
                        None => swimlab::script::run_source_with(
                            "scripts/pair.rhai (built in)",
                            DEFAULT_SCRIPT,
                            &sets,
                        ),
                    })
            }
            None => {
                return if swimlab::repl::run() {
                    ExitCode::SUCCESS
                } else {
                    ExitCode::FAILURE
                };
            }
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(msg) => {
            eprint!("{msg}");
            if swimlab::script::interrupt::requested() {
                eprintln!("swimlab: stopped by Ctrl-C (SIGINT); rows streamed to files are complete up to that point");
                // The shell convention for a process ended by SIGINT.
                ExitCode::from(130)
            } else {
                ExitCode::FAILURE
            }
        }
    }
}
