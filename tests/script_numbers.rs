//! Numbers in scripts behave as IEEE f64: comparisons are exact, so the sign of a 1e-20 m drift is
//! seen (Rhai's default epsilon comparison would call it zero).

use rhai::Scope;
use swimlab::script::run_source;

#[test]
fn float_comparisons_are_exact() {
    let src = r#"
        let checks = [
            1e-17 > 0.0, 1e-300 > 0.0, -1e-20 < 0.0, 0.0 < 1e-20, 1e-20 >= 0.0, !(1e-20 <= 0.0),
            1e-20 != 0.0, !(1e-20 == 0.0), 0.1 + 0.2 != 0.3, 2.4e-17 * 1.0 > 0,
            1 == 1.0, 1 < 1.0000000000000002, 1.0000000000000002 > 1, 3 >= 3.0,
        ];
        for (c, i) in checks { if !c { throw `check ${i} failed`; } }
        if 1 + 1 != 2 { throw "integer equality"; }
        if "a" != "a" { throw "string equality"; }
    "#;
    run_source("t.rhai", src, &mut Scope::new()).unwrap();
}
