//! The shell's logic below the terminal: state across inputs, shown values, commands, errors that
//! keep the session, multi-line detection by Rhai's parser, and piped input.

use swimlab::repl::{piped, Reply, Session};

fn out(s: &mut Session, input: &str) -> String {
    match s.handle(input) {
        Reply::Output(o) => o,
        other => panic!("{input:?}: {other:?}"),
    }
}

#[test]
fn variables_and_functions_persist_and_expression_values_are_shown() {
    let mut s = Session::new();
    assert_eq!(out(&mut s, "let x = 2;"), "");
    assert_eq!(out(&mut s, "fn twice(v) {\n  2 * v\n}"), "");
    assert_eq!(out(&mut s, "twice(x) + 1"), "=> 5");
    assert_eq!(out(&mut s, "let sc = scene(); sc.add(dumbbell());"), "");
    assert!(out(&mut s, "sc").starts_with("=> Scene(1 swimmers"));
    assert_eq!(out(&mut s, "sc.count;"), "", "a trailing ; hides the value");
    assert!(out(&mut s, ":vars").contains("let sc: Scene = Scene(1 swimmers"));
}

#[test]
fn errors_show_a_caret_and_keep_the_session_and_the_scene() {
    let mut s = Session::new();
    out(&mut s, "let sc = scene(); sc.add(dumbbell());");
    match s.handle("sc.add(dumbbell(#{ radius: 1e-6 }));") {
        Reply::Error(e) => {
            assert!(e.contains("unknown dumbbell key \"radius\""), "{e}");
            assert!(e.contains('^'), "{e}");
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(out(&mut s, "sc.count"), "=> 1");
}

#[test]
fn multi_line_input_is_detected_by_the_parser() {
    let s = Session::new();
    for incomplete in [
        "fn f(x) {",
        "let a = [1,",
        "sc.run(",
        "let m = #{ a: 1,",
        "let x = 1 +",
        "if true {\n  print(1);",
    ] {
        assert!(!s.is_complete(incomplete), "{incomplete:?} should continue");
    }
    for complete in [
        "print(1)",
        "let x = (1 + ;",
        ":help",
        "",
        "fn f(x) {\n x\n}",
    ] {
        assert!(
            s.is_complete(complete),
            "{complete:?} is complete (or a real error)"
        );
    }
}

#[test]
fn help_lists_everything_and_shows_one_name() {
    let mut s = Session::new();
    let all = out(&mut s, ":help");
    for name in ["scene", "dumbbell", "run_periods", "record", "R_H", ":load"] {
        assert!(all.contains(name), "{name} missing from :help");
    }
    let one = out(&mut s, ":help run_periods");
    assert!(
        one.contains("s.run_periods(n)") && one.contains("example:"),
        "{one}"
    );
    match s.handle(":help run_period") {
        Reply::Error(e) => assert!(e.contains("did you mean \"run_periods\""), "{e}"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn load_clear_and_quit() {
    let mut s = Session::new();
    assert!(matches!(s.handle(":load no/such.rhai"), Reply::Error(_)));
    let dir = std::env::temp_dir().join(format!("swimlab-repl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("def.rhai");
    std::fs::write(&f, "let loaded = 41;\nfn inc(v) { v + 1 }\n").unwrap();
    out(&mut s, &format!(":load {}", f.display()));
    assert_eq!(out(&mut s, "inc(loaded)"), "=> 42");
    out(&mut s, ":clear");
    assert!(matches!(s.handle("loaded"), Reply::Error(_)));
    assert_eq!(s.handle(":quit"), Reply::Quit);
}

#[test]
fn piped_input_runs_line_by_line_and_reports_failure() {
    let input =
        "let s = scene();\nfn f(x) {\n  x * 2\n}\nf(21)\ns.mobility = \"stokes\";\ns.mobility\n";
    let (mut buf, mut errs) = (Vec::new(), Vec::new());
    let ok = piped(input.as_bytes(), &mut buf, &mut errs);
    let text = String::from_utf8(buf).unwrap();
    let errors = String::from_utf8(errs).unwrap();
    assert!(!ok, "an error makes the piped session fail");
    assert!(text.contains("=> 42"), "{text}");
    assert!(
        errors.contains("unknown mobility"),
        "errors go to stderr: {errors}"
    );
    assert!(!text.contains("unknown mobility"), "not to stdout: {text}");
    assert!(
        text.contains("=> \"rpy\""),
        "the session went on after the error: {text}"
    );
}

#[test]
fn imports_stay_for_later_inputs() {
    let mut s = Session::new();
    assert_eq!(out(&mut s, "import \"paper\" as paper;"), "");
    assert_eq!(out(&mut s, "let sc = paper::mirror(10.0, true, true);"), "");
    assert_eq!(out(&mut s, "sc.count"), "=> 2");
    assert_eq!(out(&mut s, "paper::ell()"), "=> 5e-6");
}

/// A variable hidden by a later `let` of the same name is dropped: a notebook cell run again
/// makes its scene and its trajectory afresh, and the hidden scene's recorder lets its file go
/// (two writers on one file are refused while both live).
#[test]
fn a_cell_run_again_writes_its_trajectory_afresh() {
    let dir = std::env::temp_dir().join(format!("swimlab-repl-rerun-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("t.xyz");
    let cell = format!(
        "let s = scene(); s.add(dumbbell()); s.trajectory(\"{}\", 0.5); s.run_periods(1);",
        path.display()
    );
    let mut s = Session::new();
    out(&mut s, &cell);
    out(&mut s, &cell);
    let vars = out(&mut s, ":vars");
    assert_eq!(vars.matches("let s:").count(), 1, "{vars}");
    let text = std::fs::read_to_string(&path).unwrap();
    assert_eq!(
        text.matches("Properties=").count(),
        3,
        "three frames: {text}"
    );
    match s.handle(&format!(
        "let t = s; s.trajectory(\"{}\", 1);",
        path.display()
    )) {
        Reply::Error(e) => assert!(e.contains("is being written by a trajectory"), "{e}"),
        other => panic!("{other:?}"),
    }
}

/// An input that fails before it declares a variable anew leaves the old one as it was (it was
/// only set aside for the run); one that reads the variable in its own declaration keeps it too.
#[test]
fn a_failed_redeclaration_keeps_the_old_variable() {
    let mut s = Session::new();
    out(&mut s, "let sc = scene(); sc.add(dumbbell());");
    assert!(matches!(
        s.handle("let sc = load_scene(\"no/such/scene.json\");"),
        Reply::Error(_)
    ));
    assert_eq!(out(&mut s, "sc.count"), "=> 1");
    out(
        &mut s,
        "let sc = sc.copy(); sc.add(dumbbell(#{ center: [20e-6, 0, 0] }));",
    );
    assert_eq!(out(&mut s, "sc.count"), "=> 2");
}

// `ans` is the last value an input gave, shown or not (as in Julia); a constant `ans` of the
// user's stays.
#[test]
fn ans_is_the_last_value() {
    let mut s = Session::new();
    assert_eq!(out(&mut s, "1 + 2"), "=> 3");
    assert_eq!(out(&mut s, "ans * 10"), "=> 30");
    assert_eq!(out(&mut s, "ans + 1;"), "", "a trailing ; hides the value");
    assert_eq!(out(&mut s, "ans"), "=> 31");
    assert_eq!(out(&mut s, "let x = 5;"), "", "a statement gives no value");
    assert_eq!(out(&mut s, "ans"), "=> 31");
    assert!(matches!(s.handle("undefined_name + 1"), Reply::Error(_)));
    assert_eq!(out(&mut s, "ans"), "=> 31", "a failed input leaves ans");
    out(&mut s, "const ans = 7;");
    assert_eq!(out(&mut s, "40 + 2"), "=> 42");
    assert_eq!(out(&mut s, "ans"), "=> 7");
}

// `:time CODE` answers as CODE does, then with its wall time and, for each scene that ran, the
// steps and right-hand sides it took; `:history [N]` lists the session's inputs.
#[test]
fn time_and_history_commands() {
    let mut s = Session::new();
    assert_eq!(out(&mut s, "let sc = scene(); sc.add(dumbbell());"), "");
    let timed = out(
        &mut s,
        ":time sc.integrator = rk4(1e-5); sc.run(0.001); sc.count",
    );
    let lines: Vec<&str> = timed.lines().collect();
    assert_eq!(lines[0], "=> 1", "{timed}");
    assert!(lines[1].starts_with("time: "), "{timed}");
    assert_eq!(lines[2], "sc: 100 steps, 400 right-hand sides", "{timed}");
    assert_eq!(out(&mut s, ":time 1 + 1").lines().count(), 2);
    match s.handle(":time") {
        Reply::Error(e) => assert!(e.contains(":time s.run_periods(100)"), "{e}"),
        other => panic!("{other:?}"),
    }
    let all = out(&mut s, ":history");
    assert!(all.starts_with("   1  let sc = scene();"), "{all}");
    assert!(all.contains("   2  :time sc.integrator"), "{all}");
    assert_eq!(out(&mut s, ":history 1"), "   4  :time");
    match s.handle(":history x") {
        Reply::Error(e) => assert!(e.contains(":history 10"), "{e}"),
        other => panic!("{other:?}"),
    }
}

// Completion after `value.` offers that value's own methods and properties when its type is
// known (a Field's `to_vtk`, not a Scene's), and every name otherwise.
#[test]
fn completion_after_a_dot_follows_the_value_type() {
    let mut s = Session::new();
    out(
        &mut s,
        "let sc = scene(); sc.box = [1e-4, 1e-4, 1e-4]; sc.add(dumbbell()); let f = sc.field(\"density\");",
    );
    let names = |s: &Session, line: &str| s.complete(line, line.len()).1;
    assert_eq!(names(&s, "f.to_v"), vec!["to_vtk"]);
    assert!(
        names(&s, "sc.to_v").is_empty(),
        "{:?}",
        names(&s, "sc.to_v")
    );
    let runs = names(&s, "sc.ru");
    assert!(
        runs.contains(&"run".to_string()) && runs.contains(&"run_periods".to_string()),
        "{runs:?}"
    );
    assert!(names(&s, "sc.").contains(&"count".to_string()));
    assert!(!names(&s, "sc.").contains(&"to_vtk".to_string()));
    // An unknown receiver: every name.
    assert!(names(&s, "nothing.to_v").contains(&"to_vtk".to_string()));
}
