//! `euler(dt)`, `rk4(dt)`, `dopri5(rtol)`, `rosw(rtol)`: integrator choices as script values (type
//! `Integrator`), one constructor per entry of the engine's method table.

use super::convert::{lift, number, ScriptResult};
use super::docs::{doc_entry, Doc};
use crate::engine::integrators::METHODS;
use crate::engine::IntegratorSpec;
use rhai::{Dynamic, Engine};

/// The accepted call forms, for messages: `euler(dt), rk4(dt), dopri5(rtol), rosw(rtol)`.
pub fn call_forms() -> String {
    METHODS
        .iter()
        .map(|m| format!("{}({})", m.name, m.parameter))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Register the `Integrator` type and its constructors.
pub fn register(engine: &mut Engine) {
    engine.register_type_with_name::<IntegratorSpec>("Integrator");
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
    super::convert::register_display::<IntegratorSpec>(engine);
    engine.register_fn("==", |a: IntegratorSpec, b: IntegratorSpec| a == b);
}

/// The help text of this file's script names (`:help NAME`), gathered by [`super::docs`].
pub(super) const DOCS: &[Doc] = &[
    doc_entry!("euler", "numerics", "euler(dt) -> Integrator", "Forward Euler with steps of at most dt seconds.", "let i = euler(1e-6); print(i);"),
    doc_entry!("rk4", "numerics", "rk4(dt) -> Integrator", "Classic Runge-Kutta 4 with steps of at most dt seconds.", "let i = rk4(5e-6); print(i);"),
    doc_entry!("dopri5", "numerics", "dopri5(rtol) -> Integrator", "Adaptive Dormand-Prince 5(4); rtol is relative to the stroke and drift scales, not to positions.", "let i = dopri5(1e-8); print(i);"),
    doc_entry!("rosw", "numerics", "rosw(rtol) -> Integrator", "Adaptive Rosenbrock-W ROS34PW2 (order 3, L-stable): implicit in each dumbbell's own spring and hydrodynamics, explicit between dumbbells; not held by the spring's stability limit.", "let i = rosw(1e-6); print(i);"),
];
