//! `swimlab sweep`: one experiment script over every point of a parameter grid, each point a
//! `swimlab run SCRIPT --set NAME=VALUE ...` process in a folder of its own, locally on N
//! processes or as a SLURM job array. Both run a point the same way (its folder is the working
//! directory, its output in `stdout.txt` and `stderr.txt`, its outcome in `status.txt`), so a
//! cluster's results equal a laptop's. `index.csv` lists every point: index, parameters, status,
//! wall time.

use crate::script::console;
use crate::script::shell_quote;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// One swept parameter: a name and its values, as given to `--grid NAME=v1,v2,...`.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// The script's constant (read with `param(NAME, default)` or as a plain name).
    pub name: String,
    /// Its values, as text (each passed on as `--set NAME=value`).
    pub values: Vec<String>,
}

impl Axis {
    /// `NAME=v1,v2,...`, checked.
    pub fn parse(item: &str) -> Result<Self, String> {
        let (name, values) = item.split_once('=').ok_or_else(|| {
            format!("error: --grid {item}: expected NAME=v1,v2,..., such as --grid D=5,10,20\n")
        })?;
        crate::script::params::parse_set(&format!("{name}=0"))
            .map(|_| ())
            .map_err(|e| format!("{e}\n"))?;
        let values: Vec<String> = values.split(',').map(|v| v.trim().to_string()).collect();
        if values.iter().any(String::is_empty) {
            return Err(format!(
                "error: --grid {item}: an empty value; separate values by single commas, such as --grid D=5,10,20\n"
            ));
        }
        Ok(Axis {
            name: name.to_string(),
            values,
        })
    }
}

/// What to sweep and how.
#[derive(Debug, Clone)]
pub struct Sweep {
    /// The experiment script.
    pub script: PathBuf,
    /// The grid's axes, in the order given (the last varies fastest).
    pub axes: Vec<Axis>,
    /// The output folder: one sub-folder per point, `index.csv`, `sweep.sbatch`.
    pub out: PathBuf,
    /// Processes at once (local sweeps).
    pub jobs: usize,
    /// Skip points whose `status.txt` says ok.
    pub resume: bool,
    /// Pass `--quick` to every point.
    pub quick: bool,
}

/// Most points one sweep may have.
pub const MAX_POINTS: usize = 1_000_000;

impl Sweep {
    /// Every point: the (name, value) pairs of grid point k, k = 0 … n−1, last axis fastest.
    pub fn points(&self) -> Vec<Vec<(String, String)>> {
        let mut points = vec![Vec::new()];
        for axis in &self.axes {
            points = points
                .into_iter()
                .flat_map(|p| {
                    axis.values.iter().map(move |v| {
                        let mut q = p.clone();
                        q.push((axis.name.clone(), v.clone()));
                        q
                    })
                })
                .collect();
        }
        points
    }

    /// Check the grid and make the paths absolute (points run in their own folders).
    fn prepare(&mut self) -> Result<usize, String> {
        if self.axes.is_empty() {
            return Err("error: swimlab sweep needs at least one --grid NAME=v1,v2,...\n".into());
        }
        for (i, a) in self.axes.iter().enumerate() {
            if self.axes[..i].iter().any(|b| b.name == a.name) {
                return Err(format!(
                    "error: --grid {} is given twice; give each parameter once with all its values\n",
                    a.name
                ));
            }
        }
        let n = self
            .axes
            .iter()
            .try_fold(1usize, |n, a| n.checked_mul(a.values.len()))
            .filter(|n| *n <= MAX_POINTS)
            .ok_or_else(|| {
                format!("error: the grid has more than {MAX_POINTS} points; sweep fewer values\n")
            })?;
        self.script = std::fs::canonicalize(&self.script).map_err(|e| {
            format!(
                "error: cannot read the script {}: {e}; check the path\n",
                self.script.display()
            )
        })?;
        std::fs::create_dir_all(&self.out).map_err(|e| {
            format!(
                "error: cannot create the output folder {}: {e}; choose a folder you can write to\n",
                self.out.display()
            )
        })?;
        self.out = std::fs::canonicalize(&self.out).map_err(|e| format!("error: {e}\n"))?;
        if self.jobs == 0 {
            return Err("error: --jobs must be at least 1\n".into());
        }
        Ok(n)
    }

    /// The folder of point `k`.
    pub fn folder(&self, k: usize) -> PathBuf {
        self.out.join(k.to_string())
    }

