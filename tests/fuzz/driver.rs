//! The driver the seeded script fuzzers share: scripts made by a generator run one at a time, each
//! on its own thread; one still running after [`PATIENCE`] is interrupted as a user presses
//! Ctrl-C, and must then stop within [`STOP_WITHIN`]. No panic may reach the script boundary
//! (where it shows as an "internal error"), and no message may show a Rust path or debug form.
//! An abort (out of memory) ends the test process, which fails the test.
//!
//! Each script runs under an interrupt request of its own (`interrupt::scoped`), so stopping it
//! stops no other test's run in the same process.

use crate::common::Rng;
use std::sync::{mpsc, Mutex};
use std::time::{Duration, Instant};
use swimlab::script::interrupt::{self, Interrupt};
use swimlab::script::run_source;

/// A script still running after this is interrupted, as a user would press Ctrl-C...
pub const PATIENCE: Duration = Duration::from_secs(3);
/// ...and must then stop within this: a step of any scene the fuzzers build (a few swimmers,
/// spectral Ewald and small continua included) takes well under a second.
pub const STOP_WITHIN: Duration = Duration::from_secs(10);

/// What no message may show: a Rust path or debug form, or Rhai's generated closure names.
pub const LEAKS: &[&str] = &[
    "swimlab::",
    "Os {",
    "IoError",
    "ImageError",
    "anon$",
    "alloc::",
];

/// A template with its placeholders filled left to right: `V` from `values`, `P` from `paths`.
/// Values and paths hold no placeholder letters of their own that a later search could take
/// (they are looked for in the template only).
pub fn fill(template: &str, rng: &mut Rng, values: &[&str], paths: &[&str]) -> String {
    let mut out = String::new();
    for c in template.chars() {
        match c {
            'V' => out.push_str(rng.pick(values)),
            'P' => out.push_str(rng.pick(paths)),
            c => out.push(c),
        }
    }
    out
}

fn from_env<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// A printed line that quotes Rust's spelling of a string type. A swimlab function's wrong call
/// reaches `catch` as its message; an operator's is still Rhai's own error map (Rhai's builtin
/// operators come after any registered form, so none is registered for them), which may.
fn rust_spelling(line: &str) -> bool {
    let operator_map = line
        .strip_prefix("#{\"error\": \"ErrorFunctionNotFound\", \"function\": \"")
        .and_then(|rest| rest.split(' ').next())
        .is_some_and(|f| !f.chars().any(|c| c.is_alphanumeric() || c == '_'));
    line.contains("ImmutableString") && !operator_map
}

/// One script's outcome: the engine's result, what it printed, and the renderer's message when
/// it also ran through [`run_source`].
type Outcome = (Result<(), String>, String, Option<String>);

/// A run of one fuzzer: `scripts` scripts from `seed` (`SWIMLAB_FUZZ_SEED` and
/// `SWIMLAB_FUZZ_SCRIPTS` explore others; a failure names its script, which reruns alone).
pub struct Fuzz {
    pub name: &'static str,
    pub seed: u64,
    pub scripts: usize,
    /// Whether each script runs on an engine whose `print` is captured, so that the messages
    /// the script prints (`catch (e) { print(e); }`) are checked.
    pub captured: bool,
    /// Every this many scripts, the script runs (again) through [`run_source`] (the renderer's
    /// path, with its panic guard); 1 runs every script that way.
    pub rendered_every: usize,
}

