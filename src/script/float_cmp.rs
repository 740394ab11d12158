//! Exact IEEE comparisons of numbers in scripts.
//!
//! Rhai's checked build compares floats with a relative epsilon, and against 0.0 with an absolute
//! one: `x > 0.0` is false for any x below 2.2e-16. Scripts speak SI, where a per-period drift is
//! ~1e-12 m and a bisection on its sign must see 1e-20: those comparisons would silently be wrong.
//! swimlab registers exact comparisons for FLOAT/FLOAT and FLOAT/INT pairs instead.

use rhai::{Engine, FLOAT, INT};

macro_rules! exact {
    ($engine:ident, $($op:tt)*) => {$(
        $engine
            .register_fn(stringify!($op), |x: FLOAT, y: FLOAT| x $op y)
            .register_fn(stringify!($op), |x: FLOAT, y: INT| x $op (y as FLOAT))
            .register_fn(stringify!($op), |x: INT, y: FLOAT| (x as FLOAT) $op y);
    )*};
}

/// Register exact comparisons; built-in fast operators are switched off so these take effect.
pub fn register(engine: &mut Engine) {
    engine.set_fast_operators(false);
    exact!(engine, == != < <= > >=);
}
