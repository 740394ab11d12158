//! Continuum fields in scripts: `s.field(kind[, #{ grid, width }])` (type `Field`: `.values`,
//! `.to_vtk(path)`, `.plot(...)`, `.stat(name)`), `s.structure_factor([#{ bins, k_max }])`, and
//! the recorder observable `field_stat(kind, stat[, opts])`.

use super::convert::{describe, lift, number, script_error, ScriptResult};
use super::doc::{doc_entry, Doc};
use super::picture_api::Picture;
use super::scene_api::SceneHandle;
use crate::engine::fields::{Field, FieldKind, FieldSpec, FieldStat};
use crate::engine::structure::structure_factor;
use crate::engine::Observable;
use crate::plot::HeatMap;
use rhai::{Array, Dynamic, Engine, Map, INT};

/// `#{ grid: [nx, ny, nz], width }` as a field spec (defaults for what is left out).
fn spec(opts: &Map) -> ScriptResult<FieldSpec> {
    const FIX: &str = "use #{ grid: [nx, ny, nz], width: metres }";
    let mut s = FieldSpec::default();
    for (k, v) in opts {
        match k.as_str() {
            "grid" => {
                let arr = v.clone().try_cast::<Array>().filter(|a| a.len() == 3);
                let Some(arr) = arr else {
                    return Err(script_error(format!(
                        "field grid must be three cell counts such as [32, 32, 32], got {}",
                        describe(v)
                    )));
                };
                for (d, x) in arr.iter().enumerate() {
                    let n = x.as_int().map_err(|_| {
                        script_error(format!(
                            "field grid[{d}] must be a whole number, got {}",
                            describe(x)
                        ))
                    })?;
                    s.grid[d] = usize::try_from(n).unwrap_or(0);
                }
            }
            "width" => s.width = Some(number("field width", v)?),
            other => {
                return Err(script_error(format!(
                    "field: unknown option \"{other}\"; {FIX}"
                )))
            }
        }
    }
    lift(s.check()).map(|_| s)
}

fn kind(name: &str) -> ScriptResult<FieldKind> {
    lift(FieldKind::parse(name))
}

fn field_of(s: &SceneHandle, name: &str, opts: &Map) -> ScriptResult<Field> {
    let (k, sp) = (kind(name)?, spec(opts)?);
    s.with(|sc| Field::of(sc, k, &sp))
}

/// The slice picture of `f` for `opts` (axis: "x" | "y" | "z", default "z"; index, default the
/// middle; title).
fn heat_map(f: &Field, opts: &Map) -> ScriptResult<HeatMap> {
    let mut axis = 2;
    let mut index = None;
    let mut title = String::new();
    for (k, v) in opts {
        match k.as_str() {
            "axis" => {
                let name = v.clone().into_immutable_string().map_err(|_| {
                    script_error(format!(
                        "plot axis must be \"x\", \"y\" or \"z\", got {}",
                        describe(v)
                    ))
                })?;
                axis = match name.as_str() {
                    "x" => 0,
                    "y" => 1,
                    "z" => 2,
                    other => {
                        return Err(super::convert::unknown_choice(
                            "axis",
                            other,
                            &["x", "y", "z"],
                        ))
                    }
                }
            }
            "index" => {
                let i = v.as_int().map_err(|_| {
                    script_error(format!(
                        "plot index must be a whole number, got {}",
                        describe(v)
                    ))
                })?;
                index = Some(usize::try_from(i).map_err(|_| {
                    script_error(format!("plot index {i} is negative; cells start at 0"))
                })?);
            }
            "title" => title = v.to_string(),
            other => {
                return Err(script_error(format!(
                    "field plot: unknown option \"{other}\"; use axis, index and title"
                )))
            }
        }
    }
    let index = index.unwrap_or(f.grid[axis] / 2);
    let slice = lift(f.slice(axis, index))?;
    const NAMES: [&str; 3] = ["x [µm]", "y [µm]", "z [µm]"];
    let value_desc = match f.kind {
        FieldKind::Density => "density [1/µm³]",
        FieldKind::Polarization => "|Π|",
        FieldKind::Nematic => "S (largest eigenvalue of Q)",
    };
    let scale = if f.kind == FieldKind::Density {
        1e-18
    } else {
        1.0
    };
    Ok(HeatMap {
        title,
        x_desc: NAMES[slice.axes.0].into(),
        y_desc: NAMES[slice.axes.1].into(),
        value_desc: value_desc.into(),
        cols: slice.cols,
        rows: slice.rows,
        values: slice.values.iter().map(|v| v * scale).collect(),
        x: (slice.x.0 * 1e6, slice.x.1 * 1e6),
        y: (slice.y.0 * 1e6, slice.y.1 * 1e6),
        size: (760, 600),
    })
}

