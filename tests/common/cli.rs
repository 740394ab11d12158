//! The `swimlab` binary run as a user runs it, for the bad-input tables: each case in its own
//! process and folder under a time limit, so a hang or an abort fails the test instead of
//! stalling it, and a panic shows as the "internal error" the script boundary turns it into.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Well above any case's real cost (the slowest reads 256 MiB from /dev/full, ~1 s; the rest
/// are a few periods of a pair at most), far below what the hangs these cases once were take.
pub const LIMIT: Duration = Duration::from_secs(60);

/// What no case's output may hold: a panic, a Rust path or debug text, Rhai's raw messages.
const NEVER: &[&str] = &[
    "internal error",
    "panicked",
    "swimlab::",
    "Os {",
    "IoError",
    "BackendError",
    "Function not found",
];

/// A fresh folder for one case (cases run in parallel).
pub fn case_dir() -> PathBuf {
    use std::sync::atomic::{AtomicU64, Ordering};
    static N: AtomicU64 = AtomicU64::new(0);
    let d = std::env::temp_dir()
        .join(format!("swimlab-cases-{}", std::process::id()))
        .join(format!("case-{}", N.fetch_add(1, Ordering::SeqCst)));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Run `swimlab ARGS` in `cwd` (stdin from `input`) to completion within [`LIMIT`].
pub fn swimlab(args: &[&str], input: &str, cwd: &Path) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_swimlab"))
        .args(args)
        .current_dir(cwd)
        .env("SWIMLAB_PROGRESS", "0")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start swimlab");
    let mut stdin = child.stdin.take().unwrap();
    stdin.write_all(input.as_bytes()).unwrap();
    drop(stdin);
    let start = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            return child.wait_with_output().unwrap();
        }
        if start.elapsed() > LIMIT {
            let _ = child.kill();
            panic!("swimlab {args:?} did not finish within {LIMIT:?} (a hang):\n{input}");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// Run `script` as a file with `swimlab run` in `cwd`.
pub fn run_in(script: &str, cwd: &Path) -> Output {
    let file = cwd.join("case.rhai");
    std::fs::write(&file, script).unwrap();
    swimlab(&["run", file.to_str().unwrap()], "", cwd)
}

/// stdout and stderr of a run.
pub fn text(out: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

/// Check a run of `what`: its exit code, that its output holds every fragment, and that nothing
/// in [`NEVER`] surfaced. Returns the output.
#[track_caller]
pub fn check(what: &str, out: &Output, fragments: &[&str], code: i32) -> String {
    let text = text(out);
    assert_eq!(
        out.status.code(),
        Some(code),
        "exit code of:\n{what}\n---\n{text}"
    );
    for f in fragments {
        assert!(text.contains(f), "missing {f:?} for:\n{what}\n---\n{text}");
    }
    for bad in NEVER {
        assert!(!text.contains(bad), "{bad:?} for:\n{what}\n---\n{text}");
    }
    text
}

/// Run `script` with `swimlab run` in a fresh folder and [`check`] it.
#[track_caller]
pub fn case(script: &str, fragments: &[&str], code: i32) -> String {
    check(script, &run_in(script, &case_dir()), fragments, code)
}

/// [`case`], and the output holds none of `absent` (a word the old, wrong message used, a NaN).
#[track_caller]
pub fn case_without(script: &str, fragments: &[&str], absent: &[&str], code: i32) -> String {
    let text = case(script, fragments, code);
    for bad in absent {
        assert!(!text.contains(bad), "{bad:?} for:\n{script}\n---\n{text}");
    }
    text
}
