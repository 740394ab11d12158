//! Integrator choices as script values (type `Integrator`): one constructor per entry of the
//! engine's method table (`euler(dt)`, `rk4(dt)`, `dopri5(rtol)`, ...), and `stroboscopic(tol,
//! inner)` with an inner method.

use super::convert::{lift, number, ScriptResult};
use super::doc::{doc_entry, Doc};
use crate::engine::integrators::METHODS;
use crate::engine::IntegratorSpec;
use rhai::{Dynamic, Engine};

/// The accepted call forms of the method table, for messages: `euler(dt), rk4(dt), ...`.
pub fn call_forms() -> String {
    METHODS
        .iter()
        .map(|m| format!("{}({})", m.name, m.parameter))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Register the `Integrator` type and its constructors.
pub fn register(engine: &mut Engine) {
    for m in METHODS {
        let make = m.make;
        let what = format!("{}({p}): {p}", m.name, p = m.parameter);
        engine.register_fn(m.name, move |v: Dynamic| -> ScriptResult<IntegratorSpec> {
            lift(make(number(&what, &v)?))
        });
    }
    engine.register_fn(
        "stroboscopic",
        |tol: Dynamic, inner: IntegratorSpec| -> ScriptResult<IntegratorSpec> {
            let tol = number("stroboscopic(tol, inner): tol", &tol)?;
            lift(IntegratorSpec::stroboscopic_with(tol, Some(inner)))
        },
    );
    engine.register_fn("==", |a: IntegratorSpec, b: IntegratorSpec| a == b);
}

/// The help text of this file's script names (`:help NAME`), gathered by [`super::docs`].
pub(super) const DOCS: &[Doc] = &[
    doc_entry!("euler", "numerics", "euler(dt) -> Integrator", "Forward Euler with steps of at most dt seconds.", "let i = euler(1e-6); print(i);"),
    doc_entry!("rk4", "numerics", "rk4(dt) -> Integrator", "Classic Runge-Kutta 4 with steps of at most dt seconds.", "let i = rk4(5e-6); print(i);"),
    doc_entry!("dopri5", "numerics", "dopri5(rtol) -> Integrator", "Adaptive Dormand-Prince 5(4); rtol is relative to the stroke and drift scales, not to positions.", "let i = dopri5(1e-8); print(i);"),
    doc_entry!("stroboscopic", "numerics", "stroboscopic(tol) -> Integrator\nstroboscopic(tol, inner) -> Integrator", "Stroboscopic averaging for the spring and rigid models over 1e4-1e6 periods: short microscopic runs of whole periods (by inner, or one chosen for tol) sample the map from one period to the next, and macro steps of many periods follow the slow motion they define; tol is relative to the drift. The slopes' polynomial degree (2-6) adapts so that their own error stays within a tenth of tol. The start transient, runs under 16 periods, rows between period multiples and stretches where macro steps fail (a motion not slow at this tol) are integrated directly. Needs a common period (equal or commensurate omega). s.stats counts macro_steps and micro_periods, and direct_fallbacks and fallback_periods where macro steps fail at their shortest (such a run says so on stderr as it falls back, and s.integrator_info says why).", "let s = scene(); s.add(dumbbell()); s.add(dumbbell(#{ phase: 1.0, center: [25e-6, 0, 0] })); s.integrator = stroboscopic(1e-4); s.run_periods(1000); print(s.stats.macro_steps);"),
    doc_entry!("auto", "numerics", "auto(tol) -> Integrator", "The cheapest method expected to meet tol (relative to the drift) for the scene: stroboscopic averaging with an inner step chosen for tol when the strokes share a period, that inner method directly otherwise, suspension(tol) for a suspension of the averaged model (a box, a cutoff, steric repulsion or 64 swimmers), dopri5 for other averaged scenes. s.integrator_info says which and why.", "let s = scene(); s.add(dumbbell()); s.integrator = auto(1e-4); print(s.integrator_info);"),
    doc_entry!("platen", "thermal", "platen(dt) -> Integrator", "Platen's explicit weak second-order scheme (Kloeden & Platen 15.1.3) with steps of at most dt seconds, for thermal noise in the spring model: averages and distributions converge as dt^2 where Euler-Maruyama's converge as dt. It factors the mobility at 4m + 1 states a step (m = 6 per swimmer), so it takes at most 16 swimmers. Without noise it is Heun's method (order 2).", "let s = scene(); s.add(dumbbell()); s.temperature = 300; s.integrator = platen(2e-6); s.run_periods(0.05); print(s.stats.noisy_steps);"),
    doc_entry!("rosw", "numerics", "rosw(rtol) -> Integrator", "Adaptive Rosenbrock-W ROS34PW2 (order 3, L-stable): implicit in each dumbbell's own spring and hydrodynamics, explicit between dumbbells; not held by the spring's stability limit.", "let i = rosw(1e-6); print(i);"),
    doc_entry!("suspension", "numerics", "suspension(tol) -> Integrator", "For suspensions of the averaged model, and their default (tol 1e-3): adaptive Rosenbrock-W ROS34PW2 (order 3) implicit only in clusters of swimmers in steric contact, explicit elsewhere. Each swimmer's local error is held to tol of its own displacement over the step (not of the fastest pair's), the step set so that 99% of swimmers meet it; the few fast ones (a contact, a close pair) are stepped again alone in substeps, and their partners once more along the refined paths. s.stats counts refined_steps.", "let s = scene(); s.model = \"averaged\"; s.add_random(dumbbell(), 100, 1e-3, 1); s.integrator = suspension(1e-3); s.run_periods(10); print(s.stats.steps);"),
];
