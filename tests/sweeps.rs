//! `swimlab sweep`: every grid point in its own folder, index.csv, a failing point that does not
//! stop the others, `--resume`, and the SLURM job array whose tasks (run here by setting
//! SLURM_ARRAY_TASK_ID, as SLURM does) give exactly the local sweep's files.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("swimlab-sweep-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The averaged Fig-1 pair's drift per period at separation D and phase difference PHI, written
/// to result.csv in the working folder. D = -1 makes the swimmers overlap: an error.
const SCRIPT: &str = r#"
import "paper" as paper;
let D = param("D", 10.0);
let PHI = param("PHI", 1.5707963267948966);
let s = paper::mirror(D, true, true);
s.phases = [0.0, PHI];
s.model = "averaged";
let v = s.velocity(0)[0] * s.period / paper::ell();
write_csv("result.csv", [#{ D: D, PHI: PHI, drift_per_period: v }]);
print(`D = ${D}, phi = ${PHI}: drift ${v} ell per period`);
"#;

fn swimlab(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_swimlab"))
        .args(args)
        .current_dir(cwd)
        .output()
        .unwrap()
}

fn index(out: &Path) -> Vec<Vec<String>> {
    csv::Reader::from_path(out.join("index.csv"))
        .unwrap()
        .records()
        .map(|r| r.unwrap().iter().map(str::to_string).collect())
        .collect()
}

#[test]
fn a_local_sweep_runs_every_point_in_its_folder_and_survives_a_failing_one() {
    let d = dir("local");
    std::fs::write(d.join("drift.rhai"), SCRIPT).unwrap();
    let out = swimlab(
        &[
            "sweep",
            "drift.rhai",
            "--grid",
            "D=-1,8,12",
            "--grid",
            "PHI=0.5,1.0",
            "--out",
            "out",
            "--jobs",
            "2",
        ],
        &d,
    );
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        out.status.code(),
        Some(1),
        "a failed point makes the sweep fail:\n{text}"
    );
    assert!(text.contains("4 of 6 points ok"), "{text}");
    assert!(text.contains("rerun with --resume"), "{text}");
    let rows = index(&d.join("out"));
    assert_eq!(rows.len(), 6);
    for (k, row) in rows.iter().enumerate() {
        assert_eq!(row[0], k.to_string());
        // The last axis varies fastest.
        assert_eq!(row[1], ["-1", "-1", "8", "8", "12", "12"][k]);
        assert_eq!(row[2], ["0.5", "1.0"][k % 2]);
        let folder = d.join("out").join(k.to_string());
        if k < 2 {
            assert_eq!(row[3], "failed (exit 1)");
            let err = std::fs::read_to_string(folder.join("stderr.txt")).unwrap();
            assert!(
                err.contains("overlap"),
                "point {k}'s stderr says why: {err}"
            );
        } else {
            assert_eq!(row[3], "ok");
            assert!(row[4].parse::<f64>().unwrap() >= 0.0);
            let stdout = std::fs::read_to_string(folder.join("stdout.txt")).unwrap();
            assert!(stdout.contains(&format!("D = {}", row[1])), "{stdout}");
            assert!(
                folder.join("result.csv").exists(),
                "files land in the point's folder"
            );
        }
    }
}

#[test]
fn resume_runs_only_the_points_not_finished() {
    let d = dir("resume");
    std::fs::write(d.join("drift.rhai"), SCRIPT).unwrap();
    let args = [
        "sweep",
        "drift.rhai",
        "--grid",
        "D=8,12,16",
        "--out",
        "out",
        "--jobs",
        "1",
    ];
    assert!(swimlab(&args, &d).status.success());
    let stamp = |k: usize| {
        std::fs::metadata(d.join("out").join(k.to_string()).join("result.csv"))
            .unwrap()
            .modified()
            .unwrap()
    };
    let before: Vec<_> = (0..3).map(stamp).collect();
    // Point 1 "did not finish": its status is gone.
    std::fs::remove_file(d.join("out/1/status.txt")).unwrap();
    std::thread::sleep(std::time::Duration::from_millis(20));
    let mut resumed = args.to_vec();
    resumed.push("--resume");
    let out = swimlab(&resumed, &d);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    assert!(text.contains("3 points (1 to run"), "{text}");
    assert_eq!(stamp(0), before[0], "a finished point is not run again");
    assert_eq!(stamp(2), before[2]);
    assert_ne!(stamp(1), before[1], "the unfinished point runs");
    assert!(index(&d.join("out")).iter().all(|r| r[2] == "ok"));
}

/// The same 6-point grid swept locally into `local/` and written as a SLURM job into `cluster/`
/// (not run); returns the job script.
fn local_sweep_and_job(d: &Path) -> PathBuf {
    std::fs::write(d.join("drift.rhai"), SCRIPT).unwrap();
    let grid = ["--grid", "D=8,12", "--grid", "PHI=0.5,1.0,2.0"];
    let mut local = vec!["sweep", "drift.rhai"];
    local.extend(grid);
    local.extend(["--out", "local"]);
    assert!(swimlab(&local, d).status.success());
    let mut slurm = vec!["sweep", "drift.rhai"];
    slurm.extend(grid);
    slurm.extend(["--out", "cluster", "--slurm"]);
    assert!(swimlab(&slurm, d).status.success());
    d.join("cluster/sweep.sbatch")
}

/// Every point's result.csv and stdout.txt are the same in `local/` and `cluster/`, and
/// cluster/index.csv says ok for all.
fn cluster_equals_local(d: &Path) {
    for k in 0..6 {
        for file in ["result.csv", "stdout.txt"] {
            let a = std::fs::read(d.join("local").join(k.to_string()).join(file)).unwrap();
            let b = std::fs::read(d.join("cluster").join(k.to_string()).join(file)).unwrap();
            assert_eq!(
                a, b,
                "point {k}: {file} differs between the local sweep and SLURM"
            );
        }
    }
    let rows = index(&d.join("cluster"));
    assert!(rows.iter().all(|r| r[3] == "ok"), "{rows:?}");
}

#[test]
fn slurm_tasks_give_the_local_sweeps_files() {
    let d = dir("slurm");
    let script = local_sweep_and_job(&d);
    let text = std::fs::read_to_string(&script).unwrap();
    assert!(text.starts_with("#!/bin/bash\n"));
    assert!(text.contains("#SBATCH --array=0-5\n"), "{text}");
    assert!(index(&d.join("cluster")).iter().all(|r| r[3] == "pending"));
    // What SLURM does for task k: run the script with SLURM_ARRAY_TASK_ID=k (from elsewhere).
    for k in 0..6 {
        let o = Command::new("bash")
            .arg(&script)
            .env("SLURM_ARRAY_TASK_ID", k.to_string())
            .current_dir(std::env::temp_dir())
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "task {k}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    cluster_equals_local(&d);
    // Without a task id the script refuses, naming the variable.
    let o = Command::new("bash").arg(&script).output().unwrap();
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("SLURM_ARRAY_TASK_ID"));
}

#[test]
fn bad_grids_are_refused_with_the_fix() {
    let d = dir("bad");
    std::fs::write(d.join("drift.rhai"), SCRIPT).unwrap();
    for (args, fragment) in [
        (
            vec!["sweep", "drift.rhai", "--grid", "D", "--out", "o"],
            "expected NAME=v1,v2",
        ),
        (
            vec!["sweep", "drift.rhai", "--grid", "D=1,,2", "--out", "o"],
            "an empty value",
        ),
        (
            vec![
                "sweep",
                "drift.rhai",
                "--grid",
                "D=1",
                "--grid",
                "D=2",
                "--out",
                "o",
            ],
            "given twice",
        ),
        (
            vec!["sweep", "nothere.rhai", "--grid", "D=1", "--out", "o"],
            "cannot read the script",
        ),
        (
            vec![
                "sweep",
                "drift.rhai",
                "--grid",
                "D=8",
                "--out",
                "o",
                "--task",
                "3",
            ],
            "task 3 is not a point",
        ),
    ] {
        let out = swimlab(&args, &d);
        let text = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?}");
        assert!(text.contains(fragment), "{args:?}: {text}");
    }
}

