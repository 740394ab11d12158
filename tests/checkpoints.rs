//! Checkpoints: a run stopped between checkpoints (an orderly stop or SIGKILL) and started again
//! ends as the uninterrupted run does, the final state bit for bit (its checksum) and the rows
//! byte for byte, for every model and integrator family whose steppers keep memory between steps
//! (adaptive step sizes, stroboscopic macro steps, multirate suspensions, noise counters); a file
//! of another setup is refused by name.

use crate::common::cli::{case, case_dir, check, swimlab, text};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// A script that builds a scene with `setup`, records and streams, checkpoints every `every`
/// periods and runs to `end` periods (or stops at `stop` periods when given); it prints whether
/// it went on from a checkpoint, the final checksum and the row count.
fn script(setup: &str, every: f64, end: f64) -> String {
    format!(
        r#"
let stop = param("stop", 0.0);
let s = scene();
{setup}
let r = s.record([R_H(0), N(0)], 0.25);
r.stream_csv("rows.csv");
let resumed = s.checkpoint("run.checkpoint.json", {every:?});
s.run_to_periods(if stop > 0.0 {{ stop }} else {{ {end:?} }});
print(`resumed=${{resumed}} checksum=${{s.checksum}} rows=${{r.len}}`);
"#
    )
}

fn run(dir: &Path, args: &[&str]) -> String {
    let mut all = vec!["run", "case.rhai"];
    all.extend(args);
    let out = swimlab(&all, "", dir);
    check(&format!("{args:?} in {}", dir.display()), &out, &[], 0);
    String::from_utf8_lossy(&out.stdout).trim_end().to_string()
}

/// The uninterrupted run's last line and rows against a run stopped at `stop` periods and
/// started again.
#[track_caller]
fn resumes_exactly(setup: &str, every: f64, end: f64, stop: f64) {
    let code = script(setup, every, end);
    let whole = case_dir();
    std::fs::write(whole.join("case.rhai"), &code).unwrap();
    let expected = run(&whole, &[]);
    assert!(expected.starts_with("resumed=false"), "{expected}");

    let cut = case_dir();
    std::fs::write(cut.join("case.rhai"), &code).unwrap();
    run(&cut, &["--set", &format!("stop={stop:?}")]);
    let resumed = run(&cut, &[]);
    assert_eq!(
        resumed.replace("resumed=true", "resumed=false"),
        expected,
        "{setup}"
    );
    assert!(resumed.starts_with("resumed=true"), "{resumed}");
    assert_eq!(
        std::fs::read(cut.join("rows.csv")).unwrap(),
        std::fs::read(whole.join("rows.csv")).unwrap(),
        "the streamed rows differ: {setup}"
    );
}

#[test]
fn the_spring_model_goes_on_from_a_checkpoint_bit_for_bit() {
    // auto(tol) on a pair: stroboscopic macro steps over dopri5's inner periods.
    resumes_exactly(
        "s.add(dumbbell(#{ center: [-5e-6, 0, 0], dir: [1, 0, 0] })); s.add(dumbbell(#{ center: [5e-6, 0, 0], dir: [-1, 0, 0], phase: 1.0 }));",
        1.0,
        4.0,
        2.6,
    );
}

#[test]
fn the_rigid_model_with_contacts_in_a_box_goes_on_bit_for_bit() {
    resumes_exactly(
        r#"s.box = [12e-6, 12e-6, 12e-6]; s.add_random(dumbbell(#{ a1: 0.225e-6, a2: 0.1125e-6 }), 6, 1001);
           s.steric = #{ range: 0.5e-6, stiffness: 1e-3, body: "rods", law: "smooth" }; s.overlaps = "allow";
           s.model = "rigid";"#,
        0.5,
        2.0,
        1.3,
    );
}

#[test]
fn noisy_runs_go_on_with_the_same_draws() {
    // The noise is drawn by step count (s.stats.noisy_steps), which the checkpoint holds.
    resumes_exactly(
        "s.model = \"averaged\"; s.add_random(dumbbell(), 8, 1e-3, 3); s.temperature = 300; s.seed = 11;",
        0.5,
        3.0,
        1.7,
    );
    resumes_exactly(
        "s.add(dumbbell()); s.temperature = 300; s.seed = 5;",
        0.25,
        0.5,
        0.3,
    );
}

#[test]
fn a_multirate_suspension_goes_on_bit_for_bit() {
    resumes_exactly(
        r#"s.model = "averaged"; s.box = [40e-6, 40e-6, 40e-6]; s.add_random(dumbbell(), 64, 2);
           s.steric = #{ range: 0.5e-6, stiffness: 1e-3 }; s.integrator = suspension(1e-3);"#,
        2.0,
        10.0,
        5.0,
    );
}

#[test]
fn a_finished_run_started_again_runs_nothing_and_prints_the_same() {
    let code = script("s.add(dumbbell());", 1.0, 2.0);
    let dir = case_dir();
    std::fs::write(dir.join("case.rhai"), &code).unwrap();
    let first = run(&dir, &[]);
    let again = run(&dir, &[]);
    assert_eq!(again.replace("resumed=true", "resumed=false"), first);
}

