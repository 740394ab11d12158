//! Every shipped script runs through the real binary, and `scripts/pair.rhai` prints the drift the
//! engine computes.

use crate::common;
use std::process::Command;

fn swimlab(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_swimlab"))
        .args(args)
        .env("SWIMLAB_QUICK", "1")
        .output()
        .expect("swimlab runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn pair_script_prints_the_fig1_drift() {
    let (ok, out, err) = swimlab(&["run", "scripts/pair.rhai"]);
    assert!(ok, "{err}");
    let line = out
        .lines()
        .find(|l| l.starts_with("collective drift per period:"))
        .unwrap_or_else(|| panic!("no drift line in:\n{out}"));
    let value: f64 = line.split_whitespace().nth(4).unwrap().parse().unwrap();
    // Independent of the script: the engine with a converged integrator.
    let mut s = common::mirror_inwards(10.0, true);
    s.set_integrator(Some(common::reference()));
    let (expected, _) = common::drift_per_period(&mut s, 10.0);
    assert!(
        common::rel(value, expected) < 1e-4,
        "script {value:e}, engine {expected:e}"
    );
}

#[test]
fn run_without_a_file_runs_the_built_in_experiment() {
    let (ok, out, err) = swimlab(&["run"]);
    assert!(ok, "{err}");
    assert!(out.contains("collective drift per period"));
}

/// Settings that shrink a script's quick mode further where it is long for the suite; each keeps
/// every code path of the script. The density study's `--quick` runs every state of the study
/// with the spring model (about three minutes on two cores); here one state, with the quick
/// mode's two seeds (its standard errors need two). The bulk demo's quick mode runs 300 swimmers
/// in each of its four cases; here 100. The instantaneous comparison's quick mode takes four
/// densities; here the thinnest and the densest, with the open-space check.
fn smaller(path: &std::path::Path) -> Vec<&'static str> {
    if path.ends_with("study/densities.rhai") {
        vec![
            "--set",
            "densities=0.01",
            "--set",
            "kinds=asymmetric",
            "--set",
            "phases=two",
        ]
    } else if path.ends_with("study/instantaneous.rhai") {
        vec!["--set", "densities=0.001,0.03", "--set", "open=true"]
    } else if path.ends_with("demos/bulk.rhai") {
        vec!["--set", "n=100"]
    } else {
        vec![]
    }
}

// Two scripts at a time: most are serial, and the suite's other thread is often waiting on a
// child process of its own.
#[test]
fn every_shipped_script_runs() {
    let mut scripts = Vec::new();
    let mut stack = vec![std::path::PathBuf::from("scripts")];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rhai") {
                scripts.push(path);
            }
        }
    }
    assert!(!scripts.is_empty());
    let next = std::sync::Mutex::new(scripts.into_iter());
    let failures: Vec<String> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..2)
            .map(|_| {
                scope.spawn(|| {
                    let mut failed = Vec::new();
                    loop {
                        let Some(path) = next.lock().unwrap().next() else {
                            break;
                        };
                        let mut args = vec!["run", path.to_str().unwrap()];
                        args.extend(smaller(&path));
                        let (ok, _, err) = swimlab(&args);
                        if !ok {
                            failed.push(format!("{}: {err}", path.display()));
                        }
                    }
                    failed
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().unwrap())
            .collect()
    });
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn errors_exit_non_zero_with_file_line_and_column() {
    let dir = std::env::temp_dir().join(format!("swimlab-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("bad.rhai");
    std::fs::write(&f, "let s = scene();\n\ns.model = \"fast\";\n").unwrap();
    let (ok, _, err) = swimlab(&["run", f.to_str().unwrap()]);
    assert!(!ok);
    assert!(err.contains("bad.rhai:3:"), "{err}");
    assert!(err.contains("unknown model"), "{err}");
    let (ok, _, err) = swimlab(&["run", "no/such/file.rhai"]);
    assert!(!ok && err.contains("cannot read"), "{err}");
}

#[test]
fn set_exposes_values_and_e_evaluates() {
    let dir = std::env::temp_dir().join(format!("swimlab-set-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("set.rhai");
    std::fs::write(&f, "print(`${D * 2} ${name} ${flag} ${n + 1}`);\n").unwrap();
    let (ok, out, err) = swimlab(&[
        "run",
        f.to_str().unwrap(),
        "--set",
        "D=2.5",
        "--set",
        "name=mirror",
        "--set",
        "flag=true",
        "--set",
        "n=4",
    ]);
    assert!(ok, "{err}");
    assert_eq!(out.trim(), "5.0 mirror true 5");
    let (ok, _, err) = swimlab(&["run", f.to_str().unwrap(), "--set", "2x=1"]);
    assert!(!ok && err.contains("not a valid variable name"), "{err}");
    let (ok, out, _) = swimlab(&["-e", "let s = scene(); s.add(dumbbell()); s.count + 1"]);
    assert!(ok);
    assert_eq!(out.trim(), "2");
    let (ok, _, err) = swimlab(&["-e", "let s = scene(); s.model = \"x\""]);
    assert!(!ok && err.contains("unknown model"), "{err}");
}

/// The density study's settings are each checked by name with its range before anything runs:
/// `seeds=0` is not an index error deep inside, `rows=0` not a division by zero, `seeds=1.5`
/// not an operator error, `densities=0` not a box of side inf, and `n=0` does not run the least
/// count that fits in silence.
#[test]
fn the_density_studys_settings_are_checked_by_name() {
    let cases: &[(&str, &str)] = &[
        ("seeds=0", "seeds must be a whole number ≥ 1, got 0"),
        ("seeds=1.5", "seeds must be a whole number ≥ 1, got 1.5"),
        ("rows=0", "rows must be a whole number ≥ 2, got 0"),
        ("n=0", "n must be a whole number ≥ 1, got 0"),
        ("n=-5", "n must be a whole number ≥ 1, got -5"),
        ("periods=x", "periods must be a whole number ≥ 1, got \"x\""),
        (
            "densities=0",
            "each density is a sphere volume fraction above 0 and below 0.5",
        ),
        ("densities=0.01,abc", "got \"abc\""),
    ];
    for (set, message) in cases {
        let (ok, out, err) = swimlab(&["run", "scripts/study/densities.rhai", "--set", set]);
        assert!(!ok, "--set {set} ran:\n{out}");
        assert!(err.contains(message), "--set {set}:\n{err}");
        assert!(!out.contains("phi ="), "--set {set} ran a state:\n{out}");
    }
}