/// With a SLURM cluster at hand (`.ci/run` starts a one-node one with `.ci/slurm-up` and sets
/// SWIMLAB_SLURM=1), the job script is submitted for real: `sbatch --wait` runs the array, and
/// every point's files equal the local sweep's, index.csv complete. Without one it is skipped
/// with a message (the test above runs the tasks as SLURM would).
#[test]
fn a_real_slurm_cluster_runs_the_job_array() {
    if std::env::var("SWIMLAB_SLURM").as_deref() != Ok("1") {
        eprintln!("skipped: no SLURM cluster (SWIMLAB_SLURM=1 after .ci/slurm-up)");
        return;
    }
    let d = dir("real-slurm");
    local_sweep_and_job(&d);
    let mut job = Command::new("sbatch")
        .args(["--wait", "cluster/sweep.sbatch"])
        .current_dir(&d)
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    let status = loop {
        if let Some(st) = job.try_wait().unwrap() {
            break st;
        }
        if start.elapsed() > std::time::Duration::from_secs(300) {
            let _ = job.kill();
            panic!("the SLURM job array did not finish within 5 minutes");
        }
        std::thread::sleep(std::time::Duration::from_millis(100));
    };
    assert!(status.success(), "sbatch --wait: {status}");
    cluster_equals_local(&d);
}