/// Lines in `path` now (0 while it does not exist).
fn lines_in(path: &Path) -> usize {
    std::fs::read_to_string(path).map_or(0, |t| t.matches('\n').count())
}

/// SIGKILL at a random moment of `scripts/demos/checkpoint.rhai` (in a folder of its own, so its
/// files are the test's), then the script again: its last line and its rows are those of an
/// uninterrupted run. The moment is drawn from the clock as a point of the run's progress (the
/// streamed row it waits for, then up to 40 ms more, inside a step) and shown on failure.
#[test]
fn the_checkpoint_demo_killed_at_a_random_moment_ends_as_an_uninterrupted_run() {
    let demo = std::fs::canonicalize("scripts/demos/checkpoint.rhai").unwrap();
    let demo = demo.to_str().unwrap();
    // 8 periods, a row every quarter period (33 rows), a checkpoint every half period.
    let args = ["run", demo, "--set", "every=0.5"];
    let whole = case_dir();
    let out = swimlab(&args, "", &whole);
    let expected = check("the demo", &out, &["final state checksum"], 0);
    let last = |s: &str| {
        s.lines()
            .rfind(|l| l.starts_with("final"))
            .unwrap()
            .to_string()
    };
    let expected = last(&expected);

    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .subsec_nanos();
    // The rows (header included) to wait for before each kill: one early (maybe before the first
    // checkpoint), one past the middle.
    let moments = [(2 + nanos % 8) as usize, (18 + nanos / 8 % 12) as usize];
    for (i, lines) in moments.into_iter().enumerate() {
        let extra = Duration::from_millis(u64::from(nanos / 96 % 40));
        let cut = case_dir();
        let csv = cut.join("out/demos/checkpoint.csv");
        let mut child = Command::new(env!("CARGO_BIN_EXE_swimlab"))
            .args(args)
            .current_dir(&cut)
            .env("SWIMLAB_PROGRESS", "0")
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let start = Instant::now();
        while lines_in(&csv) < lines && child.try_wait().unwrap().is_none() {
            assert!(
                start.elapsed() < Duration::from_secs(120),
                "no row {lines} came"
            );
            std::thread::sleep(Duration::from_millis(5));
        }
        std::thread::sleep(extra);
        // SIGKILL: no handler runs, nothing is flushed or cleaned up.
        let _ = child.kill();
        let killed = child.wait().unwrap();
        let moment = format!("kill {i} after {lines} lines and {extra:?} ({killed})");
        assert!(!killed.success(), "the run ended before the {moment}");
        let out = swimlab(&args, "", &cut);
        let got = check("the demo after a kill", &out, &["final state checksum"], 0);
        assert_eq!(last(&got), expected, "{moment}:\n{}", text(&out));
        if i == 1 {
            // Past the middle, several checkpoints lie behind the kill.
            assert!(
                got.contains("going on from the checkpoint"),
                "{moment}: {got}"
            );
        }
        assert_eq!(
            std::fs::read(&csv).unwrap(),
            std::fs::read(whole.join("out/demos/checkpoint.csv")).unwrap(),
            "{moment}: the rows differ"
        );
    }
}

#[test]
fn a_checkpoint_of_another_setup_is_refused_by_name() {
    let dir = case_dir();
    let code = |n: i64, every: f64| {
        script(
            &format!("s.add_random(dumbbell(), {n}, 1e-3, 1);"),
            every,
            1.0,
        )
    };
    std::fs::write(dir.join("case.rhai"), code(2, 0.5)).unwrap();
    run(&dir, &[]);
    let with = |code: String, fragments: &[&str]| {
        std::fs::write(dir.join("case.rhai"), &code).unwrap();
        let out = swimlab(&["run", "case.rhai"], "", &dir);
        check(&code, &out, fragments, 1);
    };
    with(
        code(3, 0.5),
        &[
            "run.checkpoint.json was written by another setup",
            "\"swimmers\"",
            "delete the file to start afresh",
        ],
    );
    with(code(2, 0.25), &["was written every 0.5 periods from t = 0 s, this run asks every 0.25 periods from t = 0 s"]);
    with(
        code(2, 0.5).replace(
            "let r = s.record([R_H(0), N(0)], 0.25);",
            "let r = s.record([R_H(1)], 0.25);",
        ),
        &["recorder 0", "it recorded time, R_H[0].x"],
    );
    with(
        code(2, 0.5).replace(
            "r.stream_csv(\"rows.csv\");",
            "r.stream_csv(\"rows.csv\"); s.record([N(1)], 1);",
        ),
        &["holds 1 recorders, this scene has 2"],
    );
    std::fs::write(
        dir.join("run.checkpoint.json"),
        "{\"format\": 1, \"scene\": {}}",
    )
    .unwrap();
    with(code(2, 0.5), &["is not a swimlab checkpoint"]);
    std::fs::write(
        dir.join("run.checkpoint.json"),
        "{\"kind\": \"swimlab checkp",
    )
    .unwrap();
    with(code(2, 0.5), &["is not a swimlab checkpoint"]);
}

