//! The shell through a real pseudo-terminal, as a transcript: what only a terminal shows (line
//! editing, completion, continuation lines, Ctrl-C and Ctrl-D). The logic itself is tested below
//! the terminal in `repl_session.rs`; this file stays small.

use expectrl::session::OsSession as Session;
use expectrl::{ControlCode, Eof, Expect};
use std::process::Command;
use std::time::Duration;

/// A fresh prompt starts a line (after any terminal control sequences); rustyline's redraws of the
/// line being edited start with `\r` instead.
const PROMPT: expectrl::Regex<&str> = expectrl::Regex("\n(\x1b\\[[0-9;?]*[a-zA-Z]|\r)*swimlab> ");

fn start() -> Session {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_swimlab"));
    let hist = std::env::temp_dir().join(format!("swimlab-pty-history-{}", std::process::id()));
    cmd.env("SWIMLAB_HISTORY", hist)
        .env("TERM", "xterm")
        .env_remove("SWIMLAB_PROGRESS");
    let mut s = Session::spawn(cmd).expect("spawn swimlab in a pty");
    s.set_expect_timeout(Some(Duration::from_secs(20)));
    s.expect(PROMPT).unwrap();
    s
}

/// Send a line and wait for `expect` and then the next prompt.
#[track_caller]
fn step(s: &mut Session, send: &str, expect: &str) {
    s.send_line(send).unwrap();
    if !expect.is_empty() {
        s.expect(expect)
            .unwrap_or_else(|e| panic!("after {send:?}: expected {expect:?}: {e}"));
    }
    s.expect(PROMPT)
        .unwrap_or_else(|e| panic!("after {send:?}: no prompt: {e}"));
}

#[test]
fn transcript_of_a_session() {
    let mut s = start();
    step(&mut s, "1 + 2", "=> 3");
    // A multi-line function: the parser asks for more until the block closes.
    s.send_line("fn twice(v) {").unwrap();
    s.send_line("  2 * v").unwrap();
    step(&mut s, "}", "");
    step(&mut s, "twice(21)", "=> 42");
    // Completion: "sce" + Tab completes to "scene".
    s.send("let s = sce\t").unwrap();
    step(&mut s, "();", "");
    step(&mut s, "s.count", "=> 0");
    // A second Tab lists the candidates (the first completes what they share), the value's own.
    s.send("s.ru\t\t").unwrap();
    s.expect(expectrl::Regex("run +run_periods"))
        .expect("a second Tab lists the candidates");
    // Ctrl-U clears the line.
    s.send("\x15").unwrap();
    step(&mut s, "40 + 2", "=> 42");
    step(&mut s, ":help rk4", "Classic Runge-Kutta 4");
    // An error keeps the session.
    step(&mut s, "s.model = \"fast\";", "unknown model");
    step(&mut s, "s.add(dumbbell(#{ center: [-25e-6, 0, 0] })); s.add(dumbbell(#{ phase: 1.0, center: [25e-6, 0, 0] }));", "");
    // On the CPU: under "auto" with an adapter present (lavapipe in CI) the process's first run
    // would first time both backends (engine/calibrate.rs), which under the whole suite's load has
    // taken longer than the wait below; the interrupt is what is checked here.
    step(&mut s, "s.backend = \"cpu\";", "");
    let rec = "let rec = s.record([pair_mean(0, 1)], 1);";
    step(&mut s, rec, "");
    // Ctrl-C during a long run stops it at a step boundary and keeps the scene and the rows.
    // The progress bar (shown once a run has lasted half a second) says the run has begun: a
    // Ctrl-C before it would be cleared with the command's start on a slow machine.
    s.send_line("s.run_periods(1000000);").unwrap();
    s.set_expect_timeout(Some(Duration::from_secs(60)));
    s.expect("periods/s").expect("the run has begun");
    s.set_expect_timeout(Some(Duration::from_secs(20)));
    s.send(ControlCode::EndOfText).unwrap();
    s.expect("run interrupted at t =").unwrap();
    s.expect(PROMPT).unwrap();
    step(
        &mut s,
        "s.time > 0.0 && s.count == 2 && rec.len > 1",
        "=> true",
    );
    // Ctrl-C at an empty prompt does not leave; Ctrl-D does.
    s.send(ControlCode::EndOfText).unwrap();
    s.expect("Ctrl-D or :quit leaves").unwrap();
    s.send(ControlCode::EndOfTransmission).unwrap();
    s.expect(Eof).expect("Ctrl-D ends the session");
}

// A run longer than half a second at a terminal shows a progress bar (periods done, rate, ETA),
// cleared when the run ends.
#[test]
fn long_runs_show_a_progress_bar() {
    let mut s = start();
    // The direct step: the default auto(tol) would average 1,000 periods in a blink. Directly
    // they take ~2 s here, well past the bar's 0.5 s delay.
    step(
        &mut s,
        "let s = scene(); s.add(dumbbell()); s.integrator = rk4(s.direct_step);",
        "",
    );
    s.send_line("s.run_periods(1000); s.count").unwrap();
    s.expect("periods/s").expect("a progress bar");
    s.expect("=> 1").unwrap();
    s.expect(PROMPT).unwrap();
}

// History is appended as each command is entered: a terminal that dies (here: the shell is
// killed with SIGKILL, which no exit handler sees) keeps every command typed before.
#[test]
fn history_survives_a_killed_terminal() {
    let hist = std::env::temp_dir().join(format!("swimlab-pty-killed-{}", std::process::id()));
    let _ = std::fs::remove_file(&hist);
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_swimlab"));
    cmd.env("SWIMLAB_HISTORY", &hist).env("TERM", "xterm");
    let mut s = Session::spawn(cmd).expect("spawn swimlab in a pty");
    s.set_expect_timeout(Some(Duration::from_secs(20)));
    s.expect(PROMPT).unwrap();
    step(&mut s, "let kept = 41;", "");
    step(&mut s, "kept + 1", "=> 42");
    let pid = s.get_process().pid().to_string();
    let killed = Command::new("kill").args(["-KILL", &pid]).status().unwrap();
    assert!(killed.success());
    let text = std::fs::read_to_string(&hist).expect("the history file exists");
    assert!(text.contains("let kept = 41;"), "{text}");
    assert!(text.contains("kept + 1"), "{text}");
}

// An empty SWIMLAB_HISTORY or XDG_DATA_HOME counts as unset (the XDG base directory rules): the
// history goes to $HOME/.local/share/swimlab/history, as with neither set.
#[test]
fn empty_history_variables_count_as_unset() {
    let home = std::env::temp_dir().join(format!("swimlab-pty-home-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&home);
    std::fs::create_dir_all(&home).unwrap();
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_swimlab"));
    cmd.env("SWIMLAB_HISTORY", "")
        .env("XDG_DATA_HOME", "")
        .env("HOME", &home)
        .env("TERM", "xterm");
    let mut s = Session::spawn(cmd).expect("spawn swimlab in a pty");
    s.set_expect_timeout(Some(Duration::from_secs(20)));
    s.expect(PROMPT).unwrap();
    step(&mut s, "let typed = 7;", "");
    s.send(ControlCode::EndOfTransmission).unwrap();
    s.expect(Eof).unwrap();
    let hist = home.join(".local/share/swimlab/history");
    let text = std::fs::read_to_string(&hist).expect("the history file under HOME");
    assert!(text.contains("let typed = 7;"), "{text}");
    let _ = std::fs::remove_dir_all(&home);
}
