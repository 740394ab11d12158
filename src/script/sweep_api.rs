//! `sweep(params, |p| ...)`: run one closure per parameter on all cores and collect the results.
//!
//! Each call is independent (it should build its own scene); the calls run on rayon's threads,
//! the results come back in the order of `params`, and the first failing call (in that order)
//! is the error, naming its parameter. Ctrl-C stops every call between statements.
//!
//! A scene or continuum that every call reaches (captured by the closure, or given in more than
//! one parameter) is shared by calls running at once: they may read it (properties, observe,
//! copy, save) but not change it, which would race and make the results change from run to run;
//! a change is an error naming the fix (build it in the call, or change a copy).

use super::continuum_api::ContinuumHandle;
use super::convert::{script_error, ScriptResult};
use super::doc::{doc_entry, Doc};
use super::observable_api::RecorderHandle;
use super::scene_api::{SceneHandle, SweepShare};
use rayon::prelude::*;
use rhai::{Array, Dynamic, Engine, EvalAltResult, FnPtr, Map, NativeCallContext, INT};

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
    // Scenes and continuums the calls share: the closure's captures, and any reached from two
    // parameters.
    let mut shared = Reached::default();
    if params.len() > 1 {
        for v in f.curry() {
            reached_from(v, &mut shared, 0);
        }
        let mut seen = Reached::default();
        for p in &params {
            let mut here = Reached::default();
            reached_from(p, &mut here, 0);
            for h in here.scenes {
                if seen.scenes.iter().any(|s| s.is_same_as(&h)) {
                    shared.scenes.push(h);
                } else {
                    seen.scenes.push(h);
                }
            }
            for h in here.continuums {
                if seen.continuums.iter().any(|c| c.is_same_as(&h)) {
                    shared.continuums.push(h);
                } else {
                    seen.continuums.push(h);
                }
            }
        }
    }
    let mut scenes: Vec<SceneHandle> = Vec::new();
    for h in shared.scenes {
        if !scenes.iter().any(|u| u.is_same_as(&h)) {
            scenes.push(h);
        }
    }
    let mut continuums: Vec<ContinuumHandle> = Vec::new();
    for h in shared.continuums {
        if !continuums.iter().any(|u| u.is_same_as(&h)) {
            continuums.push(h);
        }
    }
    let _shared = SweepShare::new(
        scenes
            .iter()
            .map(|h| h.sweeps().clone())
            .chain(continuums.iter().map(|h| h.sweeps().clone()))
            .collect(),
    );
    // Captured scenes and continuums reach the calls as their handles, not as the captured
    // variables: Rhai holds a captured variable's lock through a whole method call on it, so calls
    // running at once would find it taken (its bare "Data race detected", after a few
    // milliseconds) where the handle's own lock waits its turn, and the share refuses changes. (A
    // call that assigns such a variable anew changes its own copy only.)
    let mut f = f;
    let curry: Vec<Dynamic> = f
        .curry()
        .iter()
        .map(|v| {
            let handle = v.read_lock::<SceneHandle>().is_some()
                || v.read_lock::<ContinuumHandle>().is_some();
            if v.is_shared() && handle {
                v.flatten_clone()
            } else {
                v.clone()
            }
        })
        .collect();
    f.set_curry(curry);
    let store = ctx.store_data();
    let engine = ctx.engine();
    // The calls answer the caller's interrupt: scenes they build take it on rayon's threads.
    let stop = super::interrupt::current();
    let call = |(k, p): (usize, &Dynamic)| -> Result<Dynamic, (usize, Box<EvalAltResult>)> {
        super::interrupt::scoped(&stop, || {
            let ctx = store.create_context(engine);
            f.call_within_context::<Dynamic>(&ctx, (p.clone(),))
                .map_err(|e| (k, e))
        })
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
                    super::show::quote(&params[k]),
                    super::render::message_of(&e)
                ))
            })
        })
        .collect()
}

/// Nesting deeper than this is not searched for scenes (values nest arrays, maps and closures).
const MAX_DEPTH: usize = 32;

/// The scenes and continuums a value reaches.
#[derive(Default)]
struct Reached {
    scenes: Vec<SceneHandle>,
    continuums: Vec<ContinuumHandle>,
}

/// The scenes and continuums `v` reaches: itself, a recorder's scene, and those in arrays, maps
/// and the captures of closures.
fn reached_from(v: &Dynamic, out: &mut Reached, depth: usize) {
    if depth > MAX_DEPTH {
        return;
    }
    if let Some(h) = v.read_lock::<SceneHandle>() {
        out.scenes.push(h.clone());
    } else if let Some(c) = v.read_lock::<ContinuumHandle>() {
        out.continuums.push(c.clone());
    } else if let Some(r) = v.read_lock::<RecorderHandle>() {
        out.scenes.push(r.scene.clone());
    } else if let Some(a) = v.read_lock::<Array>() {
        a.iter().for_each(|x| reached_from(x, out, depth + 1));
    } else if let Some(m) = v.read_lock::<Map>() {
        m.values().for_each(|x| reached_from(x, out, depth + 1));
    } else if let Some(f) = v.read_lock::<FnPtr>() {
        f.curry()
            .iter()
            .for_each(|x| reached_from(x, out, depth + 1));
    }
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
    doc_entry!("sweep", "scene", "sweep(params: array, f) -> array\nsweep(params: array, f, threads: int) -> array", "Call f(p) for every p of params on all cores (or on `threads` threads) and return the results in the order of params. Each call should build its own scene; results may be numbers, strings, arrays or maps. A scene or continuum every call reaches (captured by f, or given in more than one parameter) is shared by calls that run at once: they may read it (properties, observe, modes, copy, save, c.sample) but not change it (run, settings, recorders, c.perturb), which would race and make the results change from run to run; such a change is an error: build it inside f, or change a copy (|p| { let t = s.copy(); t.run_periods(p); t.time }). The first failing call is the error, naming its parameter. For clusters, run one process per parameter instead: swimlab run script.rhai --set D=10 (the book: Trajectories, sweeps and clusters).", "let r = sweep([1, 2, 3], |p| p * p); print(r);"),
];
