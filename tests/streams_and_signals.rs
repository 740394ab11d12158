//! Recorded rows survive what ends a process: `rec.stream_csv` appends each row, whole, as it is
//! taken, so `kill -9` loses no row already recorded and leaves no half line; SIGINT stops
//! `swimlab run` at a step boundary as Ctrl-C does in the shell (the script gets the interrupt
//! error, the stream is complete, the exit code is 130); the shell appends each command to its
//! history as it is entered, so a killed terminal keeps it; a closed standard output ends a run
//! quietly, as SIGPIPE ends other command-line tools.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("swimlab-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A long streamed recording of the Fig-1 pair (a row every 1/20 period; the run is far longer
/// than the test waits).
fn start_recording(d: &Path) -> (Child, PathBuf) {
    let csv = d.join("rows.csv");
    let script = d.join("long.rhai");
    std::fs::write(
        &script,
        format!(
            "import \"paper\" as paper;\nlet s = paper::mirror(10.0, true, true);\nlet r = s.record([R_H(0), length(1)], every_periods(0.05));\nr.stream_csv(\"{}\");\ns.run_periods(100000);\n",
            csv.display()
        ),
    )
    .unwrap();
    let child = Command::new(env!("CARGO_BIN_EXE_swimlab"))
        .args(["run", script.to_str().unwrap()])
        .env("SWIMLAB_PROGRESS", "0")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start swimlab");
    (child, csv)
}

fn lines_in(csv: &Path) -> usize {
    std::fs::read_to_string(csv).map_or(0, |t| t.matches('\n').count())
}

