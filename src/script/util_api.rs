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

/// `n` uniform numbers in [0, 1) from `seed` (splitmix64: reproducible on every platform).
pub fn uniform_randoms(n: INT, seed: INT) -> rhai::Array {
    let mut state = seed as u64;
    (0..n.max(0))
        .map(|_| {
            state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^= z >> 31;
            Dynamic::from_float((z >> 11) as f64 / (1u64 << 53) as f64)
        })
        .collect()
}

/// Register the helpers.
pub fn register(engine: &mut Engine) {
    engine
        .register_fn("pi", || std::f64::consts::PI)
        .register_fn("quick", quick)
        .register_fn("uniform_randoms", uniform_randoms)
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