fn picture(f: &Field, opts: &Map) -> ScriptResult<Picture> {
    let image = heat_map(f, opts)?.image().map_err(script_error)?;
    Ok(Picture::new(image, "field slice"))
}

/// The cell values as script values: floats (density), [x, y, z] (polarization), 3×3 rows (Q).
fn values(f: &Field) -> Array {
    let c = f.kind.components();
    let float = |x: f64| Dynamic::from_float(x);
    (0..f.cells())
        .map(|i| {
            let v = &f.values[c * i..c * (i + 1)];
            match f.kind {
                FieldKind::Density => float(v[0]),
                FieldKind::Polarization => {
                    Dynamic::from_array(v.iter().map(|x| float(*x)).collect())
                }
                FieldKind::Nematic => Dynamic::from_array(
                    v.chunks(3)
                        .map(|row| Dynamic::from_array(row.iter().map(|x| float(*x)).collect()))
                        .collect(),
                ),
            }
        })
        .collect()
}

fn floats(v: &[f64]) -> Dynamic {
    Dynamic::from_array(v.iter().map(|x| Dynamic::from_float(*x)).collect())
}

fn structure(s: &SceneHandle, opts: &Map) -> ScriptResult<Map> {
    let (mut bins, mut k_max) = (32usize, None);
    for (k, v) in opts {
        match k.as_str() {
            "bins" => {
                let b = v.as_int().map_err(|_| {
                    script_error(format!(
                        "structure_factor bins must be a whole number, got {}",
                        describe(v)
                    ))
                })?;
                bins = usize::try_from(b).unwrap_or(0);
            }
            "k_max" => k_max = Some(number("structure_factor k_max", v)?),
            other => {
                return Err(script_error(format!(
                    "structure_factor: unknown option \"{other}\"; use #{{ bins: 32, k_max: 1/m }}"
                )))
            }
        }
    }
    let sf = s.with(|sc| structure_factor(sc, bins, k_max))?;
    let mut m = Map::new();
    m.insert("k".into(), floats(&sf.k));
    m.insert("S".into(), floats(&sf.s));
    let counts: Vec<f64> = sf.count.iter().map(|&c| c as f64).collect();
    m.insert("count".into(), floats(&counts));
    Ok(m)
}

fn field_stat(name: &str, stat: &str, opts: &Map) -> ScriptResult<Observable> {
    Ok(Observable::Field {
        kind: kind(name)?,
        stat: lift(FieldStat::parse(stat))?,
        spec: spec(opts)?,
    })
}

impl std::fmt::Display for Field {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Field({}, grid {:?}, cells {:.3e} x {:.3e} x {:.3e} m, width {:.3e} m{}, {})",
            self.kind.name(),
            self.grid,
            self.spacing[0],
            self.spacing[1],
            self.spacing[2],
            self.width,
            if self.periodic { ", periodic" } else { "" },
            // What the values add up to: the swimmers a density holds; the cells' mean |Π| or
            // largest Q eigenvalue otherwise.
            match self.kind {
                FieldKind::Density => format!("integral {:.4}", self.integral()),
                _ => format!("cell mean {:.4e}", self.stat(FieldStat::Mean)),
            }
        )
    }
}