/// Wait until the stream holds at least `n` lines (header included).
fn wait_for_lines(csv: &Path, n: usize) -> usize {
    let start = Instant::now();
    loop {
        let k = lines_in(csv);
        if k >= n {
            return k;
        }
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "the stream did not reach {n} lines (has {k})"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Every line whole: the header's number of fields, numbers that parse, a final newline.
fn whole_rows(csv: &Path) -> usize {
    let text = std::fs::read_to_string(csv).unwrap();
    assert!(text.ends_with('\n'), "the file ends inside a line");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header[0], "time [s]");
    let mut rows = 0;
    let mut last_t = f64::NEG_INFINITY;
    for l in lines {
        let fields: Vec<f64> = l
            .split(',')
            .map(|f| {
                f.parse()
                    .unwrap_or_else(|e| panic!("bad field in {l:?}: {e}"))
            })
            .collect();
        assert_eq!(fields.len(), header.len(), "a partial row: {l:?}");
        assert!(fields[0] > last_t, "times increase");
        last_t = fields[0];
        rows += 1;
    }
    rows
}

fn signal(child: &Child, sig: &str) {
    let ok = Command::new("kill")
        .args([sig, &child.id().to_string()])
        .status()
        .unwrap()
        .success();
    assert!(ok, "kill {sig} failed");
}

fn wait_within(child: &mut Child, limit: Duration) -> std::process::ExitStatus {
    let start = Instant::now();
    loop {
        if let Some(s) = child.try_wait().unwrap() {
            return s;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("the process did not end within {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

#[test]
fn kill_9_during_a_streamed_recording_keeps_every_row_already_recorded() {
    let d = dir("kill9");
    let (mut child, csv) = start_recording(&d);
    let seen = wait_for_lines(&csv, 60);
    signal(&child, "-KILL");
    wait_within(&mut child, Duration::from_secs(10));
    let rows = whole_rows(&csv);
    assert!(
        rows + 1 >= seen,
        "rows lost: {rows} rows, {seen} lines seen before the kill"
    );
}

#[test]
fn sigint_stops_swimlab_run_at_a_step_boundary_and_keeps_the_rows() {
    let d = dir("sigint");
    let (mut child, csv) = start_recording(&d);
    let seen = wait_for_lines(&csv, 40);
    signal(&child, "-INT");
    // A step of the pair is ~1 µs: the run stops at once, the process soon after.
    let status = wait_within(&mut child, Duration::from_secs(20));
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(status.code(), Some(130), "exit code; stderr:\n{err}");
    assert!(err.contains("run interrupted at t ="), "{err}");
    assert!(
        err.contains("long.rhai:5:"),
        "names the line of the run: {err}"
    );
    let rows = whole_rows(&csv);
    assert!(
        rows + 1 >= seen,
        "{rows} rows, {seen} lines seen before SIGINT"
    );
}

/// A reader that closes standard output early (`swimlab run s.rhai | head -1`) ends the run
/// quietly with the status a shell gives a process that SIGPIPE ended (141), and rows already
/// streamed stay whole (Rhai's own `print` would panic there: "failed printing to stdout: Broken
/// pipe", an internal error).
#[test]
fn a_closed_standard_output_ends_the_run_quietly() {
    use std::io::BufRead;
    let d = dir("closed-stdout");
    let script = d.join("many.rhai");
    let csv = d.join("rows.csv");
    std::fs::write(
        &script,
        format!(
            "let s = scene();\ns.add(dumbbell());\nlet r = s.record([R_H(0)], every_periods(0.1));\nr.stream_csv(\"{}\");\ns.run_periods(1);\nfor i in 0..100000000 {{ print(i); }}\n",
            csv.display()
        ),
    )
    .unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_swimlab"))
        .args(["run", script.to_str().unwrap()])
        .env("SWIMLAB_PROGRESS", "0")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start swimlab");
    let mut first = String::new();
    std::io::BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    assert_eq!(first, "0\n");
    // The reader is dropped here: the pipe is closed.
    let status = wait_within(&mut child, Duration::from_secs(60));
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(status.code(), Some(141), "stderr:\n{err}");
    assert!(err.is_empty(), "quietly: {err}");
    assert_eq!(
        whole_rows(&csv),
        10,
        "the rows of the one-period run, whole"
    );
}

/// The same for piped input (`swimlab < session.rhai | head -1`): the values the shell shows
/// meet the closed output, and the session ends quietly with 141 instead of running on unread.
#[test]
fn a_closed_standard_output_ends_a_piped_session_quietly() {
    use std::io::BufRead;
    let d = dir("closed-stdout-piped");
    let input = d.join("session.rhai");
    // Far more values than a pipe's buffer holds, each shown on its own line.
    std::fs::write(
        &input,
        format!("let i = 0;\n{}", "i += 1; i\n".repeat(200_000)),
    )
    .unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_swimlab"))
        .env("SWIMLAB_PROGRESS", "0")
        .stdin(std::fs::File::open(&input).unwrap())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start swimlab");
    let mut first = String::new();
    std::io::BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    assert_eq!(first, "=> 1\n");
    let status = wait_within(&mut child, Duration::from_secs(60));
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(status.code(), Some(141), "stderr:\n{err}");
    assert!(err.is_empty(), "quietly: {err}");
}

/// A stream whose file cannot grow (a full disk; here the process's file size limit, 8 KiB, the
/// write failing part way through a row as it does when a disk fills) is cut back to its last
/// whole row; the run stops with the write error, which names the file and the fix, and the
/// recorder keeps its rows in memory (the script reads them after the error).
#[test]
fn a_stream_that_cannot_grow_keeps_whole_rows_and_stops_the_run_with_the_error() {
    let d = dir("full");
    let csv = d.join("rows.csv");
    let script = d.join("full.rhai");
    std::fs::write(
        &script,
        format!(
            "import \"paper\" as paper;\nlet s = paper::mirror(10.0, true, true);\nlet r = s.record([R_H(0), length(1)], every_periods(0.05));\nr.stream_csv(\"{}\");\ntry {{ s.run_periods(1000); print(\"ran through\"); }} catch (e) {{ print(`stopped: ${{e}}`); }}\nprint(`rows in memory: ${{r.rows.len()}}`);\n",
            csv.display()
        ),
    )
    .unwrap();
    // bash's `ulimit -f` counts 1,024-byte blocks; SIGXFSZ ignored, so a write past the limit
    // fails with EFBIG (after writing what fits) instead of killing the process.
    let out = Command::new("bash")
        .arg("-c")
        .arg(format!(
            "ulimit -f 8; trap '' XFSZ; exec '{}' run '{}'",
            env!("CARGO_BIN_EXE_swimlab"),
            script.display()
        ))
        .env("SWIMLAB_PROGRESS", "0")
        .stdin(Stdio::null())
        .output()
        .expect("run swimlab");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("stopped: "), "{stdout}");
    assert!(
        stdout.contains("cannot write") && stdout.contains("disk not full"),
        "{stdout}"
    );
    let size = std::fs::metadata(&csv).unwrap().len();
    assert!(size <= 8192, "{size} bytes");
    let rows = whole_rows(&csv);
    // About 8 KiB of ~50-byte rows were written before the limit.
    assert!(rows > 100, "{rows} rows");
    let in_memory: usize = stdout
        .lines()
        .find_map(|l| l.strip_prefix("rows in memory: "))
        .and_then(|n| n.trim().parse().ok())
        .unwrap_or_else(|| panic!("{stdout}"));
    assert!(
        in_memory >= rows,
        "{in_memory} rows in memory, {rows} in the file"
    );
}

/// A front end that runs several scripts at once gives each its own interrupt request
/// (`interrupt::scoped`): a request stops its own script's runs (a scene's, a plain loop, the
/// calls of a sweep on rayon's threads) and leaves another script, running meanwhile, alone.
#[test]
fn an_interrupt_of_its_own_stops_that_script_alone() {
    use std::sync::mpsc;
    use swimlab::script::interrupt::{self, Interrupt};
    let start = |src: &'static str, stop: Interrupt| {
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            let r = interrupt::scoped(&stop, || {
                let mut scope = rhai::Scope::new();
                swimlab::script::run_source("t.rhai", src, &mut scope)
            });
            let _ = tx.send((r, Instant::now()));
        });
        rx
    };
    // Without its interrupt each of these would run for hours (fixed steps: no stroboscopic
    // macro-steps over the periods).
    let long = [
        "let s = scene(); s.add(dumbbell()); s.integrator = rk4(1e-5); s.run_periods(1e6);",
        "let n = 0; loop { n += 1; }",
        "sweep([1, 2], |p| { let t = scene(); t.add(dumbbell()); t.integrator = rk4(1e-5); \
         t.run_periods(1e6); })",
    ];
    // Runs a scene for 1.5 s of wall time, across the other script's interrupt.
    let other = "let s = scene(); s.add(dumbbell()); let t = timestamp(); \
                 while t.elapsed < 1.5 { s.run_periods(0.05); }";
    for src in long {
        let (mine, theirs) = (Interrupt::new(), Interrupt::new());
        let stopped = start(src, mine.clone());
        let running = start(other, theirs);
        std::thread::sleep(Duration::from_millis(300));
        let asked = Instant::now();
        mine.request();
        let (r, _) = stopped
            .recv_timeout(Duration::from_secs(20))
            .unwrap_or_else(|_| panic!("not stopped by its interrupt: {src}"));
        let err = r.expect_err(src);
        // A run says the time it stopped at; a statement loop, the statement.
        assert!(
            err.contains("run interrupted at t =")
                || err.contains("script interrupted at this statement"),
            "{src}: {err}"
        );
        let (r, ended) = running.recv_timeout(Duration::from_secs(60)).unwrap();
        assert!(r.is_ok(), "the other script was stopped too: {r:?}");
        assert!(
            ended > asked,
            "the other script ended before the interrupt: no check"
        );
    }
}
