//! Conversions between Rhai values and engine values, with errors that say what was expected.

use crate::engine::error::Setting;
use crate::engine::EngineError;
use nalgebra::Vector3;
use rhai::{Array, Dynamic, EvalAltResult, Position, FLOAT, INT};
use std::sync::OnceLock;

/// How messages quote a value ("euler(1e-6) (Integrator)"): the shell's `describe`, which knows
/// every script type and so sits above the binding files that quote values; installed by the
/// engine builder.
static DESCRIBE: OnceLock<fn(&Dynamic) -> String> = OnceLock::new();

/// Install how messages quote a value (the engine builder does, before any script runs).
pub fn install_describe(f: fn(&Dynamic) -> String) {
    let _ = DESCRIBE.set(f);
}

/// A value as a message quotes it: its text and its type, "euler(1e-6) (Integrator)"; Rhai's
/// type name before an engine was built.
pub fn describe(v: &Dynamic) -> String {
    DESCRIBE
        .get()
        .map_or_else(|| v.type_name().to_string(), |f| f(v))
}

/// Result type of script-visible functions.
pub type ScriptResult<T> = Result<T, Box<EvalAltResult>>;

/// A runtime error with this message; Rhai fills in the script position of the call.
pub fn script_error(msg: impl Into<String>) -> Box<EvalAltResult> {
    let msg = crate::engine::compact_numbers(&msg.into());
    EvalAltResult::ErrorRuntime(Dynamic::from(msg), Position::NONE).into()
}

/// The script line that makes a setting an engine error names as its fix.
pub fn setting_in_script(s: &Setting) -> String {
    match s {
        Setting::Backend(b) => format!("s.backend = \"{b}\""),
        Setting::Model(m) => format!("s.model = \"{m}\""),
        Setting::FixedStep => "s.integrator = rk4(dt)".into(),
        Setting::DefaultIntegrator => "s.integrator = \"default\"".into(),
        Setting::StableStep => "a step dt below ~2.8 / s.stiff_rate".into(),
        Setting::Steric => "s.steric = #{ range: 1e-7, stiffness: 1e-3 }".into(),
        Setting::AllowOverlaps => "s.overlaps = \"allow\"".into(),
        Setting::NoCutoff => "s.cutoff = ()".into(),
        Setting::AddSwimmer => "s.add(dumbbell(#{}))".into(),
        Setting::Lattice => "s.add_at(d, lattice::cubic(nx, ny, nz, spacing))".into(),
        Setting::Mobility(m) => format!("s.mobility = \"{m}\""),
        Setting::NoNoise => "s.temperature = 0".into(),
        Setting::NoiseIntegrator => "s.integrator = euler(dt) or platen(dt)".into(),
        Setting::EwaldMethod(m) => format!("s.ewald_method = \"{m}\""),
        Setting::LooserEwaldTol => "a looser s.ewald_tol (e.g. 1e-6)".into(),
        Setting::NoWall => "s.wall = ()".into(),
        Setting::NoBox => "s.box = ()".into(),
    }
}

/// An engine error as a script user reads it: the engine's message, its fixes as script lines.
pub fn engine_message(e: &EngineError) -> String {
    e.message_with(&setting_in_script)
}

/// Engine errors become script errors carrying the engine's message in script terms.
pub fn from_engine(e: EngineError) -> Box<EvalAltResult> {
    script_error(engine_message(&e))
}

/// Map an engine result into a script result.
pub fn lift<T>(r: crate::engine::Result<T>) -> ScriptResult<T> {
    r.map_err(from_engine)
}

/// A number (integer or float) as f64.
pub fn number(what: &str, v: &Dynamic) -> ScriptResult<f64> {
    if let Some(f) = v.clone().try_cast::<FLOAT>() {
        Ok(f)
    } else if let Some(i) = v.clone().try_cast::<INT>() {
        Ok(i as f64)
    } else {
        Err(script_error(format!(
            "{what} must be a number, got {}",
            describe(v)
        )))
    }
}

/// An array of three numbers as a vector.
pub fn vector3(what: &str, v: &Dynamic) -> ScriptResult<Vector3<f64>> {
    let arr = v.clone().try_cast::<Array>().ok_or_else(|| {
        script_error(format!(
            "{what} must be an array of 3 numbers such as [1.0, 0.0, 0.0], got {}",
            describe(v)
        ))
    })?;
    if arr.len() != 3 {
        return Err(script_error(format!(
            "{what} must have exactly 3 components, got {}",
            arr.len()
        )));
    }
    let mut out = Vector3::zeros();
    for (k, x) in arr.iter().enumerate() {
        out[k] = number(&format!("{what}[{k}]"), x)?;
    }
    Ok(out)
}

/// A vector as a Rhai array of floats.
pub fn array3(v: &Vector3<f64>) -> Array {
    v.iter().map(|x| Dynamic::from_float(*x)).collect()
}

/// A script index as usize (negative indices are an error).
pub fn index(i: INT) -> ScriptResult<usize> {
    usize::try_from(i)
        .map_err(|_| script_error(format!("swimmer index {i} is negative; indices start at 0")))
}

/// The closest of `options` to `word`, if reasonably close (for "did you mean").
pub use crate::engine::choice::closest as suggest;

/// "unknown X \"w\"; did you mean \"y\"? Valid: a, b, c".
pub fn unknown_choice(kind: &str, word: &str, options: &[&str]) -> Box<EvalAltResult> {
    let hint = suggest(word, options)
        .map(|s| format!(" did you mean \"{s}\"?"))
        .unwrap_or_default();
    script_error(format!(
        "unknown {kind} \"{word}\";{hint} valid: {}",
        options.join(", ")
    ))
}
