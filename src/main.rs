//! The `swimlab` command line: a thin layer over `swimlab::script` and `swimlab::repl`.

use clap::{Parser, Subcommand};
use rhai::{Dynamic, Scope};
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

fn main() -> ExitCode {
    let cli = Cli::parse();
    let mut scope = Scope::new();
    let result = if let Some(expr) = cli.eval {
        let engine = swimlab::script::engine();
        match engine.eval_with_scope::<Dynamic>(&mut scope, &expr) {
            Ok(v) => {
                if !v.is_unit() {
                    println!("{}", swimlab::script::show(&v));
                }
                Ok(())
            }
            Err(e) => Err(swimlab::script::render_error("-e", &expr, &e)),
        }
    } else {
        match cli.command {
            Some(Command::Run { file, quick, set }) => {
                if quick {
                    // Read by `quick()` in scripts; set before any other thread exists.
                    std::env::set_var("SWIMLAB_QUICK", "1");
                }
                let mut res = Ok(());
                for item in &set {
                    match parse_set(item) {
                        Ok((name, v)) => {
                            scope.push_constant_dynamic(name, v);
                        }
                        Err(e) => {
                            res = Err(format!("{e}\n"));
                            break;
                        }
                    }
                }
                res.and_then(|()| match file {
                    Some(path) => swimlab::script::run_file(&path, &mut scope),
                    None => swimlab::script::run_source(
                        "scripts/pair.rhai (built in)",
                        DEFAULT_SCRIPT,
                        &mut scope,
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
            ExitCode::FAILURE
        }
    }
}
