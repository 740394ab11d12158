//! The Jupyter kernel driven by real Jupyter clients: jupyter_client for the protocol (values,
//! persistence, pictures, errors, interrupts by message and by signal, progress, completion,
//! inspection, forged and unsigned messages, restart, shutdown: tests/jupyter/drive_kernel.py),
//! and nbclient executing the teaching notebooks of examples/notebooks with their outputs checked
//! (tests/jupyter/run_notebooks.py). Skipped without a Python that has them, unless
//! `SWIMLAB_REQUIRE_JUPYTER=1` (CI, whose `.ci/run` makes one).

use crate::common::python_with;
use std::path::Path;
use std::process::Command;

fn python() -> Option<std::path::PathBuf> {
    python_with(
        "jupyter_client, nbclient, nbformat, zmq",
        "SWIMLAB_REQUIRE_JUPYTER",
        "python3 -m venv .venv && .venv/bin/pip install jupyter_client nbclient nbformat",
    )
}

/// Run a driver script under tests/jupyter with the swimlab binary; it prints "ok ..." per check.
fn drive(script: &str, extra: &[&str]) {
    let Some(py) = python() else {
        return;
    };
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = Command::new(py)
        .arg("-u")
        .arg(dir.join("tests/jupyter").join(script))
        .arg(env!("CARGO_BIN_EXE_swimlab"))
        .args(extra)
        // Kernels started by the clients must not find a user's own kernelspecs or config.
        .env(
            "JUPYTER_CONFIG_DIR",
            std::env::temp_dir().join("swimlab-test-jupyter-config"),
        )
        .output()
        .expect("python runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    eprintln!("{stdout}");
    assert!(out.status.success(), "{script} failed:\n{stdout}\n{stderr}");
}

#[test]
fn jupyter_client_drives_the_kernel() {
    drive("drive_kernel.py", &[]);
}

#[test]
fn the_teaching_notebooks_run_against_the_kernel() {
    let notebooks = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/notebooks");
    drive(
        "run_notebooks.py",
        &[notebooks.to_str().expect("a UTF-8 path")],
    );
}
