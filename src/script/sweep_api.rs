//! `sweep(params, |p| ...)`: run one closure per parameter on all cores and collect the results.
//!
//! Each call is independent (it should build its own scene); the calls run on rayon's threads,
//! the results come back in the order of `params`, and the first failing call (in that order)
//! is the error, naming its parameter. Ctrl-C stops every call between statements.

use super::convert::{script_error, ScriptResult};
use super::docs::{doc_entry, Doc};
use rayon::prelude::*;
use rhai::{Array, Dynamic, Engine, EvalAltResult, FnPtr, NativeCallContext, INT};

/// Threads per core a sweep may ask for: more only adds switching (the calls compute, they do
/// not wait).
pub const MAX_THREADS_PER_CORE: usize = 4;

/// Run `f(p)` for every `p` in `params` on `threads` threads (`None`: rayon's pool, one per core).
///
/// The call context is stored and re-created on each thread: Rhai's documented way to call a
/// function pointer outside the native call (`internals`; marked volatile, hence the allow).
#[allow(deprecated)]
fn sweep(
    ctx: &NativeCallContext,
    params: Array,
    f: FnPtr,
    threads: Option<usize>,
) -> ScriptResult<Array> {
    let store = ctx.store_data();
    let engine = ctx.engine();
    let call = |(k, p): (usize, &Dynamic)| -> Result<Dynamic, (usize, Box<EvalAltResult>)> {
        let ctx = store.create_context(engine);
        f.call_within_context::<Dynamic>(&ctx, (p.clone(),))
            .map_err(|e| (k, e))
    };
    let run = || -> Vec<Result<Dynamic, (usize, Box<EvalAltResult>)>> {
        params.par_iter().enumerate().map(call).collect()
    };
    let results = match threads {
        None => run(),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| script_error(format!("sweep: cannot start {n} threads: {e}")))?
            .install(run),
    };
    results
        .into_iter()
        .map(|r| {
            r.map_err(|(k, e)| {
                script_error(format!(
                    "sweep: the call for parameter {k} ({}) failed: {}",
                    params[k],
                    e.to_string().trim_end()
                ))
            })
        })
        .collect()
}

/// Register `sweep`.
pub fn register(engine: &mut Engine) {
    engine
        .register_fn(
            "sweep",
            |ctx: NativeCallContext, params: Array, f: FnPtr| -> ScriptResult<Array> {
                sweep(&ctx, params, f, None)
            },
        )
        .register_fn(
            "sweep",
            |ctx: NativeCallContext,
             params: Array,
             f: FnPtr,
             threads: INT|
             -> ScriptResult<Array> {
                if threads < 1 {
                    return Err(script_error(format!(
                        "sweep(params, f, threads): threads must be at least 1, got {threads}"
                    )));
                }
                let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
                let most = MAX_THREADS_PER_CORE * cores;
                if threads as usize > most {
                    return Err(script_error(format!(
                        "sweep(params, f, threads): {threads} threads on a machine with {cores} cores; at most {most} ({MAX_THREADS_PER_CORE} per core) are useful: give fewer, or leave threads out to use one per core"
                    )));
                }
                sweep(&ctx, params, f, Some(threads as usize))
            },
        );
}

/// The help text of this file's script names (`:help NAME`), gathered by [`super::docs`].
pub(super) const DOCS: &[Doc] = &[
    doc_entry!("sweep", "scene", "sweep(params: array, f) -> array\nsweep(params: array, f, threads: int) -> array", "Call f(p) for every p of params on all cores (or on `threads` threads) and return the results in the order of params. Each call should build its own scene; results may be numbers, strings, arrays or maps. The first failing call is the error, naming its parameter. For clusters, run one process per parameter instead: swimlab run script.rhai --set D=10 (README, Sweeps).", "let r = sweep([1, 2, 3], |p| p * p); print(r);"),
];
