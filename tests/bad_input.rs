//! Nothing lost, nothing hangs: cases of bad input a new user meets, as a table of (script, expected message fragment, exit code). Each runs in its
//! own `swimlab` process under a time limit, so a hang or an abort fails the test instead of
//! stalling it, and a panic shows as the "internal error" the script boundary turns it into.

use crate::common::cli::{self, case_dir, swimlab};
use std::process::Output;

/// Run `script` as a file with `swimlab run`; check the exit code and that stdout+stderr hold
/// `fragment`, and that no panic surfaced.
#[track_caller]
fn case(script: &str, fragment: &str, code: i32) {
    cli::case(script, &[fragment], code);
}

#[track_caller]
fn check(what: &str, out: &Output, fragment: &str, code: i32) {
    cli::check(what, out, &[fragment], code);
}

const PAIR: &str = "let s = scene();\ns.add(dumbbell(#{ center: [-25e-6, 0, 0] }));\ns.add(dumbbell(#{ center: [25e-6, 0, 0], phase: 1.0 }));\n";

#[test]
fn oversized_padding_and_spans_are_values_or_clear_errors() {
    case("print(lpad(1, 65536).len());", "65536", 0);
    case("print(rpad(\"D\", 65536).len());", "65536", 0);
    case("lpad(1, 1000000000000);", "SWIMLAB_MAX_STRING", 1);
    case(
        "uniform_randoms(9223372036854775807, 1);",
        "SWIMLAB_MAX_ARRAY",
        1,
    );
    case(
        "plot(\"p.svg\", #{ x: [-1e308, 1e308], y: [0, 1] });",
        "the x values span from -1e308 to 1e308",
        1,
    );
    case(
        "plot(\"p.svg\", #{ x: [0, 1], y: [-1e308, 1e308] });",
        "the y values span",
        1,
    );
}

#[test]
fn unbounded_arrays_strings_and_recursion_stop_at_a_named_limit() {
    case("uniform_randoms(10000000000, 1);", "SWIMLAB_MAX_ARRAY", 1);
    case(
        "let s = \"ab\";\nfor i in 0..40 { s += s; }",
        "SWIMLAB_MAX_STRING",
        1,
    );
    case("fn f(x) { f(x) }\nf(1);", "SWIMLAB_MAX_CALL_DEPTH", 1);
}

#[test]
fn runs_that_would_never_end_are_refused_with_the_numbers() {
    let settled = format!("{PAIR}s.run_periods(1);\n");
    case(
        &format!("{settled}s.record([R_H(0)], 5e-324);\ns.run_periods(0);"),
        "cannot be resolved at t =",
        1,
    );
    case(
        &format!("{PAIR}s.record([R_H(0)], every_seconds(1e-300));\ns.run_periods(1);"),
        "cannot be resolved",
        1,
    );
    case(
        &format!("{PAIR}s.record([R_H(0)], every_periods(1e-9));\ns.run_periods(100);"),
        "rows per run",
        1,
    );
    case(
        "let s = scene();\ns.add_random(dumbbell(), 1000000000, 0.01, 1);",
        "at most 2000000",
        1,
    );
    case("sweep([1, 2], |p| p, 100000000);", "per core", 1);
    case(
        "let s = scene();\ns.add(dumbbell());\ns.add(dumbbell(#{ center: [1e300, 0, 0] }));\ns.snapshot(\"s.png\");",
        "positions may reach",
        1,
    );
    case(
        "plot(\"p.svg\", #{ x: [1e-300, 1e308], y: [1, 2] }, #{ log_x: true });",
        "decades",
        1,
    );
    case("load_scene(\"/dev/full\");", "larger than", 1);
    case(
        &format!("{PAIR}s.integrator = rk4(1e-300);\ns.run(1.0);"),
        "cannot advance the time",
        1,
    );
    case(
        &format!("{PAIR}s.integrator = rk4(1e-7);\ns.run(3e4);"),
        "steps of dt",
        1,
    );
}

/// A saved scene changed as `edit` says (on the JSON text), then loaded.
fn bad_scene(edit: impl Fn(&mut serde_json::Value), fragment: &str) {
    let d = case_dir();
    let good = d.join("good.json");
    let out = swimlab(
        &["-e", &format!("{PAIR}s.save(\"{}\");", good.display())],
        "",
        &d,
    );
    assert!(out.status.success(), "{out:?}");
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&good).unwrap()).unwrap();
    edit(&mut v);
    let bad = d.join("bad.json");
    std::fs::write(&bad, v.to_string()).unwrap();
    let script = format!(
        "let t = load_scene(\"{}\");\nt.run_periods(1);",
        bad.display()
    );
    let out = swimlab(&["-e", &script], "", &d);
    check(&script, &out, fragment, 1);
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(
        text.contains(&bad.display().to_string()),
        "names the file: {text}"
    );
}

