//! The `swimlab` command line: a thin layer over `swimlab::script` and `swimlab::repl`.

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;
use swimlab::script::params;

/// The experiment run by `swimlab run` without a file: the paper's Fig-1 pair.
const DEFAULT_SCRIPT: &str = include_str!("../scripts/pair.rhai");

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
        /// Keep the live views the script starts (s.view()) up after it ends well, until Ctrl-C.
        #[arg(long)]
        view: bool,
    },
    /// Run SCRIPT for every point of a parameter grid, each point in its own folder DIR/<index>/
    /// (its working directory: its files, stdout.txt, stderr.txt, status.txt there), as
    /// `swimlab run SCRIPT --set NAME=VALUE ...`; DIR/index.csv lists index, parameters, status
    /// and wall time. A failed point is reported and does not stop the others.
    Sweep {
        /// The experiment script.
        script: PathBuf,
        /// A parameter and its values, e.g. --grid D=5,10,20 (repeat for more; the last varies
        /// fastest).
        #[arg(long = "grid", value_name = "NAME=V1,V2,...", required = true)]
        grid: Vec<String>,
        /// The output folder.
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// Processes at once (default: one per core).
        #[arg(long, value_name = "N")]
        jobs: Option<usize>,
        /// Skip the points that already finished (status ok).
        #[arg(long)]
        resume: bool,
        /// Write DIR/sweep.sbatch, a SLURM job array whose task k runs point k exactly as the
        /// local sweep would, instead of running.
        #[arg(long)]
        slurm: bool,
        /// Run each point's quick variant.
        #[arg(long)]
        quick: bool,
        /// Run point K only (what a SLURM array task does).
        #[arg(long, value_name = "K")]
        task: Option<usize>,
    },
    /// Run as a Jupyter kernel on a connection file (Jupyter starts it so), or install the
    /// kernelspec: `swimlab kernel install [--user | --prefix DIR]`.
    Kernel {
        /// The connection file Jupyter wrote (ports, address, signing key).
        #[arg(short = 'f', value_name = "CONNECTION_FILE")]
        connection_file: Option<PathBuf>,
        #[command(subcommand)]
        action: Option<KernelAction>,
    },
    /// Render every figure of the paper (scripts/paper, built in): CSV and PNG to out/paper/,
    /// and the PNGs also to --out if given (e.g. docs/src/figures for the book).
    MakeFigures {
        /// The scripts' quick variants (fewer points and periods).
        #[arg(long)]
        quick: bool,
        /// Also copy the pictures here.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
    /// Print the reference of every script name and shell command as Markdown: the book's
    /// reference chapter (swimlab reference > docs/src/reference.md), from what :help shows.
    Reference,
}

#[derive(Subcommand)]
enum KernelAction {
    /// Write the kernelspec "swimlab" (kernel.json) so that Jupyter lists this kernel.
    Install {
        /// Into the user's Jupyter data folder (the default).
        #[arg(long, conflicts_with = "prefix")]
        user: bool,
        /// Into DIR/share/jupyter/kernels (an environment's prefix, e.g. a venv).
        #[arg(long, value_name = "DIR")]
        prefix: Option<PathBuf>,
    },
}

impl From<BenchKind> for swimlab::bench::report::Kind {
    fn from(k: BenchKind) -> Self {
        use swimlab::bench::report::Kind;
        match k {
            BenchKind::WorkPrecision => Kind::WorkPrecision,
            BenchKind::Stability => Kind::Stability,
            BenchKind::Backends => Kind::Backends,
            BenchKind::Pairs => Kind::Pairs,
            BenchKind::Scaling => Kind::Scaling,
            BenchKind::Ewald => Kind::Ewald,
            BenchKind::Boundaries { ewald_tol } => Kind::Boundaries { ewald_tol },
            BenchKind::Contacts => Kind::Contacts,
            BenchKind::Suspension => Kind::Suspension,
            BenchKind::View => Kind::View,
        }
    }
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
    /// all cores, against the ~1e9 per core bound; also the row kernel serially, side by side.
    /// Against PyStokes: benches/pystokes/README.md.
    Pairs,
    /// Cost per stroke period against the number of swimmers (2 … 4,096; --quick: up to 256),
    /// microscopic and averaged models on the CPU (the averaged with a cutoff up to 8x larger)
    /// and on the GPU when an adapter is present, with fitted power-law exponents.
    Scaling,
    /// The periodic box's mobility product: Beenakker's Ewald sums against spectral Ewald, 64 …
    /// 15,625 spheres (--quick: up to 512), with open space for scale, the
    /// methods' difference against the tolerance and the crossover "auto" uses.
    Ewald,
    /// One right-hand side of a suspension at volume fraction 1% in a periodic box and above a
    /// wall against the same swimmers in open space, microscopic and rigid-stroke models, 16, 64,
    /// 100, 256 and 1,000 swimmers (--quick: 100), side by side.
    Boundaries {
        /// The box's Ewald tolerance (default: the scene's, a tenth of the default integrator's
        /// drift tolerance).
        #[arg(long, value_name = "TOL")]
        ewald_tol: Option<f64>,
    },
    /// Whole runs of the spring and rigid-stroke models' suspensions in contact (~15 s; --quick:
    /// a second): the density study's 64 swimmers at volume fraction 1% with its rod
    /// repulsion, from placement at auto(1e-4), in open space and in a periodic box, and the
    /// first twentieth of a period of 1,000 rigid swimmers; seconds, right-hand sides and steps
    /// a period.
    Contacts,
    /// Bulk suspensions of the averaged model (~15 min; --quick: ~1 min): one right-hand side of
    /// 10,000 swimmers in a box with a cutoff against 1,024 all pairs, side by side; add_random of
    /// 100,000; suspension(tol)'s error against RK4 and its order; runs of 1,000 and 10,000
    /// swimmers for 1e4 periods and 100,000 for 1e3, the cost per swimmer-period.
    Suspension,
    /// The live view's cost: 10,000 swimmers of the averaged model (--quick: 1,000) for a fixed
    /// number of RK4 steps without a view, with a view no one reads, and with a reader that never
    /// reads beside one that reads every frame, side by side.
    View,
}

