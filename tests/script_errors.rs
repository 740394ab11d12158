//! Bad input gets a clear error that names the problem and the fix, at the script position, and
//! leaves the scene as it was. Nothing panics.

use crate::common;
use rhai::Scope;
use swimlab::script::run_source;

/// Run `src` expecting an error; return the rendered message.
fn error_of(src: &str) -> String {
    let mut scope = Scope::new();
    match run_source("t.rhai", src, &mut scope) {
        Ok(()) => panic!("expected an error from:\n{src}"),
        Err(msg) => msg,
    }
}

/// The error must mention each of `needles` and point at line `line`.
#[track_caller]
fn expect(src: &str, line: usize, needles: &[&str]) {
    let msg = error_of(src);
    assert!(
        msg.contains(&format!("t.rhai:{line}:")),
        "wrong position in:\n{msg}"
    );
    for n in needles {
        assert!(msg.contains(n), "missing {n:?} in:\n{msg}");
    }
    assert!(msg.contains('^'), "no caret in:\n{msg}");
}

const PAIR: &str = "let s = scene();\ns.add(dumbbell(#{ center: [-25e-6, 0, 0] }));\n";

#[test]
fn invalid_parameters_are_named() {
    expect("let d = dumbbell(#{ a1: -1e-6 });", 1, &["a1", "positive"]);
    expect("let d = dumbbell(#{ a2: 0 });", 1, &["a2", "positive"]);
    expect("let d = dumbbell(#{ omega: 0.0 });", 1, &["omega"]);
    expect("let d = dumbbell(#{ k0: -1 });", 1, &["k0"]);
    expect(
        "let x = 1.0/0.0;\nlet d = dumbbell(#{ ell: x });",
        2,
        &["ell", "finite"],
    );
    expect(
        "let d = dumbbell(#{ ell: 1.5e-6 });",
        1,
        &["ell", "a1 + a2 + lambda"],
    );
    expect(
        "let d = dumbbell(#{ dir: [0, 0, 0] });",
        1,
        &["dir", "non-zero"],
    );
    expect(
        "let d = dumbbell(#{ dir: [1, 0] });",
        1,
        &["dir", "3 components"],
    );
    expect(
        "let d = dumbbell(#{ center: \"origin\" });",
        1,
        &["center", "array of 3 numbers"],
    );
    expect(
        "let d = dumbbell(#{ phi: 1.0 });",
        1,
        &["unknown dumbbell key \"phi\"", "phase"],
    );
    expect(
        "let d = dumbbell(#{ lamda: 1e-7 });",
        1,
        &["did you mean \"lambda\""],
    );
}

#[test]
fn unknown_names_and_wrong_types_are_named() {
    expect(
        "let s = scene();\ns.model = \"mikro\";",
        2,
        &["unknown model", "did you mean \"micro\""],
    );
    expect(
        "let s = scene();\ns.mobility = \"stokes\";",
        2,
        &["unknown mobility", "rpy", "oseen"],
    );
    expect(
        "let s = scene();\ns.integrator = \"rk5\";",
        2,
        &["unknown integrator"],
    );
    expect(
        "let s = scene();\ns.integrator = 3;",
        2,
        &["euler(dt), rk4(dt), dopri5(rtol)"],
    );
    expect("let s = scene();\ns.mu = -1.0;", 2, &["mu", "positive"]);
    expect(
        "let s = scene();\ns.mu = \"water\";",
        2,
        &["mu must be a number"],
    );
    expect(
        "let s = scene();\ns.add(5);",
        2,
        &["add expects a Dumbbell"],
    );
    expect("let i = rk4(0.0);", 1, &["dt", "positive"]);
    expect("let i = euler(-1e-6);", 1, &["dt", "positive"]);
    expect("let i = dopri5(2.0);", 1, &["rtol"]);
    expect("let i = dopri5(\"tight\");", 1, &["rtol must be a number"]);
    // A property called as a method is named as the property it is.
    expect(
        "let s = scene();\nlet n = s.count();",
        2,
        &["Scene.count is a property", "without parentheses"],
    );
}

#[test]
fn indices_and_durations_are_checked() {
    expect(
        &format!("{PAIR}s.center(1);"),
        3,
        &["index 1 is out of range", "1 swimmers"],
    );
    expect(&format!("{PAIR}s.dir(-1);"), 3, &["negative"]);
    expect(&format!("{PAIR}s.center(0.5);"), 3, &["integer"]);
    expect(&format!("{PAIR}s.run(-1.0);"), 3, &["duration", ">= 0"]);
    expect(&format!("{PAIR}s.run(\"long\");"), 3, &["must be a number"]);
    expect("let s = scene();\nlet t = s.period;", 2, &["no swimmers"]);
}