/// Register `Field`, `s.field`, `s.structure_factor` and `field_stat`.
pub fn register(engine: &mut Engine) {
    engine
        .register_fn("field", |s: &mut SceneHandle, k: &str| field_of(s, k, &Map::new()))
        .register_fn("field", |s: &mut SceneHandle, k: &str, o: Map| field_of(s, k, &o))
        .register_get("values", |f: &mut Field| values(f))
        .register_get("kind", |f: &mut Field| f.kind.name().to_string())
        .register_get("grid", |f: &mut Field| -> Array {
            f.grid.iter().map(|&n| Dynamic::from_int(n as INT)).collect()
        })
        .register_get("origin", |f: &mut Field| floats(&f.origin))
        .register_get("spacing", |f: &mut Field| floats(&f.spacing))
        .register_get("width", |f: &mut Field| f.width)
        .register_fn("integral", |f: &mut Field| f.integral())
        .register_fn("stat", |f: &mut Field, name: &str| -> ScriptResult<f64> {
            Ok(f.stat(lift(FieldStat::parse(name))?))
        })
        .register_fn("to_vtk", |f: &mut Field, path: &str| -> ScriptResult<()> {
            let p = std::path::Path::new(path);
            if p.extension().and_then(|e| e.to_str()) != Some("vti") {
                return Err(script_error(format!(
                    "{path}: a field is written as VTK image data: give a path ending in .vti (ParaView opens it)"
                )));
            }
            let bytes = lift(f.to_vti())?;
            lift(crate::engine::files::write_atomically(p, |w| w.write_all(&bytes)))
        })
        .register_fn("plot", |f: &mut Field| picture(f, &Map::new()))
        .register_fn("plot", |f: &mut Field, o: Map| picture(f, &o))
        .register_fn("plot", |f: &mut Field, path: &str| {
            picture(f, &Map::new())?.save(path)
        })
        .register_fn("plot", |f: &mut Field, path: &str, o: Map| picture(f, &o)?.save(path))
        .register_fn("structure_factor", |s: &mut SceneHandle| structure(s, &Map::new()))
        .register_fn("structure_factor", |s: &mut SceneHandle, o: Map| structure(s, &o))
        .register_fn("field_stat", |k: &str, st: &str| field_stat(k, st, &Map::new()))
        .register_fn("field_stat", |k: &str, st: &str, o: Map| field_stat(k, st, &o));
}