/// A point whose script takes checkpoints and was cut off after some (here: it stops with an
/// error after its first period the first time) goes on from its last checkpoint under
/// `--resume`, in its own folder, and ends as the point that ran through: the same checksum.
#[test]
fn resume_takes_a_cut_off_point_on_from_its_checkpoint() {
    let d = dir("checkpoint");
    std::fs::write(
        d.join("long.rhai"),
        r#"
let cut = param("cut", 0);
let s = scene();
s.add_random(dumbbell(), 3, 1e-3, 5);
let r = s.record([R_H(0)], 0.25);
r.stream_csv("rows.csv");
let resumed = s.checkpoint("run.checkpoint.json", 0.5);
s.run_to_periods(1.2);
if cut == 1 && !resumed { throw "cut off (a stand-in for a time limit)"; }
s.run_to_periods(2.0);
print(`resumed=${resumed} checksum=${s.checksum} rows=${r.len}`);
"#,
    )
    .unwrap();
    let args = [
        "sweep",
        "long.rhai",
        "--grid",
        "cut=0,1",
        "--out",
        "out",
        "--jobs",
        "2",
    ];
    let out = swimlab(&args, &d);
    assert_eq!(out.status.code(), Some(1));
    let mut resume = args.to_vec();
    resume.push("--resume");
    let out = swimlab(&resume, &d);
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{text}");
    let stdout = |k: usize| std::fs::read_to_string(d.join(format!("out/{k}/stdout.txt"))).unwrap();
    let (whole, cut) = (stdout(0), stdout(1));
    assert!(whole.starts_with("resumed=false"), "{whole}");
    assert_eq!(cut.replace("resumed=true", "resumed=false"), whole);
    assert!(cut.starts_with("resumed=true"), "{cut}");
    assert!(std::fs::read_to_string(d.join("out/1/stderr.txt"))
        .unwrap()
        .contains("going on from the checkpoint run.checkpoint.json at t = "));
    assert_eq!(
        std::fs::read(d.join("out/0/rows.csv")).unwrap(),
        std::fs::read(d.join("out/1/rows.csv")).unwrap()
    );
}
