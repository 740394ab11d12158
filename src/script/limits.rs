//! Safety limits of the script engine, and the checks made against them before allocating.
//!
//! Rhai enforces the string, array, map and call-depth limits on every value a script makes;
//! swimlab's own functions that build big values (`uniform_randoms`, `rec.rows`, `lpad`, ...)
//! check the same limits before they allocate. Each limit can be raised through an environment
//! variable, which the error message names. Statement counts are not limited: long experiment
//! loops are legitimate, and Ctrl-C stops any of them between statements.

use super::convert::{script_error, ScriptResult};
use rhai::Engine;
use std::sync::OnceLock;

/// The limits in force (read once per process from the environment).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limits {
    /// Longest string, in bytes.
    pub string: usize,
    /// Most elements in one array (nested arrays count every element).
    pub array: usize,
    /// Most entries in one object map.
    pub map: usize,
    /// Deepest nesting of function calls.
    pub call_depth: usize,
}

/// One limit: its environment variable, default and what it counts.
struct Knob {
    env: &'static str,
    default: usize,
    what: &'static str,
}

const STRING: Knob = Knob {
    env: "SWIMLAB_MAX_STRING",
    default: 256 << 20,
    what: "bytes of text in one value (its strings added up)",
};
const ARRAY: Knob = Knob {
    env: "SWIMLAB_MAX_ARRAY",
    default: 20_000_000,
    what: "elements in one array (nested arrays and maps counted)",
};
const MAP: Knob = Knob {
    env: "SWIMLAB_MAX_MAP",
    default: 20_000_000,
    what: "entries in one map (nested maps counted; rec.rows holds one per recorded value)",
};
const CALL_DEPTH: Knob = Knob {
    env: "SWIMLAB_MAX_CALL_DEPTH",
    default: 64,
    what: "nested function calls",
};

fn read(k: &Knob) -> usize {
    std::env::var(k.env)
        .ok()
        .and_then(|v| v.trim().replace('_', "").parse::<usize>().ok())
        .filter(|v| *v > 0)
        .unwrap_or(k.default)
}

/// The limits of this process.
pub fn limits() -> Limits {
    static L: OnceLock<Limits> = OnceLock::new();
    *L.get_or_init(|| Limits {
        string: read(&STRING),
        array: read(&ARRAY),
        map: read(&MAP),
        call_depth: read(&CALL_DEPTH),
    })
}

/// Set the limits on an engine.
pub fn apply(engine: &mut Engine) {
    let l = limits();
    engine
        .set_max_string_size(l.string)
        .set_max_array_size(l.array)
        .set_max_map_size(l.map)
        .set_max_call_levels(l.call_depth);
}

fn message(k: &Knob, limit: usize, asked: Option<f64>) -> String {
    let asked = asked
        .map(|a| format!(" ({a:.0} asked)"))
        .unwrap_or_default();
    format!(
        "this would exceed swimlab's limit of {limit} {}{asked}; make it smaller, or raise the limit by starting swimlab with {}=<number>",
        k.what, k.env
    )
}

/// The message for a Rhai size error (`ErrorDataTooLarge`'s text, e.g. "Length of string").
pub fn data_too_large(what: &str) -> String {
    let l = limits();
    let (k, limit) = if what.contains("string") {
        (&STRING, l.string)
    } else if what.contains("map") {
        (&MAP, l.map)
    } else {
        (&ARRAY, l.array)
    };
    message(k, limit, None)
}

/// The message for a Rhai stack overflow.
pub fn call_depth_exceeded() -> String {
    format!(
        "function calls nested too deeply: {}",
        message(&CALL_DEPTH, limits().call_depth, None)
    )
}

/// Check, before allocating, that an array of `n` elements is within the limit.
pub fn check_array(what: &str, n: f64) -> ScriptResult<usize> {
    let limit = limits().array;
    if n.is_nan() || n < 0.0 {
        return Err(script_error(format!(
            "{what}: the number of elements must be >= 0, got {n}"
        )));
    }
    if n > limit as f64 {
        return Err(script_error(format!(
            "{what}: {}",
            message(&ARRAY, limit, Some(n))
        )));
    }
    Ok(n as usize)
}

/// Check, before allocating, that an array of `n` maps of `entries` each is within the limits.
pub fn check_maps(what: &str, n: usize, entries: usize) -> ScriptResult<()> {
    check_array(what, n as f64)?;
    let limit = limits().map;
    let total = n as f64 * entries as f64;
    if total > limit as f64 {
        return Err(script_error(format!(
            "{what}: {}; rec.column(name) or rec.to_csv(path) need less",
            message(&MAP, limit, Some(total))
        )));
    }
    Ok(())
}

/// Check, before allocating, that a string of `n` bytes is within the limit.
pub fn check_string(what: &str, n: f64) -> ScriptResult<usize> {
    let limit = limits().string;
    if n > limit as f64 {
        return Err(script_error(format!(
            "{what}: {}",
            message(&STRING, limit, Some(n))
        )));
    }
    Ok(n.max(0.0) as usize)
}
