//! Conversions between Rhai values and engine values, with errors that say what was expected.

use crate::engine::error::Setting;
use crate::engine::EngineError;
use nalgebra::Vector3;
use rhai::{Array, Dynamic, EvalAltResult, Position, FLOAT, INT};

/// Result type of script-visible functions.
pub type ScriptResult<T> = Result<T, Box<EvalAltResult>>;

/// A runtime error with this message; Rhai fills in the script position of the call.
pub fn script_error(msg: impl Into<String>) -> Box<EvalAltResult> {
    EvalAltResult::ErrorRuntime(Dynamic::from(msg.into()), Position::NONE).into()
}

/// The script line that makes a setting an engine error names as its fix.
pub fn setting_in_script(s: &Setting) -> String {
    match s {
        Setting::Backend(b) => format!("s.backend = \"{b}\""),
        Setting::Model(m) => format!("s.model = \"{m}\""),
        Setting::FixedStep => "s.integrator = rk4(dt)".into(),
        Setting::DefaultIntegrator => "s.integrator = \"default\"".into(),
        Setting::StableStep => "a step dt below ~2.8 / s.stiff_rate".into(),
        Setting::NoSteric => "s.steric = ()".into(),
        Setting::Steric => "s.steric = #{ range: 1e-7, stiffness: 1e-3 }".into(),
        Setting::AllowOverlaps => "s.overlaps = \"allow\"".into(),
        Setting::NoCutoff => "s.cutoff = ()".into(),
        Setting::AddSwimmer => "s.add(dumbbell(#{}))".into(),
        Setting::Lattice => "s.add_at(d, lattice::cubic(nx, ny, nz, spacing))".into(),
    }
}

fn fixes_in_script(fixes: &[Setting]) -> String {
    fixes
        .iter()
        .map(setting_in_script)
        .collect::<Vec<_>>()
        .join(" or ")
}

/// An engine error as a script user reads it: the engine's message, its fixes as script lines.
pub fn engine_message(e: &EngineError) -> String {
    match e {
        EngineError::UnknownChoice { kind, given, valid } => {
            let names: Vec<&str> = valid.iter().map(|(n, _)| *n).collect();
            let hint = suggest(given, &names)
                .map(|s| format!(" did you mean \"{s}\"?"))
                .unwrap_or_default();
            format!(
                "unknown {kind} \"{given}\";{hint} valid: {}",
                valid
                    .iter()
                    .map(|(n, a)| format!("\"{n}\" ({a})"))
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        }
        EngineError::Unsupported { problem, fixes } => {
            format!("{problem}; use {}", fixes_in_script(fixes))
        }
        EngineError::StepFailed {
            time,
            last_good,
            cause,
            hint,
            fixes,
            ..
        } if !fixes.is_empty() => format!(
            "the run stopped at t = {time:.6e} s: {cause}; the scene keeps the last good state (t = {last_good:.6e} s). Likely fix: {hint}; or use {}",
            fixes_in_script(fixes)
        ),
        other => other.to_string(),
    }
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
            "{what} must be a number, got {} ({})",
            v,
            v.type_name()
        )))
    }
}

/// An array of three numbers as a vector.
pub fn vector3(what: &str, v: &Dynamic) -> ScriptResult<Vector3<f64>> {
    let arr = v.clone().try_cast::<Array>().ok_or_else(|| {
        script_error(format!(
            "{what} must be an array of 3 numbers such as [1.0, 0.0, 0.0], got {} ({})",
            v,
            v.type_name()
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

/// The closest of `options` to `word` by edit distance, if reasonably close (for "did you mean").
pub fn suggest<'a>(word: &str, options: &[&'a str]) -> Option<&'a str> {
    options
        .iter()
        .map(|o| (edit_distance(word, o), *o))
        .filter(|(d, o)| *d <= (o.len() / 2).max(1))
        .min_by_key(|(d, _)| *d)
        .map(|(_, o)| o)
}

fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            cur[j + 1] = (prev[j] + usize::from(ca != *cb))
                .min(prev[j + 1] + 1)
                .min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

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
