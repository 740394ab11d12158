//! Small helpers scripts need: number formatting, `pi()`, and the quick mode of long scripts.

use rhai::{Dynamic, Engine, INT};

/// Whether scripts should run their quick variant (`swimlab run --quick`, or SWIMLAB_QUICK=1).
pub fn quick() -> bool {
    std::env::var("SWIMLAB_QUICK").is_ok_and(|v| !v.is_empty() && v != "0")
}

fn sci(x: f64, digits: INT) -> String {
    let d = digits.clamp(0, 17) as usize;
    format!("{x:.d$e}")
}

/// Register the helpers.
pub fn register(engine: &mut Engine) {
    engine
        .register_fn("pi", || std::f64::consts::PI)
        .register_fn("quick", quick)
        .register_fn("sci", |x: f64| sci(x, 4))
        .register_fn("sci", sci)
        .register_fn("sci", |x: INT| sci(x as f64, 4))
        .register_fn("fixed", |x: f64, digits: INT| {
            let d = digits.clamp(0, 17) as usize;
            format!("{x:.d$}")
        })
        .register_fn("lpad", |x: Dynamic, width: INT| {
            format!("{:>w$}", x.to_string(), w = width.max(0) as usize)
        })
        .register_fn("rpad", |x: Dynamic, width: INT| {
            format!("{:<w$}", x.to_string(), w = width.max(0) as usize)
        })
        .register_fn("is_number", |x: Dynamic| x.is_float() || x.is_int());
}
