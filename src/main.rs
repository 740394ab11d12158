//! The `swimlab` command line: a thin layer over `swimlab::script`.

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// The experiment run by `swimlab run` without a file: the paper's Fig-1 pair.
const DEFAULT_SCRIPT: &str = include_str!("../scripts/pair.rhai");

#[derive(Parser)]
#[command(
    name = "swimlab",
    version,
    about = "Low-Reynolds-number dumbbell swimmers (Putz & Dunkel 2010), scriptable with Rhai",
    long_about = "swimlab simulates pairs and suspensions of oscillating dumbbell swimmers in Stokes flow, \
with the microscopic model (spheres, springs, Rotne-Prager-Yamakawa mobility) and the paper's \
stroke-averaged model, driven by Rhai experiment scripts."
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Run an experiment script (without FILE: the built-in Fig-1 pair experiment, scripts/pair.rhai).
    Run {
        /// The .rhai script to run.
        file: Option<PathBuf>,
        /// Ask the script for its quick variant (scripts read it as `quick()`).
        #[arg(long)]
        quick: bool,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let mut scope = rhai::Scope::new();
    if let Some(Command::Run { quick: true, .. }) = cli.command {
        // Read by `quick()` in scripts; set before any script thread exists.
        std::env::set_var("SWIMLAB_QUICK", "1");
    }
    let result = match cli.command {
        Some(Command::Run {
            file: Some(path), ..
        }) => swimlab::script::run_file(&path, &mut scope),
        Some(Command::Run { file: None, .. }) => {
            swimlab::script::run_source("scripts/pair.rhai (built in)", DEFAULT_SCRIPT, &mut scope)
        }
        None => {
            use clap::CommandFactory;
            let _ = Cli::command().print_help();
            Ok(())
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(msg) => {
            eprint!("{msg}");
            ExitCode::FAILURE
        }
    }
}
