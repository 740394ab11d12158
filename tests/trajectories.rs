//! Trajectories for particle viewers: extended XYZ read back by ASE (a real outside reader, in
//! the Python environment `.ci/run` makes), the ParaView series read back by vtkio's parser, both
//! sharing the recorders' triggers, an XYZ stream and a ParaView series that keep every frame
//! through `kill -9`, and one writer per file.

use crate::common;
use crate::common::python_with;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use swimlab::engine::{Scene, Simulation, Trigger};

fn dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("swimlab-traj-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The sphere positions (µm), radii (µm) and swimmer indices of a scene, sphere by sphere.
fn spheres_um(s: &Scene) -> Vec<([f64; 3], f64, usize)> {
    (0..s.count())
        .flat_map(|i| {
            let (a, b) = s.spheres(i);
            let d = s.swimmer(i).unwrap();
            [(a, d.a1), (b, d.a2)].map(|(x, r)| ([x.x * 1e6, x.y * 1e6, x.z * 1e6], r * 1e6, i))
        })
        .collect()
}

/// A 3D scene (three swimmers out of line) run for one period with a trajectory every half
/// period: three frames, at 0, T/2 and T. Returns the final scene and the frames' times.
fn run_with_trajectory(path: &Path) -> (Scene, Vec<f64>) {
    let mut s = common::mirror_inwards(10.0, true);
    s.add(
        swimlab::engine::Dumbbell::default(),
        nalgebra::Vector3::new(0.0, 40e-6, 10e-6),
        nalgebra::Vector3::new(0.3, 1.0, -0.5),
    )
    .unwrap();
    let mut sim = Simulation::new(s);
    let id = sim.trajectory(path, Trigger::EveryPeriods(0.5)).unwrap();
    sim.run_periods(1.0).unwrap();
    let times = sim
        .recorder(id)
        .unwrap()
        .rows
        .iter()
        .map(|r| r[0])
        .collect();
    (sim.into_scene(), times)
}

/// A Python with ASE (skipped without one, unless `SWIMLAB_REQUIRE_ASE=1`, as in CI).
fn python_with_ase() -> Option<PathBuf> {
    python_with(
        "ase.io",
        "SWIMLAB_REQUIRE_ASE",
        "python3 -m venv .venv && .venv/bin/pip install ase",
    )
}

#[test]
fn ase_reads_the_extended_xyz_back() {
    let Some(python) = python_with_ase() else {
        return;
    };
    let d = dir("ase");
    let path = d.join("pair.xyz");
    let (scene, times) = run_with_trajectory(&path);
    assert_eq!(times.len(), 3);
    let out = Command::new(python)
        .args([
            "-c",
            "import ase.io, json, sys\n\
             frames = ase.io.read(sys.argv[1], index=':')\n\
             print(json.dumps([{'pos': f.positions.tolist(), 'radius': f.arrays['radius'].tolist(), \
             'swimmer': f.arrays['swimmer'].tolist(), 'sphere': f.arrays['sphere'].tolist(), \
             'N': f.arrays['dipoles'].tolist(), 'symbols': f.get_chemical_symbols(), 'time': f.info['Time']} \
             for f in frames]))",
            path.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "ASE failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let frames: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let frames = frames.as_array().unwrap();
    assert_eq!(frames.len(), 3, "three frames");
    for (f, t) in frames.iter().zip(&times) {
        assert_eq!(f["time"].as_f64().unwrap(), *t);
        assert_eq!(f["pos"].as_array().unwrap().len(), 2 * scene.count());
    }
    // The last frame is the final state: positions and radii exactly (the shortest round-trip
    // text of each f64), swimmer indices and unit orientations.
    let last = &frames[2];
    for (k, (p, r, i)) in spheres_um(&scene).iter().enumerate() {
        let got: Vec<f64> = last["pos"][k]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert_eq!(got, p.to_vec(), "sphere {k}");
        assert_eq!(last["radius"][k].as_f64().unwrap(), *r);
        assert_eq!(last["swimmer"][k].as_u64().unwrap() as usize, *i);
        assert_eq!(last["sphere"][k].as_u64().unwrap() as usize, k % 2 + 1);
        // Z = 0 makes every sphere ASE's dummy atom X, whatever its species name.
        assert_eq!(last["symbols"][k], "X");
        let n = scene.dir(*i).unwrap();
        for c in 0..3 {
            assert!((last["N"][k][c].as_f64().unwrap() - n[c]).abs() < 1e-9);
        }
    }
}

#[test]
fn the_paraview_series_reads_back() {
    let d = dir("pvd");
    let path = d.join("pair.pvd");
    let (scene, times) = run_with_trajectory(&path);
    let pvd = std::fs::read_to_string(&path).unwrap();
    let files: Vec<&str> = pvd
        .lines()
        .filter_map(|l| l.split("file=\"").nth(1))
        .map(|rest| rest.split('"').next().unwrap())
        .collect();
    assert_eq!(files.len(), 3);
    for t in &times {
        assert!(pvd.contains(&format!("timestep=\"{t:?}\"")), "{pvd}");
    }
    let last = vtkio::Vtk::import(d.join(files[2])).expect("vtkio parses the frame");
    let vtkio::model::DataSet::PolyData { pieces, .. } = last.data else {
        panic!("a PolyData frame");
    };
    let vtkio::model::Piece::Inline(piece) = &pieces[0] else {
        panic!("an inline piece");
    };
    let points: Vec<f64> = piece.points.cast_into().unwrap();
    let want = spheres_um(&scene);
    assert_eq!(points.len(), 3 * want.len());
    for (k, (p, ..)) in want.iter().enumerate() {
        assert_eq!(&points[3 * k..3 * k + 3], p, "point {k}");
    }
    let names: Vec<&str> = piece.data.point.iter().map(|a| a.name()).collect();
    assert_eq!(names, ["radius", "swimmer", "sphere", "N"]);
    let vtkio::model::Attribute::DataArray(radius) = &piece.data.point[0] else {
        panic!("radius is an array");
    };
    let radii: Vec<f64> = radius.data.clone().cast_into().unwrap();
    assert_eq!(radii, want.iter().map(|w| w.1).collect::<Vec<_>>());
}

#[test]
fn a_bad_trajectory_name_is_refused() {
    let mut sim = Simulation::new(common::mirror_inwards(10.0, true));
    let e = sim
        .trajectory(Path::new("out/t.dcd"), Trigger::EveryPeriods(1.0))
        .unwrap_err()
        .to_string();
    assert!(e.contains("must end in .xyz") && e.contains(".pvd"), "{e}");
}

/// The columns a frame's comment line declares: the sum of the counts in `Properties=name:type:count:...`.
fn columns_declared(comment: &str) -> Option<usize> {
    let spec = comment.split("Properties=").nth(1)?.split(' ').next()?;
    let fields: Vec<&str> = spec.split(':').collect();
    fields.len().is_multiple_of(3).then(|| {
        fields
            .chunks(3)
            .filter_map(|f| f[2].parse::<usize>().ok())
            .sum()
    })
}

/// Frames in an XYZ file, and whether it ends exactly after a whole frame.
fn whole_frames(text: &str) -> (usize, bool) {
    let lines: Vec<&str> = text.lines().collect();
    let (mut i, mut frames) = (0, 0);
    while i < lines.len() {
        let Ok(n) = lines[i].trim().parse::<usize>() else {
            return (frames, false);
        };
        if i + 2 + n > lines.len() {
            return (frames, false);
        }
        let columns = columns_declared(lines[i + 1])
            .unwrap_or_else(|| panic!("no Properties= on the comment line of frame {frames}"));
        assert!(lines[i + 2..i + 2 + n]
            .iter()
            .all(|l| l.split(' ').count() == columns));
        i += 2 + n;
        frames += 1;
    }
    (frames, text.ends_with('\n'))
}

/// `kill -9` during a run leaves every frame already due whole: the file ends after a frame.
#[test]
fn kill_9_keeps_every_frame_already_written() {
    let d = dir("kill9");
    let xyz = d.join("long.xyz");
    let script = d.join("long.rhai");
    std::fs::write(
        &script,
        format!(
            "import \"paper\" as paper;\nlet s = paper::mirror(10.0, true, true);\ns.trajectory(\"{}\", every_periods(0.05));\ns.run_periods(100000);\n",
            xyz.display()
        ),
    )
    .unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_swimlab"))
        .args(["run", script.to_str().unwrap()])
        .env("SWIMLAB_PROGRESS", "0")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let seen = loop {
        let (frames, _) = whole_frames(&std::fs::read_to_string(&xyz).unwrap_or_default());
        if frames >= 5 {
            break frames;
        }
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "no frames written"
        );
        std::thread::sleep(Duration::from_millis(20));
    };
    assert!(Command::new("kill")
        .args(["-9", &child.id().to_string()])
        .status()
        .unwrap()
        .success());
    let _ = child.wait();
    let (frames, whole) = whole_frames(&std::fs::read_to_string(&xyz).unwrap());
    assert!(whole, "the file ends inside a frame");
    assert!(
        frames >= seen,
        "{frames} frames after the kill, {seen} seen before"
    );
}

/// In a periodic box the frames carry the box as their cell (pbc true, origin at −L/2) and the
/// swimmers moved with their R_H into the box; ASE reads both.
#[test]
fn ase_reads_a_periodic_box() {
    let Some(python) = python_with_ase() else {
        return;
    };
    let d = dir("ase-box");
    let path = d.join("box.xyz");
    let mut s = Scene::new();
    s.set_model(swimlab::engine::Model::Averaged);
    let l = 100e-6;
    s.set_box(Some([l, 1.2 * l, 0.8 * l])).unwrap();
    let dd = swimlab::engine::Dumbbell::default();
    // Centres outside the box: shown at their images inside.
    s.add(
        dd,
        nalgebra::Vector3::new(0.9 * l, 0.0, 0.0),
        nalgebra::Vector3::x(),
    )
    .unwrap();
    s.add(
        dd,
        nalgebra::Vector3::new(0.0, -0.7 * l, 0.1 * l),
        nalgebra::Vector3::y(),
    )
    .unwrap();
    let mut sim = Simulation::new(s);
    sim.trajectory(&path, Trigger::EveryPeriods(1.0)).unwrap();
    sim.run_periods(1.0).unwrap();
    let out = Command::new(python)
        .args([
            "-c",
            "import ase.io, json, sys\n\
             f = ase.io.read(sys.argv[1], index=-1)\n\
             print(json.dumps({'cell': f.cell.lengths().tolist(), 'pbc': f.pbc.tolist(), 'pos': f.positions.tolist()}))",
            path.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "ASE failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let cell: Vec<f64> = v["cell"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(cell, vec![100.0, 120.0, 80.0]);
    assert_eq!(v["pbc"], serde_json::json!([true, true, true]));
    let scene = sim.into_scene();
    for i in 0..2 {
        let c = scene.shown(scene.center(i).unwrap()) * 1e6;
        let (x1, x2) = (&v["pos"][2 * i], &v["pos"][2 * i + 1]);
        for k in 0..3 {
            let mid = (x1[k].as_f64().unwrap() * dd.a1 + x2[k].as_f64().unwrap() * dd.a2)
                / (dd.a1 + dd.a2);
            assert!(
                (mid - c[k]).abs() < 1e-9,
                "swimmer {i}: R_H {mid} shown at {}",
                c[k]
            );
            assert!(
                c[k].abs() <= 0.5 * cell[k],
                "swimmer {i} shown outside the box"
            );
        }
    }
}

/// The `.pvd` is appended in place, frame by frame (the same file from the first frame to the
/// last, never rewritten whole: each frame costs the same however many came before), and lists
/// every frame with its time.
#[test]
fn the_paraview_collection_is_appended_in_place() {
    use std::os::unix::fs::MetadataExt;
    let d = dir("pvd-append");
    let path = d.join("pair.pvd");
    let mut sim = Simulation::new(common::mirror_inwards(10.0, true));
    sim.trajectory(&path, Trigger::EveryPeriods(0.01)).unwrap();
    let inode = std::fs::metadata(&path).unwrap().ino();
    sim.run_periods(0.5).unwrap();
    assert_eq!(
        std::fs::metadata(&path).unwrap().ino(),
        inode,
        "rewritten whole"
    );
    let pvd = std::fs::read_to_string(&path).unwrap();
    assert_eq!(pvd.matches("<DataSet ").count(), 51, "{pvd}");
    assert!(pvd.ends_with("  </Collection>\n</VTKFile>\n"), "{pvd}");
    let listed: Vec<&str> = pvd
        .lines()
        .filter_map(|l| l.split("file=\"").nth(1))
        .map(|rest| rest.split('"').next().unwrap())
        .collect();
    for f in &listed {
        assert!(d.join(f).is_file(), "{f}");
    }
    let names: Vec<String> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().all(|n| !n.contains("tmp")), "{names:?}");
}

/// `kill -9` during a run with a ParaView series leaves a `.pvd` that ends in its closing lines and
/// lists only whole frames, and no temporary file but, at most, the one of the frame being
/// written, inside the frames folder.
#[test]
fn kill_9_leaves_a_whole_paraview_series() {
    let d = dir("kill9-pvd");
    let pvd = d.join("long.pvd");
    let script = d.join("long.rhai");
    std::fs::write(
        &script,
        format!(
            "import \"paper\" as paper;\nlet s = paper::mirror(10.0, true, true);\ns.trajectory(\"{}\", every_periods(0.01));\ns.run_periods(10000);\n",
            pvd.display()
        ),
    )
    .unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_swimlab"))
        .args(["run", script.to_str().unwrap()])
        .env("SWIMLAB_PROGRESS", "0")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while std::fs::read_to_string(&pvd)
        .unwrap_or_default()
        .matches("<DataSet ")
        .count()
        < 20
    {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "no frames written"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(Command::new("kill")
        .args(["-9", &child.id().to_string()])
        .status()
        .unwrap()
        .success());
    let _ = child.wait();
    let text = std::fs::read_to_string(&pvd).unwrap();
    assert!(text.ends_with("  </Collection>\n</VTKFile>\n"), "{text}");
    for f in text
        .lines()
        .filter_map(|l| l.split("file=\"").nth(1))
        .map(|rest| rest.split('"').next().unwrap())
    {
        vtkio::Vtk::import(d.join(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
    }
    let outside: Vec<String> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("tmp"))
        .collect();
    assert!(outside.is_empty(), "{outside:?}");
    let inside = std::fs::read_dir(d.join("long_frames"))
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .ends_with(".tmp")
        })
        .count();
    assert!(inside <= 1, "{inside} temporary files");
}

/// One writer per file: a second trajectory, or a whole-file write, on a path a trajectory of
/// this process is writing is refused, and the first keeps whole frames. CSV cannot reach it: a
/// CSV stream or file under a trajectory's name is refused for the name first.
#[test]
fn a_second_writer_on_a_trajectory_is_refused() {
    let d = dir("claim");
    let path = d.join("t.xyz");
    let mut sim = Simulation::new(common::mirror_inwards(10.0, true));
    sim.trajectory(&path, Trigger::EveryPeriods(0.5)).unwrap();
    let mut other = Simulation::new(common::mirror_inwards(10.0, true));
    // Another spelling of the same file.
    let same = d.join(".").join("t.xyz");
    let e = other
        .trajectory(&same, Trigger::EveryPeriods(0.5))
        .unwrap_err()
        .to_string();
    assert!(e.contains("is being written by a trajectory"), "{e}");
    let id = other
        .record(Vec::new(), Trigger::EveryPeriods(1.0))
        .unwrap();
    let e = other.stream_csv(id, &path).unwrap_err();
    assert!(e.to_string().contains("ends in .xyz"), "{e}");
    let e = other.recorder(id).unwrap().write_csv(&path).unwrap_err();
    assert!(e.to_string().contains("ends in .xyz"), "{e}");
    let e = swimlab::engine::files::write_atomically(&same, |w| w.write_all(b"x\n")).unwrap_err();
    assert!(
        e.to_string().contains("is being written by a trajectory"),
        "{e}"
    );
    sim.run_periods(1.0).unwrap();
    let (frames, whole) = whole_frames(&std::fs::read_to_string(&path).unwrap());
    assert_eq!((frames, whole), (3, true));
    drop(sim);
    other.trajectory(&path, Trigger::EveryPeriods(0.5)).unwrap();
}
