//! Running a scene from a script: `s.run`, `s.run_periods`, `s.run_to`, `s.run_to_periods`
//! (each with a progress bar at a terminal, stopped by Ctrl-C), and the work counters `s.stats`.

use super::convert::{number, ScriptResult};
use super::doc::{doc_entry, Doc};
use super::scene_api::SceneHandle;
use crate::engine::Simulation;
use rhai::{Dynamic, Engine, INT};

/// Run `f` with a progress bar over the next `duration` seconds (only at a terminal).
fn with_bar<T>(
    sc: &mut Simulation,
    duration: f64,
    f: impl FnOnce(&mut Simulation) -> crate::engine::Result<T>,
) -> crate::engine::Result<T> {
    let (t0, period) = (sc.time(), sc.period().ok());
    super::progress::with_bar(sc, t0, duration, period, Simulation::set_progress, f)
}

/// Run `sim` until its time is `t` (nothing where it is there already), with a progress bar.
fn run_to(sim: &mut Simulation, t: f64) -> crate::engine::Result<()> {
    let d = (t - sim.time()).max(0.0);
    with_bar(sim, d, |sim| sim.run_to(t))
}

pub(super) fn register(engine: &mut Engine) {
    engine
        .register_fn(
            "run",
            |s: &mut SceneHandle, duration: Dynamic| -> ScriptResult<()> {
                let d = number("run(duration)", &duration)?;
                s.with_sim(|sim| with_bar(sim, d, |sim| sim.run(d)))
            },
        )
        .register_fn(
            "run_periods",
            |s: &mut SceneHandle, n: Dynamic| -> ScriptResult<()> {
                let n = number("run_periods(n)", &n)?;
                s.with_sim(|sim| {
                    let d = sim.period().map_or(0.0, |t| n * t);
                    with_bar(sim, d, |sim| sim.run_periods(n))
                })
            },
        )
        .register_fn(
            "run_to",
            |s: &mut SceneHandle, t: Dynamic| -> ScriptResult<()> {
                let t = number("run_to(t)", &t)?;
                s.with_sim(|sim| run_to(sim, t))
            },
        )
        .register_fn(
            "run_to_periods",
            |s: &mut SceneHandle, n: Dynamic| -> ScriptResult<()> {
                let n = number("run_to_periods(n)", &n)?;
                s.with_sim(|sim| {
                    let t = n * sim.period()?;
                    run_to(sim, t)
                })
            },
        )
        .register_get("stats", |s: &mut SceneHandle| {
            let st = s.borrow().stats();
            [
                ("steps", st.steps),
                ("rejected", st.rejected),
                ("rhs_evals", st.rhs_evals),
                ("rejected_by_guard", st.rejected_by_guard),
                ("macro_steps", st.macro_steps),
                ("micro_periods", st.micro_periods),
                ("noisy_steps", st.noisy_steps),
                ("refined_steps", st.refined_steps),
                ("direct_fallbacks", st.direct_fallbacks),
                ("fallback_periods", st.fallback_periods),
            ]
            .into_iter()
            .map(|(k, v)| (k.into(), (v as INT).into()))
            .collect::<rhai::Map>()
        });
}

/// The help text of this file's script names (`:help NAME`), gathered by [`super::docs`].
pub(super) const DOCS: &[Doc] = &[
    doc_entry!("run", "running", "s.run(seconds)", "Advance the scene; Ctrl-C stops at a clean step boundary and keeps the state.", "let s = scene(); s.add(dumbbell()); s.run(1e-3); print(s.time);"),
    doc_entry!("run_periods", "running", "s.run_periods(n)", "Advance n stroke periods 2 pi/omega (the swimmers' omega must agree).", "let s = scene(); s.add(dumbbell()); s.run_periods(1); print(s.time);"),
    doc_entry!("run_to", "running", "s.run_to(t)", "Advance until the scene's time is t (s); a time the scene has reached already runs nothing and takes no row. With s.checkpoint, a script that runs to absolute times goes on where a checkpoint left it.", "let s = scene(); s.add(dumbbell()); s.run_to(1e-3); s.run_to(1e-3); print(s.time);"),
    doc_entry!("run_to_periods", "running", "s.run_to_periods(n)", "Advance until the scene's time is n stroke periods 2 pi/omega (the swimmers' omega must agree); nothing where it is there already (see run_to).", "let s = scene(); s.add(dumbbell()); s.run_to_periods(2); print(s.time);"),
    doc_entry!("stats", "running", "s.stats -> map", "Work counters: steps, rejected steps, right-hand-side evaluations; macro_steps and micro_periods of stroboscopic averaging, and direct_fallbacks and fallback_periods, the times its macro steps failed at their shortest length and the periods it then integrated directly (s.integrator_info says why); noisy_steps, the steps taken with thermal noise (also the noise generator's counter); refined_steps, the short steps suspension(tol) took for a few swimmers inside its steps.", "let s = scene(); s.add(dumbbell()); s.run_periods(1); print(s.stats);"),
];