    /// Run every point (those not finished, with `resume`) on `jobs` processes; index.csv is
    /// rewritten as points finish. Returns the summary, or an error if any point failed.
    pub fn run_local(mut self) -> Result<(), String> {
        let n = self.prepare()?;
        let points = self.points();
        let todo: Vec<usize> = (0..n)
            .filter(|&k| !(self.resume && status_of(&self.folder(k)).is_some_and(|s| s.ok)))
            .collect();
        console::emit_line(&format!(
            "swimlab sweep: {n} points ({} to run{}) of {} on {} processes, into {}",
            todo.len(),
            if self.resume {
                ", the rest finished"
            } else {
                ""
            },
            self.script.display(),
            self.jobs.min(todo.len().max(1)),
            self.out.display()
        ))?;
        let next = AtomicUsize::new(0);
        let index_lock = Mutex::new(());
        std::thread::scope(|scope| {
            for _ in 0..self.jobs.min(todo.len()) {
                scope.spawn(|| loop {
                    let i = next.fetch_add(1, Ordering::SeqCst);
                    let Some(&k) = todo.get(i) else { break };
                    if crate::script::interrupt::requested() {
                        break;
                    }
                    let outcome = self.run_point(k, &points[k]);
                    let _guard = index_lock.lock().unwrap_or_else(|e| e.into_inner());
                    console::to_stdout(&format!(
                        "  point {k} ({}): {}\n",
                        describe(&points[k]),
                        outcome.text()
                    ));
                    if let Err(e) = self.write_index(&points) {
                        console::to_stderr(&e);
                    }
                });
            }
        });
        self.write_index(&points)?;
        self.summary(&points)
    }

    /// Run point `k` only (a SLURM array task), exactly as the local sweep runs it.
    pub fn run_task(mut self, k: usize) -> Result<(), String> {
        let n = self.prepare()?;
        if k >= n {
            return Err(format!(
                "error: task {k} is not a point of this grid (0 to {}); check --array in the job script\n",
                n - 1
            ));
        }
        let points = self.points();
        let outcome = self.run_point(k, &points[k]);
        console::emit_line(&format!(
            "point {k} ({}): {}",
            describe(&points[k]),
            outcome.text()
        ))?;
        self.write_index(&points)?;
        if outcome.ok {
            Ok(())
        } else {
            Err(format!(
                "error: point {k} {}; see {}\n",
                outcome.text(),
                self.folder(k).join("stderr.txt").display()
            ))
        }
    }