#[test]
fn what_a_checkpoint_cannot_carry_is_refused() {
    case(
        "let s = scene(); s.add(dumbbell()); s.trajectory(\"t.xyz\", 1); s.checkpoint(\"c.json\", 1);",
        &["the trajectory t.xyz cannot go on from a checkpoint"],
        1,
    );
    case(
        "let s = scene(); s.add(dumbbell()); s.checkpoint(\"c.json\", 1); s.trajectory(\"t.xyz\", 1);",
        &["a trajectory cannot be written in a run that takes checkpoints (c.json)"],
        1,
    );
    case(
        "let s = scene(); s.add(dumbbell()); s.checkpoint(\"c.json\", at_end());",
        &["checkpoints are taken at regular times, not at the end of each run"],
        1,
    );
    case(
        "let s = scene(); s.add(dumbbell()); s.checkpoint(\"c.json\", \"often\");",
        &["every must be a number of periods, every_periods(n) or every_seconds(t)"],
        1,
    );
    case(
        "let s = scene(); s.add(dumbbell()); s.checkpoint(\"c.json\", -1);",
        &["must be a finite positive number"],
        1,
    );
    case(
        "let s = scene(); s.add(dumbbell()); s.checkpoint(\"\", 1);",
        &["the path is empty"],
        1,
    );
}

#[test]
fn settings_changed_after_checkpoint_are_refused_when_the_checkpoint_is_due() {
    case(
        "let s = scene(); s.add(dumbbell()); s.checkpoint(\"c.json\", 1); s.run_to_periods(0.5); s.mu = 2e-3; s.run_to_periods(2);",
        &["the scene's settings changed since checkpoint() was called (in \"mu\")", "set the scene up before asking for checkpoints"],
        1,
    );
}

/// A damaged or edited checkpoint (cut short, a byte changed, a number made hostile) is read
/// without a panic: refused with a message, or, where the edit leaves a valid checkpoint of the
/// setup, gone on from (then a short run ends or fails with a message). Seeded; in process.
#[test]
fn damaged_checkpoints_are_refused_or_read_never_panic() {
    use swimlab::engine::{Observable, Simulation, Trigger};
    let dir = case_dir();
    let path = dir.join("c.json");
    let setup = || {
        let mut sim = Simulation::new(crate::common::mirror_inwards(10.0, true));
        sim.record(
            vec![Observable::CenterH(0), Observable::Dir(1)],
            Trigger::EveryPeriods(0.25),
        )
        .unwrap();
        sim
    };
    let every = Trigger::EveryPeriods(0.5);
    let mut sim = setup();
    sim.checkpoint(&path, &every).unwrap();
    let t = sim.period().unwrap();
    sim.run_to(1.2 * t).unwrap();
    let good = std::fs::read_to_string(&path).unwrap();
    let hostile = [
        "",
        "}",
        "\"",
        "-",
        "0",
        "1e308",
        "-1e308",
        "5e-324",
        "null",
        "[]",
        "{}",
        "\"x\"",
        "18446744073709551616",
        "-0.0",
    ];
    let mut rng = crate::common::Rng::new(20261207);
    let (mut refused, mut resumed) = (0, 0);
    for case in 0..400 {
        let bytes = good.as_bytes();
        let at = (rng.next() % bytes.len() as u64) as usize;
        let text = match case % 3 {
            0 => String::from_utf8_lossy(&bytes[..at]).into_owned(),
            1 => {
                let mut b = bytes.to_vec();
                b[at] = b"0123456789-e.,:[]{}\"n "[(rng.next() % 22) as usize];
                String::from_utf8_lossy(&b).into_owned()
            }
            _ => {
                // A number token from `at` on replaced by a hostile value.
                let start = good[at..]
                    .find(|c: char| c.is_ascii_digit())
                    .map_or(at, |k| at + k);
                let end = good[start..]
                    .find(|c: char| !(c.is_ascii_digit() || "+-.eE".contains(c)))
                    .map_or(good.len(), |k| start + k);
                format!("{}{}{}", &good[..start], rng.pick(&hostile), &good[end..])
            }
        };
        std::fs::write(&path, &text).unwrap();
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            let mut sim = setup();
            match sim.checkpoint(&path, &every) {
                Err(e) => {
                    let m = e.to_string();
                    assert!(
                        m.contains("c.json") || m.contains("checkpoint"),
                        "case {case}: {m}"
                    );
                    false
                }
                Ok(r) => {
                    // Read: a short run ends or fails with a message (never a panic).
                    if r.is_some() {
                        let _ = sim.run_to(1.5 * t);
                    }
                    true
                }
            }
        }));
        match outcome {
            Ok(true) => resumed += 1,
            Ok(false) => refused += 1,
            Err(_) => panic!("case {case} panicked on:\n{text}"),
        }
    }
    assert!(
        refused > 100 && resumed > 0,
        "refused {refused}, read {resumed}"
    );
}
