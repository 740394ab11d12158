//! `euler(dt)`, `rk4(dt)`, `dopri5(rtol)`, `rosw(rtol)`: integrator choices as script values (type `Integrator`).

use super::convert::{lift, number, ScriptResult};
use crate::engine::IntegratorSpec;
use rhai::{Dynamic, Engine};

fn make(
    f: fn(f64) -> crate::engine::Result<IntegratorSpec>,
    what: &str,
    v: Dynamic,
) -> ScriptResult<IntegratorSpec> {
    lift(f(number(what, &v)?))
}

/// Register the `Integrator` type and its constructors.
pub fn register(engine: &mut Engine) {
    engine
        .register_type_with_name::<IntegratorSpec>("Integrator")
        .register_fn("euler", |dt: Dynamic| {
            make(IntegratorSpec::euler, "euler(dt): dt", dt)
        })
        .register_fn("rk4", |dt: Dynamic| {
            make(IntegratorSpec::rk4, "rk4(dt): dt", dt)
        })
        .register_fn("dopri5", |r: Dynamic| {
            make(IntegratorSpec::dopri5, "dopri5(rtol): rtol", r)
        })
        .register_fn("rosw", |r: Dynamic| {
            make(IntegratorSpec::rosw, "rosw(rtol): rtol", r)
        })
        .register_fn("to_string", |i: &mut IntegratorSpec| i.to_string())
        .register_fn("to_debug", |i: &mut IntegratorSpec| i.to_string())
        .register_fn("==", |a: IntegratorSpec, b: IntegratorSpec| a == b);
}