#[test]
fn every_bad_saved_scene_is_refused_at_load() {
    bad_scene(
        |v| v["scene"]["integrator"] = serde_json::json!({ "method": "rk4", "dt": 0.0 }),
        "rk4(dt): dt must be a finite positive number",
    );
    bad_scene(
        |v| v["scene"]["integrator"] = serde_json::json!({ "method": "dopri5", "rtol": -1.0 }),
        "dopri5(rtol): rtol",
    );
    bad_scene(
        |v| v["scene"]["integrator"] = serde_json::json!({ "method": "rosw", "rtol": 0.0 }),
        "rosw(rtol): rtol",
    );
    bad_scene(
        |v| v["scene"]["mu"] = (-1e-3).into(),
        "mu must be a finite positive",
    );
    bad_scene(
        |v| v["scene"]["time"] = 1e20.into(),
        "beyond 1e9 stroke periods",
    );
    bad_scene(|v| v["scene"]["time"] = (-1.0).into(), "only grows");
    bad_scene(
        |v| v["scene"]["base"][1] = serde_json::json!([-25e-6, 0.0, 0.0]),
        "overlap",
    );
    bad_scene(
        |v| {
            for k in 3..6 {
                v["scene"]["state"][k] = 0.0.into();
            }
        },
        "dumbbell vector X2 - X1 is zero",
    );
    bad_scene(
        |v| v["scene"]["swimmers"][0]["a1"] = (-1.0).into(),
        "swimmer 0: a1",
    );
    bad_scene(|v| v["format"] = 7.into(), "format 7 is not supported");
    bad_scene(
        |v| v["scene"]["origins"][0]["dir"] = serde_json::json!([0.0, 0.0, 0.0]),
        "the origin of swimmer 0 is not a finite displacement and a unit orientation",
    );
    bad_scene(
        |v| v["scene"]["origins"].as_array_mut().unwrap().truncate(1),
        "2 swimmers but 1 origins",
    );
    bad_scene(
        |v| v["scene"]["state"].as_array_mut().unwrap().truncate(3),
        "inconsistent",
    );
    bad_scene(
        |v| {
            v["scene"]["contacts"]["steric"] =
                serde_json::json!({ "range": -1.0, "stiffness": 1.0 })
        },
        "steric range",
    );
}

#[test]
fn messages_name_the_fix() {
    let run = format!("{PAIR}s.run_period(5);");
    case(&run, "did you mean run_periods?", 1);
    case(&format!("{PAIR}print(s.tme);"), "did you mean .time?", 1);
    case(
        &format!("{PAIR}s.tme = 1;"),
        "the properties that can be set: backend",
        1,
    );
    case(
        &format!("{PAIR}s.mobilty = 1;"),
        "did you mean .mobility?",
        1,
    );
    case(&format!("{PAIR}s.time = 1;"), "can be read but not set", 1);
    case(
        "let s = scene();\ns.add_random(dumbbell(), 10.0, 0.01, 1);",
        "argument 3 of add_random(Scene, Dumbbell, float, float, int) must be an integer",
        1,
    );
    case("R_H(0.0);", "its forms: R_H(int)", 1);
    case("print(fixed(3, 2));", "3.00", 0);
    case("print(sci(3));", "3.0000e0", 0);
    case("rosw(0);", "rosw(rtol): rtol", 1);
    case("import \"paperx\" as p;", "did you mean \"paper\"?", 1);
    // A built-in module used by its name without an import: the import to write, not a
    // suggestion of the very name that was given.
    case(
        "let s = paper::mirror(10.0, true, true);",
        "the module \"paper\" is built in but not imported under that name here: write import \"paper\" as paper;",
        1,
    );
    case(
        "import \"paper\" as p;\np::mirorr(10.0, true, true);",
        "did you mean p::mirror?",
        1,
    );
    // An error inside a stdlib module: at the user's call, with the module's line beneath.
    case(
        "import \"paper\" as p;\nlet s = p::mirror(-1.0, true, true);",
        ".rhai:2:",
        1,
    );
    case(
        "import \"paper\" as p;\nlet s = p::mirror(-1.0, true, true);",
        "inside module \"paper\" at",
        1,
    );
    case(
        "plot(\"/proc/no/p.svg\", #{ x: [1, 2], y: [0, 1] });",
        "cannot",
        1,
    );
    case(
        &format!("{PAIR}s.integrator = euler(1e-3);\ns.run_periods(1);"),
        "explicit methods need dt below ~2.8/rate = 1.969e-5 s here (rate: the scene's stiff rate); or use s.integrator = \"default\"",
        1,
    );
    case("load_scene(\"no/such/file.json\");", "check the path", 1);
}