impl Fuzz {
    /// Run the scripts `make` writes; `check(k, script, printed)` adds the fuzzer's own checks
    /// of what script `k` printed. Returns a line that says what ran.
    pub fn run(
        &self,
        mut make: impl FnMut(&mut Rng) -> String,
        check: impl Fn(usize, &str, &str),
    ) -> String {
        let (seed, scripts) = (
            from_env("SWIMLAB_FUZZ_SEED", self.seed),
            from_env("SWIMLAB_FUZZ_SCRIPTS", self.scripts),
        );
        let mut rng = Rng::new(seed);
        let mut interrupted = 0;
        for k in 0..scripts {
            let src = make(&mut rng);
            let rendered = k % self.rendered_every.max(1) == 0;
            let (result, printed, rendered) = match run_limited(&src, self.captured, rendered) {
                Ok(r) => r,
                Err(r) => {
                    interrupted += 1;
                    let calls: Vec<&str> = src.lines().filter(|l| l.starts_with("try")).collect();
                    eprintln!(
                        "{}: script {k} interrupted after {PATIENCE:?}:\n  {}",
                        self.name,
                        calls.join("\n  ")
                    );
                    r.unwrap_or_else(|| {
                        fail(format!(
                            "script {k} did not stop within {STOP_WITHIN:?} of an interrupt:\n{src}"
                        ))
                    })
                }
            };
            let all = format!(
                "{}\n{printed}",
                result.as_ref().err().cloned().unwrap_or_default()
            );
            if all.contains("internal error") {
                fail(format!("script {k} panicked:\n{src}\n---\n{all}"));
            }
            if let Some(leak) = LEAKS.iter().find(|l| printed.contains(*l)) {
                fail(format!("script {k} shows {leak:?}:\n{src}\n---\n{printed}"));
            }
            if let Some(line) = printed.lines().find(|l| rust_spelling(l)) {
                fail(format!("script {k} shows a Rust type:\n{src}\n---\n{line}"));
            }
            if let Some(msg) = rendered {
                if msg.contains("internal error") {
                    fail(format!("script {k}:\n{src}\n---\n{msg}"));
                }
                if let Some(leak) = LEAKS.iter().find(|l| msg.contains(*l)) {
                    fail(format!("script {k} shows {leak:?}:\n{msg}"));
                }
            }
            check(k, &src, &printed);
        }
        format!(
            "{}: {scripts} scripts (seed {seed}), {interrupted} interrupted after {PATIENCE:?}",
            self.name
        )
    }
}

/// Fail the test with `msg`, written first to the test's output: a panic's own message is not
/// shown while another thread's script runs under the script boundary's guard (it keeps the
/// default panic hook quiet), as a script that did not stop may still be doing.
pub fn fail(msg: String) -> ! {
    eprintln!("{msg}");
    panic!("{msg}");
}

/// Run `src` on its own thread: `Ok` when it ends within [`PATIENCE`]; else it is interrupted
/// again and again, as a user presses Ctrl-C until it stops, and `Err` holds its outcome, or
/// `None` when it did not stop within [`STOP_WITHIN`].
fn run_limited(src: &str, captured: bool, rendered: bool) -> Result<Outcome, Option<Outcome>> {
    let (tx, rx) = mpsc::channel();
    let body = src.to_string();
    let stop = Interrupt::new();
    let script_stop = stop.clone();
    std::thread::spawn(move || {
        interrupt::scoped(&script_stop, || {
            let (result, text) = if captured {
                run_captured(&body)
            } else {
                (Ok(()), String::new())
            };
            let rendered = rendered.then(|| {
                let mut scope = rhai::Scope::new();
                run_source("fuzz.rhai", &body, &mut scope).err()
            });
            let _ = tx.send((result, text, rendered.flatten()));
        })
    });
    // A thread that panicked outside the renderer's guard drops its sender.
    let died = || {
        let msg = "internal error: the script's thread panicked (its message is above)";
        (Err(msg.to_string()), String::new(), None)
    };
    match rx.recv_timeout(PATIENCE) {
        Ok(r) => return Ok(r),
        Err(mpsc::RecvTimeoutError::Disconnected) => return Ok(died()),
        Err(mpsc::RecvTimeoutError::Timeout) => {}
    }
    // The rendered run clears the request when it starts: ask until the whole script stops.
    let asked = Instant::now();
    let r = loop {
        stop.request();
        match rx.recv_timeout(Duration::from_millis(100)) {
            Ok(r) => break Some(r),
            Err(mpsc::RecvTimeoutError::Disconnected) => break Some(died()),
            Err(mpsc::RecvTimeoutError::Timeout) => {}
        }
        if asked.elapsed() > STOP_WITHIN {
            break None;
        }
    };
    Err(r)
}

/// Run `body` on an engine whose `print` is captured: the result and what it printed.
fn run_captured(body: &str) -> (Result<(), String>, String) {
    let printed = std::sync::Arc::new(Mutex::new(String::new()));
    let sink = printed.clone();
    let mut engine = swimlab::script::engine();
    engine.on_print(move |s| {
        if let Ok(mut p) = sink.lock() {
            p.push_str(s);
            p.push('\n');
        }
    });
    let mut scope = rhai::Scope::new();
    let result = engine
        .compile(body)
        .map_err(|e| e.to_string())
        .and_then(|ast| {
            engine
                .run_ast_with_scope(&mut scope, &ast)
                .map_err(|e| e.to_string())
        });
    let text = printed.lock().map(|p| p.clone()).unwrap_or_default();
    (result, text)
}