    /// Write `out/sweep.sbatch`: a SLURM job array whose task k runs point k as
    /// [`Sweep::run_task`] does (same folder, same files).
    pub fn write_slurm(mut self) -> Result<(), String> {
        let n = self.prepare()?;
        let exe = std::env::current_exe().map_err(|e| format!("error: {e}\n"))?;
        let mut args = vec![
            shell_quote(&exe.to_string_lossy()),
            "sweep".into(),
            shell_quote(&self.script.to_string_lossy()),
        ];
        for a in &self.axes {
            args.push("--grid".into());
            args.push(shell_quote(&format!("{}={}", a.name, a.values.join(","))));
        }
        args.push("--out".into());
        args.push(shell_quote(&self.out.to_string_lossy()));
        if self.quick {
            args.push("--quick".into());
        }
        let path = self.out.join("sweep.sbatch");
        let text = format!(
            "#!/bin/bash\n\
             #SBATCH --job-name=swimlab-sweep\n\
             #SBATCH --array=0-{last}\n\
             #SBATCH --ntasks=1\n\
             #SBATCH --cpus-per-task=1\n\
             #SBATCH --output={out}/slurm-%A_%a.out\n\
             # Written by swimlab sweep: task k runs grid point k exactly as the local sweep does\n\
             # (its folder {out}/k/, stdout.txt, stderr.txt, status.txt; index.csv updated).\n\
             # Submit with: sbatch {path}\n\
             set -euo pipefail\n\
             exec {cmd} --task \"${{SLURM_ARRAY_TASK_ID:?run this script with sbatch, or set SLURM_ARRAY_TASK_ID}}\"\n",
            last = n - 1,
            out = self.out.display(),
            path = path.display(),
            cmd = args.join(" "),
        );
        crate::engine::files::write_atomically(&path, |w| w.write_all(text.as_bytes()))
            .map_err(|e| format!("error: {e}\n"))?;
        // Make it executable for `sbatch` and for running it by hand.
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let _ = std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755));
        }
        self.resume = false;
        self.write_index(&self.points())?;
        console::emit_line(&format!(
            "wrote {} ({n} tasks, --array=0-{}); submit it with: sbatch {}",
            path.display(),
            n - 1,
            path.display()
        ))?;
        Ok(())
    }

    /// Run one point in its folder and record its outcome there.
    fn run_point(&self, k: usize, point: &[(String, String)]) -> Outcome {
        let dir = self.folder(k);
        let start = Instant::now();
        let result = (|| -> std::io::Result<Option<i32>> {
            std::fs::create_dir_all(&dir)?;
            let _ = std::fs::remove_file(dir.join("status.txt"));
            let exe = std::env::current_exe()?;
            let mut cmd = Command::new(exe);
            cmd.arg("run").arg(&self.script).current_dir(&dir);
            for (name, value) in point {
                cmd.arg("--set").arg(format!("{name}={value}"));
            }
            if self.quick {
                cmd.arg("--quick");
            }
            let status = cmd
                .env("SWIMLAB_PROGRESS", "0")
                .stdin(Stdio::null())
                .stdout(std::fs::File::create(dir.join("stdout.txt"))?)
                .stderr(std::fs::File::create(dir.join("stderr.txt"))?)
                .status()?;
            Ok(status.code())
        })();
        let wall = start.elapsed().as_secs_f64();
        let outcome = match result {
            Ok(Some(0)) => Outcome {
                ok: true,
                status: "ok".into(),
                wall,
            },
            Ok(Some(code)) => Outcome {
                ok: false,
                status: format!("failed (exit {code})"),
                wall,
            },
            Ok(None) => Outcome {
                ok: false,
                status: "failed (killed by a signal)".into(),
                wall,
            },
            Err(e) => Outcome {
                ok: false,
                status: format!("failed ({e})"),
                wall,
            },
        };
        let _ = std::fs::write(
            dir.join("status.txt"),
            format!("{}\t{:.3}\n", outcome.status, outcome.wall),
        );
        outcome
    }

    /// `index.csv` from the points' status files (written whole, through a temporary file).
    /// Array tasks finishing together each rewrite it: they take turns through a lock file, so
    /// the last one to write has read every status written before it (each task writes its own
    /// status first).
    fn write_index(&self, points: &[Vec<(String, String)>]) -> Result<(), String> {
        let _turn = IndexTurn::take(&self.out.join(".index.lock"));
        let path = self.out.join("index.csv");
        crate::engine::files::write_atomically(&path, |w| {
            let mut csv = csv::Writer::from_writer(w);
            let mut header = vec!["index".to_string()];
            header.extend(self.axes.iter().map(|a| a.name.clone()));
            header.extend(["status".into(), "wall_s".into()]);
            csv.write_record(&header)?;
            for (k, p) in points.iter().enumerate() {
                let st = status_of(&self.folder(k));
                let mut row = vec![k.to_string()];
                row.extend(p.iter().map(|(_, v)| v.clone()));
                row.push(st.as_ref().map_or("pending".into(), |s| s.status.clone()));
                row.push(st.map_or(String::new(), |s| format!("{:.3}", s.wall)));
                csv.write_record(&row)?;
            }
            csv.flush()
        })
        .map_err(|e| format!("error: {e}\n"))
    }

    fn summary(&self, points: &[Vec<(String, String)>]) -> Result<(), String> {
        let failed: Vec<usize> = (0..points.len())
            .filter(|&k| !status_of(&self.folder(k)).is_some_and(|s| s.ok))
            .collect();
        console::emit_line(&format!(
            "{} of {} points ok; index: {}",
            points.len() - failed.len(),
            points.len(),
            self.out.join("index.csv").display()
        ))?;
        if failed.is_empty() {
            Ok(())
        } else {
            Err(format!(
                "error: {} point(s) did not finish ({}); each folder's stderr.txt says why; rerun with --resume to run only those\n",
                failed.len(),
                failed
                    .iter()
                    .take(10)
                    .map(|k| k.to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        }
    }
}

/// A turn at writing index.csv: the lock file exists while it is held (created exclusively,
/// removed on drop). A lock older than the wait (a task killed while writing) is taken over.
struct IndexTurn(PathBuf);

impl IndexTurn {
    fn take(lock: &Path) -> Self {
        let start = Instant::now();
        while std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(lock)
            .is_err()
            && start.elapsed() < std::time::Duration::from_secs(10)
        {
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
        IndexTurn(lock.to_path_buf())
    }
}

impl Drop for IndexTurn {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

/// How a point ended.
struct Outcome {
    ok: bool,
    status: String,
    wall: f64,
}

impl Outcome {
    fn text(&self) -> String {
        format!("{} in {:.2} s", self.status, self.wall)
    }
}

/// The outcome recorded in a point's folder, if it ran.
fn status_of(dir: &Path) -> Option<Outcome> {
    let text = std::fs::read_to_string(dir.join("status.txt")).ok()?;
    let (status, wall) = text.trim_end().split_once('\t')?;
    Some(Outcome {
        ok: status == "ok",
        status: status.to_string(),
        wall: wall.parse().unwrap_or(f64::NAN),
    })
}

fn describe(point: &[(String, String)]) -> String {
    point
        .iter()
        .map(|(n, v)| format!("{n}={v}"))
        .collect::<Vec<_>>()
        .join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_run_the_last_axis_fastest() {
        let s = Sweep {
            script: PathBuf::new(),
            axes: vec![
                Axis::parse("D=5,10").unwrap(),
                Axis::parse("name=a,b,c").unwrap(),
            ],
            out: PathBuf::new(),
            jobs: 1,
            resume: false,
            quick: false,
        };
        let p = s.points();
        assert_eq!(p.len(), 6);
        assert_eq!(
            p[1],
            vec![("D".into(), "5".into()), ("name".into(), "b".into())]
        );
        assert_eq!(p[3][0].1, "10");
        assert!(Axis::parse("D=").is_err());
        assert!(Axis::parse("1x=2").is_err());
        assert_eq!(shell_quote("a b'c"), r"'a b'\''c'");
        assert_eq!(shell_quote("/x/y.rhai"), "/x/y.rhai");
    }
}