fn main() -> ExitCode {
    // Before any thread starts: it may set an environment variable.
    swimlab::script::quiet_device_selection();
    let cli = Cli::parse();
    let result = if let Some(expr) = cli.eval {
        swimlab::script::interrupt::install_batch_handler();
        swimlab::script::eval_expression(&expr).map(|shown| {
            if let Some(v) = shown {
                swimlab::script::console::to_stdout(&format!("{v}\n"));
            }
        })
    } else {
        match cli.command {
            Some(Command::Reference) => {
                swimlab::script::console::emit(&swimlab::repl::reference::markdown())
            }
            Some(Command::Bench { which, quick }) => {
                swimlab::bench::report::run(which.into(), quick, &swimlab::script::console::emit_line)
            }
            Some(Command::Sweep {
                script,
                grid,
                out,
                jobs,
                resume,
                slurm,
                quick,
                task,
            }) => {
                swimlab::script::interrupt::install_batch_handler();
                grid.iter()
                    .map(|g| swimlab::sweep::Axis::parse(g))
                    .collect::<Result<Vec<_>, String>>()
                    .and_then(|axes| {
                        let sweep = swimlab::sweep::Sweep {
                            script,
                            axes,
                            out,
                            jobs: jobs.unwrap_or_else(|| {
                                std::thread::available_parallelism().map_or(1, |n| n.get())
                            }),
                            resume,
                            quick,
                        };
                        match (task, slurm) {
                            (Some(k), _) => sweep.run_task(k),
                            (None, true) => sweep.write_slurm(),
                            (None, false) => sweep.run_local(),
                        }
                    })
            }
            Some(Command::Kernel {
                connection_file,
                action,
            }) => match (action, connection_file) {
                (Some(KernelAction::Install { prefix, .. }), _) => {
                    let target = match prefix {
                        Some(p) => swimlab::repl::kernel::spec::Target::Prefix(p),
                        None => swimlab::repl::kernel::spec::Target::User,
                    };
                    swimlab::repl::kernel::spec::install(&target).and_then(|dir| {
                        swimlab::script::console::emit_line(&format!(
                            "installed the swimlab kernel in {}",
                            dir.display()
                        ))
                    })
                }
                (None, Some(file)) => swimlab::repl::kernel::run(&file),
                (None, None) => Err("swimlab kernel needs a connection file (-f FILE; Jupyter gives one), or `swimlab kernel install` to register the kernel with Jupyter".into()),
            },
            Some(Command::MakeFigures { quick, out }) => {
                swimlab::script::interrupt::install_batch_handler();
                swimlab::script::figures::make_figures(quick, out.as_deref())
            }
            Some(Command::Run {
                file,
                quick,
                set,
                view,
            }) => {
                swimlab::script::interrupt::install_batch_handler();
                if view {
                    swimlab::script::view_api::keep_views();
                }
                let result = set.iter()
                    .map(|item| params::parse_set(item))
                    .collect::<Result<Vec<_>, String>>()
                    .map_err(|e| format!("{e}\n"))
                    .and_then(|sets| {
                        let options = params::RunOptions { quick, sets };
                        match file {
                            Some(path) => swimlab::script::run_file_with(&path, &options),
                            None => swimlab::script::run_source_with(
                                "scripts/pair.rhai (built in)",
                                DEFAULT_SCRIPT,
                                &options,
                            ),
                        }
                    });
                if view && result.is_ok() {
                    swimlab::script::view_api::serve_until_interrupted();
                }
                result
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
            swimlab::script::console::to_stderr(&msg);
            if swimlab::script::interrupt::requested() {
                swimlab::script::console::to_stderr("swimlab: stopped by Ctrl-C (SIGINT); rows streamed to files are complete up to that point\n");
                // The shell convention for a process ended by SIGINT.
                ExitCode::from(130)
            } else {
                ExitCode::FAILURE
            }
        }
    }
}
