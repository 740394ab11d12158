//! Small helpers scripts need: number formatting, `pi()`, and the quick mode of long scripts.

use super::convert::{number, ScriptResult};
use super::limits;
use rhai::{Dynamic, Engine, INT};

/// Whether scripts should run their quick variant (`swimlab run --quick`, or SWIMLAB_QUICK=1).
pub fn quick() -> bool {
    std::env::var("SWIMLAB_QUICK").is_ok_and(|v| !v.is_empty() && v != "0")
}

fn sci(x: f64, digits: INT) -> String {
    let d = digits.clamp(0, 17) as usize;
    format!("{x:.d$e}")
}

/// `n` uniform numbers in [0, 1) from `seed` (splitmix64: reproducible on every platform).
pub fn uniform_randoms(n: INT, seed: INT) -> ScriptResult<rhai::Array> {
    let n = limits::check_array("uniform_randoms(n, seed)", n as f64)?;
    let mut state = seed as u64;
    Ok((0..n)
        .map(|_| {
            state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^= z >> 31;
            Dynamic::from_float((z >> 11) as f64 / (1u64 << 53) as f64)
        })
        .collect())
}

/// `x` as text padded to `width` characters, on the left (`right == false`) or the right.
fn pad(x: &Dynamic, width: INT, right: bool) -> ScriptResult<String> {
    let what = if right {
        "rpad(x, width)"
    } else {
        "lpad(x, width)"
    };
    let w = limits::check_string(what, width as f64)?;
    let text = x.to_string();
    let fill = " ".repeat(w.saturating_sub(text.chars().count()));
    Ok(if right {
        format!("{text}{fill}")
    } else {
        format!("{fill}{text}")
    })
}

/// Register the helpers.
pub fn register(engine: &mut Engine) {
    engine
        .register_fn("pi", || std::f64::consts::PI)
        .register_fn("quick", quick)
        .register_fn("uniform_randoms", uniform_randoms)
        .register_fn("sci", |x: Dynamic| -> ScriptResult<String> {
            Ok(sci(number("sci(x)", &x)?, 4))
        })
        .register_fn("sci", |x: Dynamic, digits: INT| -> ScriptResult<String> {
            Ok(sci(number("sci(x, digits)", &x)?, digits))
        })
        .register_fn("fixed", |x: Dynamic, digits: INT| -> ScriptResult<String> {
            let x = number("fixed(x, digits)", &x)?;
            let d = digits.clamp(0, 17) as usize;
            Ok(format!("{x:.d$}"))
        })
        .register_fn("lpad", |x: Dynamic, width: INT| pad(&x, width, false))
        .register_fn("rpad", |x: Dynamic, width: INT| pad(&x, width, true))
        .register_fn("is_number", |x: Dynamic| x.is_float() || x.is_int());
}