/// The help text of this file's script names (`:help NAME`), gathered by [`super::docs`].
pub(super) const DOCS: &[Doc] = &[
    doc_entry!("field", "reading", "s.field(kind) -> Field\ns.field(kind, #{ grid: [nx, ny, nz], width })", "A continuum field of the swimmers' hydrodynamic centres on a grid: kind \"density\" (number density, 1/m^3), \"polarization\" (local mean orientation Pi, |Pi| = 1 where all are aligned) or \"nematic\" (local Q = <(3NN - I)/2>, 3x3). Each swimmer is smoothed by a Gaussian of the given width (m; default one cell; at least 1/32 of a cell, where its weights would underflow, and within the reach of positions) and counted exactly once on the grid. In a periodic box the grid tiles the box and the kernel is periodic; in open space it covers the centres padded by 4 widths. Default grid [32, 32, 32]; at most 2^20 cells.", "let s = scene(); s.box = [200e-6, 200e-6, 200e-6]; s.add_random(dumbbell(), 20, 1); let f = s.field(\"density\", #{ grid: [8, 8, 8] }); print(f.integral());"),
    doc_entry!("values", "reading", "f.values -> array", "The field's cell values, x fastest, then y, then z: floats (density, 1/m^3), [x, y, z] (polarization), or 3x3 rows (nematic).", "let s = scene(); s.add(dumbbell()); print(s.field(\"density\", #{ grid: [2, 2, 2] }).values.len());"),
    doc_entry!("kind", "reading", "f.kind -> string", "Which field: \"density\", \"polarization\" or \"nematic\".", "let s = scene(); s.add(dumbbell()); print(s.field(\"polarization\", #{ grid: [2, 2, 2] }).kind);"),
    doc_entry!("grid", "reading", "f.grid -> array", "Cells per axis [nx, ny, nz].", "let s = scene(); s.add(dumbbell()); print(s.field(\"density\", #{ grid: [4, 2, 2] }).grid);"),
    doc_entry!("origin", "reading", "f.origin -> array", "Centre of cell (0, 0, 0) (m).", "let s = scene(); s.add(dumbbell()); print(s.field(\"density\", #{ grid: [2, 2, 2] }).origin);"),
    doc_entry!("spacing", "reading", "f.spacing -> array", "Cell sides (m).", "let s = scene(); s.add(dumbbell()); print(s.field(\"density\", #{ grid: [2, 2, 2] }).spacing);"),
    doc_entry!("width", "reading", "f.width -> float", "The smoothing kernel's width (m).", "let s = scene(); s.add(dumbbell()); print(s.field(\"density\", #{ grid: [2, 2, 2] }).width);"),
    doc_entry!("integral", "reading", "f.integral() -> float", "Sum over the cells of the cell scalar times the cell volume: for a density field the number of swimmers.", "let s = scene(); s.add(dumbbell()); print(s.field(\"density\", #{ grid: [4, 4, 4] }).integral());"),
    doc_entry!("stat", "reading", "f.stat(\"mean\" | \"variance\" | \"max\" | \"min\") -> float", "A summary over the cells of the cell scalar: density (1/m^3), |Pi| (polarization), or S, the largest eigenvalue of Q (nematic).", "let s = scene(); s.add(dumbbell()); print(s.field(\"polarization\", #{ grid: [4, 4, 4] }).stat(\"max\"));"),
    doc_entry!("to_vtk", "files", "f.to_vtk(path)", "Write the field as VTK image data (.vti, XML; ParaView and VTK open it): lengths in µm like the trajectories, one value per cell as cell data on the cells' corners (in a box, the grid's bounds are the box's faces, so it overlays the trajectories), named \"density\" (1/um^3), \"polarization\" (vectors) or \"Q\" (tensors), the units as the file's field data (length_unit, density_unit). Whole or not at all.", "let s = scene(); s.add(dumbbell()); s.field(\"density\", #{ grid: [4, 4, 4] }).to_vtk(\"out/density.vti\");"),
    doc_entry!("structure_factor", "reading", "s.structure_factor() -> map\ns.structure_factor(#{ bins, k_max })", "The structure factor S(k) = |sum_j exp(i k.R_j)|^2 / N of the hydrodynamic centres over the periodic box's wave vectors 0 < |k| <= k_max (default 1.5 * 2 pi / mean spacing, at most 40 waves per axis), averaged in bins of |k| (default 32): #{ k: [...] (1/m), S: [...], count: [...] } for the non-empty bins. Needs a box.", "let s = scene(); s.box = [200e-6, 200e-6, 200e-6]; s.add_random(dumbbell(), 40, 1); print(s.structure_factor(#{ bins: 8 }).S.len());"),
    doc_entry!("field_stat", "observables", "field_stat(kind, stat) -> Observable\nfield_stat(kind, stat, #{ grid, width })", "A field's summary over its cells (f.stat) as an observable for recorders: e.g. field_stat(\"density\", \"variance\", #{ grid: [16, 16, 16] }) records density_variance [1/m^6].", "let s = scene(); s.add(dumbbell()); print(s.observe(field_stat(\"polarization\", \"mean\", #{ grid: [4, 4, 4] })));"),
];
