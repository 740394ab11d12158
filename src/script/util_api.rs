//! Small helpers scripts need: number formatting, `pi()`, the quick mode of long scripts, and
//! what made a result (`run_info()`).

use super::convert::{number, ScriptResult};
use super::doc::{doc_entry, Doc};
use super::limits;
use rhai::{Dynamic, Engine, INT};

/// Whether scripts should run their quick variant (`swimlab run --quick`, or SWIMLAB_QUICK=1).
pub fn quick() -> bool {
    std::env::var("SWIMLAB_QUICK").is_ok_and(|v| !v.is_empty() && v != "0")
}

fn sci(x: f64, digits: INT) -> String {
    let d = digits.clamp(0, 17) as usize;
    format!("{x:.d$e}")
}

/// `n` uniform numbers in [0, 1) from `seed` (splitmix64: reproducible on every platform).
pub fn uniform_randoms(n: INT, seed: INT) -> ScriptResult<rhai::Array> {
    let n = limits::check_array("uniform_randoms(n, seed)", n as f64)?;
    let mut state = seed as u64;
    Ok((0..n)
        .map(|_| {
            state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^= z >> 31;
            Dynamic::from_float((z >> 11) as f64 / (1u64 << 53) as f64)
        })
        .collect())
}

/// The first value of `key` in a `key : value` listing such as /proc/cpuinfo.
fn listed(text: &str, key: &str) -> Option<String> {
    text.lines().find_map(|l| {
        let (k, v) = l.split_once(':')?;
        (k.trim() == key).then(|| v.trim().to_string())
    })
}

/// This machine in words: its CPU model, logical cores, widest vector unit and memory (what
/// Linux's /proc says; "unknown CPU" elsewhere).
fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| listed(&t, "model name"))
        .unwrap_or_else(|| "unknown CPU".to_string());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let memory = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|t| listed(&t, "MemTotal"))
        .and_then(|v| v.trim_end_matches("kB").trim().parse::<f64>().ok())
        .map_or(String::new(), |kb| {
            format!(", {:.0} GiB", kb / (1u64 << 20) as f64)
        });
    format!(
        "{cpu}, {cores} logical cores, {}{memory}",
        crate::engine::simd::vector_unit()
    )
}

/// `s` quoted for a POSIX shell (as it stands where it needs no quotes).
pub fn shell_quote(s: &str) -> String {
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "/._-=,+:".contains(c))
    {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

/// What made a result: #{ command (the command line), build (version, commit, profile),
/// machine }.
fn run_info() -> rhai::Map {
    let command = std::env::args()
        .enumerate()
        .map(|(i, a)| {
            let a = if i == 0 {
                std::path::Path::new(&a)
                    .file_name()
                    .map_or(a.clone(), |f| f.to_string_lossy().into_owned())
            } else {
                a
            };
            shell_quote(&a)
        })
        .collect::<Vec<_>>()
        .join(" ");
    let profile = if cfg!(debug_assertions) {
        "debug"
    } else {
        "release"
    };
    let build = format!(
        "swimlab {} (commit {}, {profile} build)",
        env!("CARGO_PKG_VERSION"),
        env!("SWIMLAB_COMMIT")
    );
    let mut m = rhai::Map::new();
    m.insert("command".into(), command.into());
    m.insert("build".into(), build.into());
    m.insert("machine".into(), machine().into());
    m
}

/// `x` as text padded to `width` characters, on the left (`right == false`) or the right.
fn pad(x: &Dynamic, width: INT, right: bool) -> ScriptResult<String> {
    let what = if right {
        "rpad(x, width)"
    } else {
        "lpad(x, width)"
    };
    let w = limits::check_string(what, width as f64)?;
    let text = x.to_string();
    let fill = " ".repeat(w.saturating_sub(text.chars().count()));
    Ok(if right {
        format!("{text}{fill}")
    } else {
        format!("{fill}{text}")
    })
}

/// Register the helpers.
pub fn register(engine: &mut Engine) {
    engine
        .register_fn("pi", || std::f64::consts::PI)
        .register_fn("quick", quick)
        .register_fn("run_info", run_info)
        .register_fn("uniform_randoms", uniform_randoms)
        .register_fn("sci", |x: Dynamic| -> ScriptResult<String> {
            Ok(sci(number("sci(x)", &x)?, 4))
        })
        .register_fn("sci", |x: Dynamic, digits: INT| -> ScriptResult<String> {
            Ok(sci(number("sci(x, digits)", &x)?, digits))
        })
        .register_fn("fixed", |x: Dynamic, digits: INT| -> ScriptResult<String> {
            let x = number("fixed(x, digits)", &x)?;
            let d = digits.clamp(0, 17) as usize;
            Ok(format!("{x:.d$}"))
        })
        .register_fn("lpad", |x: Dynamic, width: INT| pad(&x, width, false))
        .register_fn("rpad", |x: Dynamic, width: INT| pad(&x, width, true))
        .register_fn("is_number", |x: Dynamic| x.is_float() || x.is_int())
        .register_fn("display", |v: Dynamic| {
            super::console::display(&v, super::show)
        });
}

/// The help text of this file's script names (`:help NAME`), gathered by [`super::docs`].
pub(super) const DOCS: &[Doc] = &[
    doc_entry!(
        "display",
        "pictures",
        "display(value)",
        "Show a value now, in the middle of a cell or a loop: a notebook shows a Picture inline and other values as text; at the prompt or in a script it prints the value as the shell shows it.",
        "let s = scene(); s.add(dumbbell()); for k in 0..2 { s.run_periods(1.0); display(s.time); }"
    ),
    doc_entry!(
        "sci",
        "formatting",
        "sci(x) -> string\nsci(x, digits) -> string",
        "Scientific notation.",
        "print(sci(1.23456e-7, 2));"
    ),
    doc_entry!(
        "fixed",
        "formatting",
        "fixed(x, digits) -> string",
        "Fixed-point notation.",
        "print(fixed(3.14159, 2));"
    ),
    doc_entry!(
        "lpad",
        "formatting",
        "lpad(x, width) -> string",
        "Right-align x in width characters.",
        "print(lpad(42, 6));"
    ),
    doc_entry!(
        "rpad",
        "formatting",
        "rpad(x, width) -> string",
        "Left-align x in width characters.",
        "print(rpad(\"D\", 6) + \"|\");"
    ),
    doc_entry!(
        "pi",
        "formatting",
        "pi() -> float",
        "The number pi.",
        "print(pi());"
    ),
    doc_entry!(
        "quick",
        "formatting",
        "quick() -> bool",
        "True under `swimlab run --quick` (or SWIMLAB_QUICK=1): long scripts run a short variant.",
        "let n = if quick() { 1 } else { 100 }; print(n);"
    ),
    doc_entry!(
        "run_info",
        "formatting",
        "run_info() -> map",
        "What is making this result: #{ command: the command line, build: swimlab's version, the commit it was built from (\"-modified\" where tracked files differed) and the profile, machine: the CPU, logical cores, vector unit and memory }. Results committed beside a text carry it: write_csv(path, columns, rows, #{ notes: [...] }).",
        "let i = run_info(); print(i.build);"
    ),
    doc_entry!(
        "is_number",
        "formatting",
        "is_number(x) -> bool",
        "Whether x is an integer or a float.",
        "print(is_number(1e-6));"
    ),
    doc_entry!(
        "uniform_randoms",
        "formatting",
        "uniform_randoms(n, seed) -> array",
        "n reproducible uniform numbers in [0, 1) (splitmix64).",
        "print(uniform_randoms(3, 42));"
    ),
];