#[test]
fn overlapping_swimmers_are_refused_and_the_scene_is_unchanged() {
    let src = format!("{PAIR}let ok = false;\ntry {{ s.add(dumbbell(#{{ center: [-24e-6, 0, 0] }})); }} catch (e) {{ ok = s.count == 1 && `${{e}}`.contains(\"overlap swimmer 0\"); }}\nif !ok {{ throw \"not refused\"; }}");
    let mut scope = Scope::new();
    run_source("t.rhai", &src, &mut scope).unwrap();
    expect(
        &format!("{PAIR}s.add(dumbbell(#{{ center: [-24e-6, 0, 0] }}));"),
        3,
        &["overlap swimmer 0"],
    );
}

#[test]
fn run_periods_needs_a_common_omega() {
    let src = format!(
        "{PAIR}s.add(dumbbell(#{{ omega: 600, center: [25e-6, 0, 0] }}));\ns.run_periods(1);"
    );
    expect(&src, 4, &["different omega", "run(seconds)"]);
}

#[test]
fn a_step_that_blows_up_stops_with_time_cause_and_last_good_state() {
    // Euler at 10× its stability limit: the spring oscillation grows until spheres overlap or
    // the state overflows; the run must stop, say so, and keep a finite state.
    let src = format!(
        "{PAIR}s.integrator = euler(20.0 / s.stiff_rate);\nlet msg = \"\";\ntry {{ s.run_periods(1); }} catch (e) {{ msg = `${{e}}`; }}\n\
         if !msg.contains(\"the run stopped at t =\") || !msg.contains(\"last good state\") {{ throw `bad message: ${{msg}}`; }}\n\
         if s.time <= 0.0 || s.time >= s.period {{ throw `time ${{s.time}}`; }}\n\
         let c = s.center(0); let l = s.length(0);\n\
         if !(l > 0.0 && l < 1.0) || c[0] != c[0] {{ throw `state not finite: ${{c}} ${{l}}`; }}"
    );
    let mut scope = Scope::new();
    run_source("t.rhai", &src, &mut scope).unwrap();
}

#[test]
fn parse_errors_show_the_position() {
    expect("let s = scene();\nlet x = (1 + ;", 2, &[]);
}

#[test]
fn an_adaptive_step_that_fails_a_guard_is_retried_smaller() {
    use nalgebra::Vector3;
    use swimlab::engine::{Dumbbell, IntegratorSpec, Scene, Simulation};
    // A loose tolerance lets dopri5 propose steps far above the spring's stability limit; the
    // guards reject the resulting runaway springs, the step is retried smaller, and the run
    // completes with a physical state.
    let mut s = Scene::new();
    s.add(Dumbbell::default(), Vector3::zeros(), Vector3::x())
        .unwrap();
    s.set_integrator(Some(IntegratorSpec::Dopri5 { rtol: 0.5 }));
    let mut s = Simulation::new(s);
    s.run_periods(2.0).unwrap();
    let d = *s.swimmer(0).unwrap();
    assert!((s.length(0).unwrap() - d.rest_length(s.time())).abs() < 0.5 * d.ell);
    let st = s.stats();
    assert!(
        st.rejected_by_guard > 0,
        "the guards must have rejected steps: {st:?}"
    );
}

// Adaptive methods running into a contact: every step past it is refused by the contact guard,
// so the step shrinks towards the moment of contact. It used to shrink for ever once steps no
// longer advanced the time in f64 (t + h == t): dopri5 and rosw hung. Now the step stops at
// 1e-12 of t and the run ends with the contact's own error, the touching spheres named, the
// scene at its last good state (their gap positive, within 1e-3 µm: the approach closes ~0.02 µm
// in 0.03 T). Each run is given 60 s on a thread (it takes milliseconds), so a hang fails the
// test instead of stalling it.
#[test]
fn adaptive_methods_stop_at_a_contact_instead_of_crawling() {
    use swimlab::engine::{IntegratorSpec, Observable, Simulation};
    for spec in [
        IntegratorSpec::Dopri5 { rtol: 1e-3 },
        IntegratorSpec::Dopri5 { rtol: 1e-8 },
        IntegratorSpec::Rosw { rtol: 1e-4 },
    ] {
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let mut s = common::about_to_touch();
            s.set_integrator(Some(spec));
            let mut sim = Simulation::new(s);
            let e = sim.run_periods(1.0).map_err(|e| e.to_string());
            let gap = Observable::MinGap.evaluate(&sim).unwrap()[0];
            tx.send((e, sim.time(), gap, sim.stats())).unwrap();
        });
        let (e, t, gap, stats) = rx
            .recv_timeout(std::time::Duration::from_secs(60))
            .unwrap_or_else(|_| panic!("{spec}: no end after 60 s"));
        let e = e.expect_err("the spheres touch within the period");
        assert!(
            e.contains("sphere 2 of swimmer 0 overlaps sphere 1 of swimmer 1"),
            "{spec}: {e}"
        );
        let period = 2.0 * std::f64::consts::PI / 500.0;
        assert!(
            t > 0.02 * period && t < 0.04 * period,
            "{spec}: stopped at {t:e}"
        );
        assert!(
            (0.0..1e-9).contains(&gap),
            "{spec}: gap {gap:e} at the kept state"
        );
        assert!(stats.rejected_by_guard > 0, "{spec}: {stats:?}");
    }
}
