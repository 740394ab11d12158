//! `euler(dt)`, `rk4(dt)`, `dopri5(rtol)`, `rosw(rtol)`: integrator choices as script values (type
//! `Integrator`), one constructor per entry of the engine's method table.

use super::convert::{lift, number, ScriptResult};
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
    super::convert::register_display::<IntegratorSpec>(engine);
    engine.register_fn("==", |a: IntegratorSpec, b: IntegratorSpec| a == b);
}