#[test]
fn the_caret_sits_under_the_error_after_tabs_and_wide_characters() {
    let d = case_dir();
    let file = d.join("caret.rhai");
    std::fs::write(&file, "let x = 1;\n\tlet y = \"é€\"; y.foo();\n").unwrap();
    let out = swimlab(&["run", file.to_str().unwrap()], "", &d);
    let text = String::from_utf8_lossy(&out.stderr);
    let lines: Vec<&str> = text.lines().collect();
    let k = lines
        .iter()
        .position(|l| l.contains("| \tlet y"))
        .expect(&text);
    let (src, caret) = (lines[k], lines[k + 1]);
    let col = src.find("foo").unwrap();
    // Same bytes before the caret as before "y.foo" on screen: tab kept, one space per column.
    let shown: String = src[..col]
        .chars()
        .map(|c| if c == '\t' { '\t' } else { ' ' })
        .collect();
    assert_eq!(caret, format!("{shown}^"), "\n{text}");
}

#[test]
fn a_byte_order_mark_is_accepted() {
    let d = case_dir();
    let file = d.join("bom.rhai");
    std::fs::write(&file, "\u{feff}print(40 + 2);\n").unwrap();
    let out = swimlab(&["run", file.to_str().unwrap()], "", &d);
    check("BOM", &out, "42", 0);
}

#[test]
fn piped_errors_go_to_stderr_and_the_session_goes_on() {
    let out = swimlab(&[], "s.foo;\n1 + 1\n", &case_dir());
    let (o, e) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(o.contains("=> 2") && !o.contains("error"), "stdout: {o}");
    assert!(e.contains("Variable not found: s"), "stderr: {e}");
}

#[test]
fn set_values_are_read_or_refused() {
    let d = case_dir();
    let file = d.join("sets.rhai");
    std::fs::write(&file, "let D = 4.0;\nprint(D);\n").unwrap();
    let f = file.to_str().unwrap();
    let out = swimlab(&["run", f, "--set", "D=10"], "", &d);
    check(
        "shadowed --set",
        &out,
        "hides the value given by --set D=10",
        1,
    );
    let out = swimlab(&["run", f, "--set", "DD=10"], "", &d);
    check("unused --set", &out, "the script never reads DD", 1);
    let out = swimlab(&["run", f, "--set", "D=2", "--set", "D=3"], "", &d);
    check(
        "repeated --set",
        &out,
        "--set D is given twice (D=2 and D=3); give each name once",
        1,
    );
    std::fs::write(&file, "let D = param(\"D\", 4.0);\nprint(`D=${D}`);\n").unwrap();
    let out = swimlab(&["run", f, "--set", "D=10"], "", &d);
    check("param with --set", &out, "D=10", 0);
    let out = swimlab(&["run", f], "", &d);
    check("param default", &out, "D=4.0", 0);
    std::fs::write(&file, "print(`tag=${tag}`);\n").unwrap();
    let out = swimlab(&["run", f, "--set", "tag=7"], "", &d);
    check("read in a string", &out, "tag=7", 0);
    // param as the last expression of a block (an if branch, a function body) is a statement in
    // Rhai's tree: it counts as a read too (it was refused as "never reads").
    std::fs::write(
        &file,
        "let p = if quick() { 1 } else { param(\"P\", 2) };\nfn f() { param(\"Q\", 3) }\nprint(`P=${p} Q=${f()}`);\n",
    )
    .unwrap();
    let out = swimlab(&["run", f, "--set", "P=5", "--set", "Q=6"], "", &d);
    check("param ending a block", &out, "P=5 Q=6", 0);
}

/// Thermal noise's bad input: each refused at the script position with the reason and the fix.
#[test]
fn thermal_noise_refuses_bad_settings_with_the_fix() {
    case(
        &format!("{PAIR}s.temperature = -5;"),
        "temperature must lie between 0 and",
        1,
    );
    case(&format!("{PAIR}s.temperature = \"hot\";"), "temperature", 1);
    case(
        &format!("{PAIR}s.seed = -1;"),
        "seed must be a whole number of 0 or more",
        1,
    );
    case(
        &format!("{PAIR}s.seed = 1.5;"),
        "seed must be a whole number",
        1,
    );
    case(
        &format!("{PAIR}s.noise_root = \"lanczo\";"),
        "did you mean \"lanczos\"",
        1,
    );
    case(
        &format!("{PAIR}s.lanczos_tol = 0;"),
        "lanczos_tol must lie in",
        1,
    );
    case(
        &format!("{PAIR}s.temperature = 300;\ns.integrator = rk4(1e-6);\ns.run_periods(1);"),
        "use s.integrator = euler(dt) or platen(dt)",
        1,
    );
    case(
        &format!("{PAIR}s.model = \"rigid\";\ns.temperature = 300;\ns.run_periods(1);"),
        "s.model = \"micro\"",
        1,
    );
    case(
        &format!("{PAIR}print(s.observe(peclet(0, 1)));"),
        "set a temperature above 0 K",
        1,
    );
    case(&format!("{PAIR}platen(-1.0);"), "platen(dt): dt", 1);
}
