//! The files opened as a researcher opens them: a box's trajectory and density field read by
//! OVITO's Python module and by VTK's XML readers (real outside readers, in the Python environment
//! `.ci/run` makes; skipped without one unless `SWIMLAB_REQUIRE_VIEWERS=1`, as in CI), and one
//! frame rendered headless with OVITO's Tachyon renderer.

use crate::common::python_with;

use std::path::{Path, PathBuf};
use std::process::Command;
use swimlab::engine::build::{random_suspension, Orientations, Phases};
use swimlab::engine::fields::{Field, FieldKind, FieldSpec};
use swimlab::engine::{Dumbbell, Model, Scene, Simulation, Trigger};

/// The box's side (m) and its swimmers: dense enough that a rendered frame is mostly spheres.
const SIDE: f64 = 60e-6;
const SWIMMERS: usize = 100;

fn dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("swimlab-viewers-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A stroke-averaged box of swimmers run for one period with a trajectory at its start and end.
fn box_with_trajectory(path: &Path) -> Scene {
    let mut s = Scene::new();
    s.set_model(Model::Averaged);
    s.set_box(Some([SIDE; 3])).unwrap();
    random_suspension(
        &mut s,
        SWIMMERS,
        Dumbbell::default(),
        [SIDE; 3],
        Orientations::Random,
        Phases::Random,
        7,
    )
    .unwrap();
    let mut sim = Simulation::new(s);
    sim.trajectory(path, Trigger::EveryPeriods(1.0)).unwrap();
    sim.run_periods(1.0).unwrap();
    sim.into_scene()
}

/// A Python with OVITO and VTK.
fn python_with_viewers() -> Option<PathBuf> {
    python_with(
        "ovito, vtk",
        "SWIMLAB_REQUIRE_VIEWERS",
        "python3 -m venv .venv && .venv/bin/pip install ovito vtk",
    )
}

/// Runs `code` with `args`; returns its standard output parsed as JSON.
fn python_json(python: &Path, code: &str, args: &[&Path]) -> serde_json::Value {
    let out = Command::new(python)
        .arg("-c")
        .arg(code)
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "python failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("not JSON ({e}): {}", String::from_utf8_lossy(&out.stdout)))
}

fn floats(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// OVITO reads the extended XYZ as two particle types, a1 and a2, in two colours that are not
/// the white of the background; N as its "Dipole Orientation" (with the arrows' visual element);
/// the box as the simulation cell. A frame rendered headless with Tachyon, arrows on, shows both
/// colours (the picture is left in the test's folder to look at).
#[test]
fn ovito_draws_the_two_sphere_kinds_apart_with_arrows_along_n() {
    let Some(python) = python_with_viewers() else {
        return;
    };
    let d = dir("ovito");
    let xyz = d.join("box.xyz");
    let png = d.join("frame.png");
    let scene = box_with_trajectory(&xyz);
    let got = python_json(
        &python,
        r#"
import json, sys
from ovito.io import import_file
from ovito.vis import Viewport, TachyonRenderer
p = import_file(sys.argv[1], multiple_frames=True)
frames = p.source.num_frames
data = p.compute(frames - 1)
ptypes = data.particles.particle_types
dip = data.particles['Dipole Orientation']
out = {
    'frames': frames,
    'types': [{'id': t.id, 'name': t.name, 'color': [float(c) for c in t.color]} for t in ptypes.types],
    'type_of': ptypes[...].tolist(),
    'radius': data.particles['Radius'][...].tolist(),
    'dipoles': dip[...].tolist(),
    'arrows': dip.vis is not None,
    'cell': data.cell[...].tolist(),
    'pbc': list(data.cell.pbc),
}
dip.vis.enabled = True
p.add_to_scene()
vp = Viewport(type=Viewport.Type.Perspective, camera_dir=(-1, -1, -1))
vp.zoom_all()
img = vp.render_image(size=(320, 240), filename=sys.argv[2], background=(1, 1, 1),
                      renderer=TachyonRenderer(), frame=frames - 1)
near = {t['name']: 0 for t in out['types']}
for y in range(img.height()):
    for x in range(img.width()):
        q = img.pixelColor(x, y)
        for t in out['types']:
            # A sphere's lit surface: within 0.15 of its type's colour in every channel.
            if all(abs(c / 255 - t['color'][k]) < 0.15 for k, c in enumerate((q.red(), q.green(), q.blue()))):
                near[t['name']] += 1
out['pixels'] = near
print(json.dumps(out))
"#,
        &[&xyz, &png],
    );
    assert_eq!(got["frames"], 2, "two frames, at 0 and T");
    let types = got["types"].as_array().unwrap();
    let names: Vec<&str> = types.iter().map(|t| t["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["a1", "a2"]);
    let colors: Vec<Vec<f64>> = types.iter().map(|t| floats(&t["color"])).collect();
    for (name, c) in names.iter().zip(&colors) {
        // White on white is the failure this guards: some channel well below 1.
        assert!(
            c.iter().cloned().fold(1.0, f64::min) < 0.7,
            "{name} drawn {c:?}"
        );
    }
    let apart = (0..3)
        .map(|k| (colors[0][k] - colors[1][k]).abs())
        .fold(0.0, f64::max);
    assert!(
        apart > 0.3,
        "a1 {:?} and a2 {:?} look alike",
        colors[0],
        colors[1]
    );
    let id_of = |name: &str| types.iter().find(|t| t["name"] == name).unwrap()["id"].clone();
    let type_of = got["type_of"].as_array().unwrap();
    let radius = floats(&got["radius"]);
    let dipoles = got["dipoles"].as_array().unwrap();
    assert_eq!(type_of.len(), 2 * SWIMMERS);
    let d0 = Dumbbell::default();
    for i in 0..SWIMMERS {
        let n = scene.dir(i).unwrap();
        for (k, (name, a)) in [("a1", d0.a1), ("a2", d0.a2)].into_iter().enumerate() {
            let p = 2 * i + k;
            assert_eq!(type_of[p], id_of(name), "sphere {p}");
            assert_eq!(radius[p], a * 1e6, "sphere {p}");
            let got = floats(&dipoles[p]);
            for c in 0..3 {
                // The written N is the unit vector between the shown spheres; the scene's N is
                // the averaged model's own: the same to rounding.
                assert!((got[c] - n[c]).abs() < 1e-9, "sphere {p}: {got:?} vs {n:?}");
            }
        }
    }
    assert_eq!(
        got["arrows"], true,
        "Dipole Orientation has OVITO's arrow element"
    );
    let cell = got["cell"].as_array().unwrap();
    let l = SIDE * 1e6;
    for (r, row) in cell.iter().take(3).enumerate() {
        let row = floats(row);
        for (c, &v) in row.iter().take(3).enumerate() {
            assert_eq!(v, if r == c { l } else { 0.0 }, "cell {r},{c}");
        }
        assert_eq!(row[3], -0.5 * l, "cell origin {r}");
    }
    assert_eq!(got["pbc"], serde_json::json!([true, true, true]));
    for name in ["a1", "a2"] {
        let seen = got["pixels"][name].as_u64().unwrap();
        assert!(
            seen > 100,
            "{name}: {seen} pixels of its colour in the frame"
        );
    }
    assert!(png.exists(), "the rendered frame");
}

/// VTK's XML readers: the density field's image spans the box face to face, one density per cell
/// (cell data named plainly), adding up to the swimmers; the units are field data. The frame's
/// N is the active vectors (what ParaView's Glyph filter orients arrows by) and its spheres lie
/// in the field's bounds, so the two overlay.
#[test]
fn vtk_reads_the_field_on_the_box_and_the_frames_with_n_as_vectors() {
    let Some(python) = python_with_viewers() else {
        return;
    };
    let d = dir("vtk");
    let pvd = d.join("box.pvd");
    let scene = box_with_trajectory(&pvd);
    let vti = d.join("density.vti");
    let field = Field::of(
        &scene,
        FieldKind::Density,
        &FieldSpec {
            grid: [8, 6, 5],
            width: None,
        },
    )
    .unwrap();
    std::fs::write(&vti, field.to_vti().unwrap()).unwrap();
    let frame = d.join("box_frames").join(
        std::fs::read_dir(d.join("box_frames"))
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .filter(|n| n.to_string_lossy().ends_with(".vtp"))
            .max()
            .unwrap(),
    );
    let got = python_json(
        &python,
        r#"
import json, sys
import vtk
from vtk.util.numpy_support import vtk_to_numpy
def units(data):
    fd = data.GetFieldData()
    return {fd.GetAbstractArray(i).GetName(): fd.GetAbstractArray(i).GetValue(0)
            for i in range(fd.GetNumberOfArrays())}
r = vtk.vtkXMLImageDataReader(); r.SetFileName(sys.argv[1]); r.Update()
img = r.GetOutput()
cd = img.GetCellData()
rho = cd.GetArray('density')
dx, dy, dz = img.GetSpacing()
p = vtk.vtkXMLPolyDataReader(); p.SetFileName(sys.argv[2]); p.Update()
poly = p.GetOutput()
vec = poly.GetPointData().GetVectors()
print(json.dumps({
    'bounds': list(img.GetBounds()),
    'cells': img.GetNumberOfCells(),
    'cell_arrays': [cd.GetArrayName(i) for i in range(cd.GetNumberOfArrays())],
    'point_arrays': img.GetPointData().GetNumberOfArrays(),
    'count': float(vtk_to_numpy(rho).sum() * dx * dy * dz),
    'image_units': units(img),
    'vectors': vec.GetName() if vec else None,
    'N': vtk_to_numpy(vec).tolist() if vec else [],
    'frame_bounds': list(poly.GetBounds()),
    'frame_units': units(poly),
}))
"#,
        &[&vti, &frame],
    );
    let l = SIDE * 1e6;
    let bounds = floats(&got["bounds"]);
    for (k, b) in bounds.iter().enumerate() {
        // f32 origin and spacing in the file: the faces to f32's 7 digits of 30 µm.
        let face = if k % 2 == 0 { -0.5 * l } else { 0.5 * l };
        assert!(
            (b - face).abs() < 1e-4,
            "bound {k}: {b} µm, the box face at {face}"
        );
    }
    assert_eq!(got["cells"], 8 * 6 * 5);
    assert_eq!(got["cell_arrays"], serde_json::json!(["density"]));
    assert_eq!(got["point_arrays"], 0, "values are cell data");
    let count = got["count"].as_f64().unwrap();
    // Σ ρ ΔV = N exactly in f64; ΔV here is from f32 spacings (relative 1e-7 each).
    assert!(
        (count - SWIMMERS as f64).abs() < 1e-4 * SWIMMERS as f64,
        "Σ ρ ΔV = {count}"
    );
    assert_eq!(
        got["image_units"],
        serde_json::json!({"length_unit": "um", "density_unit": "1/um^3"})
    );
    assert_eq!(got["vectors"], "N", "N is the frame's active vectors");
    let n_written = got["N"].as_array().unwrap();
    assert_eq!(n_written.len(), 2 * SWIMMERS);
    for i in 0..SWIMMERS {
        let n = scene.dir(i).unwrap();
        let w = floats(&n_written[2 * i]);
        assert!((0..3).all(|c| (w[c] - n[c]).abs() < 1e-9), "swimmer {i}");
    }
    let fb = floats(&got["frame_bounds"]);
    // Spheres are drawn at their swimmer's wrapped centre ± ℓ/2 + a: they reach past a face by
    // at most that much.
    let d0 = Dumbbell::default();
    let reach = (d0.ell + d0.a1) * 1e6;
    for k in 0..6 {
        let (lo, hi) = (bounds[k & !1], bounds[k | 1]);
        assert!(
            fb[k] >= lo - reach && fb[k] <= hi + reach,
            "frame bound {k}: {} outside the field's {lo}..{hi}",
            fb[k]
        );
    }
    assert_eq!(got["frame_units"], serde_json::json!({"length_unit": "um"}));
}
