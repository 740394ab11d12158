//! Pictures from scripts: `plot` and `tplot` of series, `rec.plot` / `rec.tplot` of recorded
//! columns, and `s.snapshot` of a scene.
//!
//! A series is a map `#{ x: [..], y: [..], label: "..", style: "line" | "points", color: 0-9 }`
//! (x defaults to 0, 1, 2, ...; color to the series' index in the palette); options are a
//! map `#{ title, x_label, y_label, log_x, log_y, width, height }` (and `cols`, `rows` for text).

use super::convert::{describe, lift, number, script_error, ScriptResult};
use super::doc::{doc_entry, Doc};
use super::observable_api::RecorderHandle;
use super::picture_api::Picture;
use super::scene_api::SceneHandle;
use crate::plot::{
    render_text, scene_image, snapshot, Figure, Legend, Plane, SceneFilm, Series, SnapshotOptions,
    Style,
};
use rhai::{Array, Dynamic, Engine, Map, INT};

fn numbers(what: &str, v: &Dynamic) -> ScriptResult<Vec<f64>> {
    let arr = v.clone().try_cast::<Array>().ok_or_else(|| {
        script_error(format!(
            "{what} must be an array of numbers, got {}",
            describe(v)
        ))
    })?;
    arr.iter()
        .enumerate()
        .map(|(i, x)| number(&format!("{what}[{i}]"), x))
        .collect()
}

fn text(what: &str, v: &Dynamic) -> ScriptResult<String> {
    v.clone()
        .into_immutable_string()
        .map(|s| s.to_string())
        .map_err(|_| script_error(format!("{what} must be a string, got {}", describe(v))))
}

fn flag(what: &str, v: &Dynamic) -> ScriptResult<bool> {
    v.as_bool()
        .map_err(|_| script_error(format!("{what} must be true or false, got {}", describe(v))))
}

fn pixels(what: &str, v: &Dynamic) -> ScriptResult<u32> {
    let n = number(what, v)?;
    if n.fract() != 0.0 || !(1.0..=1e5).contains(&n) {
        return Err(script_error(format!(
            "{what} must be a whole number of pixels, got {}",
            describe(v)
        )));
    }
    Ok(n as u32)
}

fn series_of(k: usize, m: &Map) -> ScriptResult<Series> {
    let mut s = Series {
        label: String::new(),
        x: Vec::new(),
        y: Vec::new(),
        style: Style::Line,
        color: None,
    };
    let (mut has_x, mut has_y) = (false, false);
    for (key, v) in m {
        match key.as_str() {
            "x" => (s.x, has_x) = (numbers(&format!("series {k}: x"), v)?, true),
            "y" => (s.y, has_y) = (numbers(&format!("series {k}: y"), v)?, true),
            "label" => s.label = text("label", v)?,
            "color" => {
                let c = v.as_int().map_err(|_| {
                    script_error(format!(
                        "series {k}: color must be a palette index 0-9, got {}",
                        describe(v)
                    ))
                })?;
                s.color = Some(c.rem_euclid(crate::plot::COLORS.len() as rhai::INT) as usize);
            }
            "style" => {
                s.style = Style::parse(&text("style", v)?)
                    .map_err(|e| script_error(format!("series {k}: {e}")))?
            }
            other => {
                return Err(script_error(format!(
                    "series {k}: unknown key \"{other}\"; use x, y, label, style, color"
                )))
            }
        }
    }
    if !has_y {
        return Err(script_error(format!(
            "series {k} has no y; a series is #{{ x: [..], y: [..], label: \"..\" }}"
        )));
    }
    if !has_x {
        s.x = (0..s.y.len()).map(|i| i as f64).collect();
    }
    Ok(s)
}

/// One map or an array of maps.
fn all_series(v: &Dynamic) -> ScriptResult<Vec<Series>> {
    if let Some(m) = v.clone().try_cast::<Map>() {
        return Ok(vec![series_of(0, &m)?]);
    }
    let arr = v.clone().try_cast::<Array>().ok_or_else(|| {
        script_error(format!(
            "plot series must be a map #{{ x: [..], y: [..] }} or an array of them, got {}",
            describe(v)
        ))
    })?;
    arr.iter()
        .enumerate()
        .map(|(k, s)| {
            let m = s.clone().try_cast::<Map>().ok_or_else(|| {
                script_error(format!(
                    "series {k} must be a map #{{ x: [..], y: [..] }}, got {}",
                    describe(s)
                ))
            })?;
            series_of(k, &m)
        })
        .collect()
}

/// Text plot size from the options.
struct TextSize(usize, usize);

fn apply_options(f: &mut Figure, opts: &Map) -> ScriptResult<TextSize> {
    let mut size = TextSize(72, 18);
    for (key, v) in opts {
        match key.as_str() {
            "title" => f.title = text("title", v)?,
            "x_label" => f.x_label = text("x_label", v)?,
            "y_label" => f.y_label = text("y_label", v)?,
            "log_x" => f.log_x = flag("log_x", v)?,
            "log_y" => f.log_y = flag("log_y", v)?,
            "width" => f.width = pixels("width", v)?,
            "height" => f.height = pixels("height", v)?,
            "legend" => {
                f.legend = Legend::parse(&text("legend", v)?).map_err(script_error)?
            }
            "cols" => size.0 = pixels("cols", v)? as usize,
            "rows" => size.1 = pixels("rows", v)? as usize,
            other => {
                return Err(script_error(format!(
                    "unknown plot option \"{other}\"; use title, x_label, y_label, log_x, log_y, width, height, legend (cols, rows for tplot)"
                )))
            }
        }
    }
    Ok(size)
}

fn save(f: &Figure, path: &str) -> ScriptResult<()> {
    f.save(std::path::Path::new(path))
        .map_err(|e| script_error(format!("plot \"{path}\": {e}")))
}

fn show(f: &Figure, size: TextSize) -> ScriptResult<()> {
    let t = render_text(f, size.0, size.1).map_err(|e| script_error(format!("tplot: {e}")))?;
    super::console::write(&t);
    Ok(())
}

/// The figure of `series` with `opts` applied, and the text plot size.
fn figure_of(series: &Dynamic, opts: &Map) -> ScriptResult<(Figure, TextSize)> {
    let mut f = Figure {
        series: all_series(series)?,
        ..Figure::default()
    };
    let size = apply_options(&mut f, opts)?;
    Ok((f, size))
}

fn plot(path: &str, series: &Dynamic, opts: &Map) -> ScriptResult<()> {
    save(&figure_of(series, opts)?.0, path)
}

fn tplot(series: &Dynamic, opts: &Map) -> ScriptResult<()> {
    let (f, size) = figure_of(series, opts)?;
    show(&f, size)
}

/// Columns `x` and `ys` of a recorder as a figure, labelled with the header's units.
fn recorder_figure(r: &RecorderHandle, x: &str, ys: &Dynamic) -> ScriptResult<Figure> {
    let names: Vec<String> = if let Ok(s) = ys.clone().into_immutable_string() {
        vec![s.to_string()]
    } else {
        let arr = ys.clone().try_cast::<Array>().ok_or_else(|| {
            script_error(format!(
                "y columns must be a name or an array of names, got {}",
                describe(ys)
            ))
        })?;
        arr.iter()
            .map(|v| text("y column", v))
            .collect::<ScriptResult<_>>()?
    };
    r.with(|rec| {
        let cols = rec.columns();
        let header = rec.header();
        let find = |name: &str| {
            cols.iter().position(|c| c == name).ok_or_else(|| {
                script_error(format!(
                    "the recorder has no column \"{name}\"; it has {}",
                    cols.join(", ")
                ))
            })
        };
        let column = |i: usize| rec.rows.iter().map(|row| row[i]).collect::<Vec<f64>>();
        let xi = find(x)?;
        let series = names
            .iter()
            .map(|n| {
                let i = find(n)?;
                Ok(Series {
                    label: header[i].clone(),
                    x: column(xi),
                    y: column(i),
                    style: Style::Line,
                    color: None,
                })
            })
            .collect::<ScriptResult<Vec<_>>>()?;
        let y_label = if names.len() == 1 {
            header[find(&names[0])?].clone()
        } else {
            String::new()
        };
        Ok(Figure {
            x_label: header[xi].clone(),
            y_label,
            series,
            ..Figure::default()
        })
    })?
}

fn snapshot_options(opts: &Map) -> ScriptResult<SnapshotOptions> {
    let mut o = SnapshotOptions::default();
    for (key, v) in opts {
        match key.as_str() {
            "plane" => {
                o.plane = Plane::parse(&text("plane", v)?)
                    .map_err(|e| script_error(format!("snapshot: {e}")))?
            }
            "title" => o.title = text("title", v)?,
            "width" => o.width = pixels("width", v)?,
            "height" => o.height = pixels("height", v)?,
            other => {
                return Err(script_error(format!(
                    "unknown snapshot option \"{other}\"; use plane, title, width, height"
                )))
            }
        }
    }
    Ok(o)
}

/// Most frames one animation may have (a GIF of 700×600 frames is ~100 KB a frame).
const MAX_FRAMES: i64 = 2000;

/// `s.animate(path, #{ periods, frames, fps, plane, title, width, height })`: run the scene for
/// `periods` periods and write `frames` + 1 pictures (the first now, then one per equal slice of
/// the run) to an animated GIF. Recorders fire as in any run; an error or Ctrl-C stops the run
/// and leaves the frames so far in a valid GIF.
fn animate(s: &mut SceneHandle, path: &str, opts: &Map) -> ScriptResult<INT> {
    let (mut periods, mut frames, mut fps) = (1.0, 24_i64, 12.0);
    let mut rest = Map::new();
    for (key, v) in opts {
        match key.as_str() {
            "periods" => periods = number("animate: periods", v)?,
            "frames" => {
                frames = v.as_int().map_err(|_| {
                    script_error(format!(
                        "animate: frames must be a whole number, got {}",
                        describe(v)
                    ))
                })?
            }
            "fps" => fps = number("animate: fps", v)?,
            _ => {
                rest.insert(key.clone(), v.clone());
            }
        }
    }
    if !(1..=MAX_FRAMES).contains(&frames) {
        return Err(script_error(format!(
            "animate: frames must be 1 to {MAX_FRAMES}, got {frames}"
        )));
    }
    if !(periods.is_finite() && periods > 0.0) {
        return Err(script_error(format!(
            "animate: periods must be a positive number, got {periods}"
        )));
    }
    let o = snapshot_options(&rest).map_err(|e| {
        script_error(format!(
            "animate: {}; or periods, frames, fps",
            e.to_string()
                .trim_end_matches(|c: char| c == ')' || c.is_whitespace())
        ))
    })?;
    let duration = periods * lift(s.borrow().period())?;
    let mut film = SceneFilm::create(std::path::Path::new(path), &o, fps)
        .map_err(|e| script_error(format!("animate \"{path}\": {e}")))?;
    let t0 = s.borrow().time();
    for k in 0..=frames {
        if k > 0 {
            // Frame k at t0 + k/frames of the run: no rounding accumulates over the frames.
            let target = t0 + duration * k as f64 / frames as f64;
            let now = s.borrow().time();
            lift(s.borrow_mut()?.run((target - now).max(0.0)))?;
        }
        film.frame(&s.borrow())
            .map_err(|e| script_error(format!("animate \"{path}\": {e}")))?;
    }
    Ok(film.frames() as INT)
}

/// `f` drawn in memory.
fn picture(f: &Figure) -> ScriptResult<Picture> {
    Ok(Picture::new(
        f.image().map_err(|e| script_error(format!("plot: {e}")))?,
        "plot",
    ))
}

/// A picture of the scene in memory.
fn scene_picture(s: &SceneHandle, opts: &SnapshotOptions) -> ScriptResult<Picture> {
    let image =
        scene_image(&s.borrow(), opts).map_err(|e| script_error(format!("snapshot: {e}")))?;
    Ok(Picture::new(image, "snapshot"))
}

/// Register the picture functions.
pub fn register(engine: &mut Engine) {
    // Without a path: a Picture value (notebooks show it inline).
    engine
        .register_fn("plot", |series: Dynamic| -> ScriptResult<Picture> {
            picture(&figure_of(&series, &Map::new())?.0)
        })
        .register_fn(
            "plot",
            |series: Array, opts: Map| -> ScriptResult<Picture> {
                picture(&figure_of(&Dynamic::from(series), &opts)?.0)
            },
        )
        .register_fn("plot", |series: Map, opts: Map| -> ScriptResult<Picture> {
            picture(&figure_of(&Dynamic::from(series), &opts)?.0)
        })
        .register_fn(
            "plot",
            |r: &mut RecorderHandle, x: &str, ys: Dynamic| -> ScriptResult<Picture> {
                picture(&recorder_figure(r, x, &ys)?)
            },
        )
        .register_fn(
            "plot",
            |r: &mut RecorderHandle, x: &str, ys: Dynamic, opts: Map| -> ScriptResult<Picture> {
                let mut f = recorder_figure(r, x, &ys)?;
                apply_options(&mut f, &opts)?;
                picture(&f)
            },
        )
        .register_fn("snapshot", |s: &mut SceneHandle| -> ScriptResult<Picture> {
            scene_picture(s, &SnapshotOptions::default())
        })
        .register_fn(
            "snapshot",
            |s: &mut SceneHandle, opts: Map| -> ScriptResult<Picture> {
                scene_picture(s, &snapshot_options(&opts)?)
            },
        );
    engine
        .register_fn(
            "animate",
            |s: &mut SceneHandle, path: &str| -> ScriptResult<INT> {
                animate(s, path, &Map::new())
            },
        )
        .register_fn(
            "animate",
            |s: &mut SceneHandle, path: &str, opts: Map| -> ScriptResult<INT> {
                animate(s, path, &opts)
            },
        );
    engine
        .register_fn("plot", |path: &str, series: Dynamic| {
            plot(path, &series, &Map::new())
        })
        .register_fn("plot", |path: &str, series: Dynamic, opts: Map| {
            plot(path, &series, &opts)
        })
        .register_fn("tplot", |series: Dynamic| tplot(&series, &Map::new()))
        .register_fn("tplot", |series: Dynamic, opts: Map| tplot(&series, &opts))
        .register_fn(
            "plot",
            |r: &mut RecorderHandle, path: &str, x: &str, ys: Dynamic| -> ScriptResult<()> {
                save(&recorder_figure(r, x, &ys)?, path)
            },
        )
        .register_fn(
            "plot",
            |r: &mut RecorderHandle,
             path: &str,
             x: &str,
             ys: Dynamic,
             opts: Map|
             -> ScriptResult<()> {
                let mut f = recorder_figure(r, x, &ys)?;
                apply_options(&mut f, &opts)?;
                save(&f, path)
            },
        )
        .register_fn(
            "tplot",
            |r: &mut RecorderHandle, x: &str, ys: Dynamic| -> ScriptResult<()> {
                show(&recorder_figure(r, x, &ys)?, TextSize(72, 18))
            },
        )
        .register_fn(
            "tplot",
            |r: &mut RecorderHandle, x: &str, ys: Dynamic, opts: Map| -> ScriptResult<()> {
                let mut f = recorder_figure(r, x, &ys)?;
                let size = apply_options(&mut f, &opts)?;
                show(&f, size)
            },
        )
        .register_fn(
            "snapshot",
            |s: &mut SceneHandle, path: &str| -> ScriptResult<()> {
                snapshot(
                    &s.borrow(),
                    &SnapshotOptions::default(),
                    std::path::Path::new(path),
                )
                .map_err(|e| script_error(format!("snapshot \"{path}\": {e}")))
            },
        )
        .register_fn(
            "snapshot",
            |s: &mut SceneHandle, path: &str, opts: Map| -> ScriptResult<()> {
                let o = snapshot_options(&opts)?;
                snapshot(&s.borrow(), &o, std::path::Path::new(path))
                    .map_err(|e| script_error(format!("snapshot \"{path}\": {e}")))
            },
        );
}

/// The help text of this file's script names (`:help NAME`), gathered by [`super::docs`].
pub(super) const DOCS: &[Doc] = &[
    doc_entry!("plot", "pictures", "plot(path, series)\nplot(path, series, #{ title, x_label, y_label, log_x, log_y, width, height })\nrec.plot(path, x_column, y_columns)\nrec.plot(path, x_column, y_columns, options)", "Draw series to an SVG or PNG file (by the extension; folders are created). A series is #{ x: [..], y: [..], label: \"..\", style: \"line\" | \"points\" }; give one map or an array of them. rec.plot draws recorded columns against one column, with their units as labels. Text uses an embedded font: no system fonts needed. Without a path, plot(series[, options]) and rec.plot(x_column, y_columns[, options]) return a Picture (:help Picture), which a notebook shows inline.", "plot(\"out/help/p.svg\", [#{ x: [1, 2, 3], y: [1, 4, 9], label: \"x^2\" }, #{ x: [1, 2, 3], y: [1, 8, 27], label: \"x^3\", style: \"points\" }], #{ title: \"powers\", x_label: \"x\", y_label: \"y\", log_y: true });"),
    doc_entry!("tplot", "pictures", "tplot(series)\ntplot(series, options)\nrec.tplot(x_column, y_columns)\nrec.tplot(x_column, y_columns, options)", "A quick plot as text in the terminal: series and options as for plot, plus cols and rows (the plot area in characters, default 72 x 18).", "tplot(#{ x: [0, 1, 2, 3], y: [0, 1, 4, 9], label: \"x^2\" }, #{ cols: 40, rows: 8 });"),
    doc_entry!("animate", "pictures", "s.animate(path) -> int\ns.animate(path, #{ periods, frames, fps, plane, title, width, height }) -> int", "Run the scene for periods periods (default 1) and write an animated GIF of it: the picture of s.snapshot now and after each of frames equal slices of the run (default 24; at most 2000), fps frames a second (default 12), every frame showing the first frame's region. The run is a run like any other: the scene moves on and recorders fire; Ctrl-C stops it and the frames so far stay a valid GIF. Returns the number of frames.", "let s = scene(); s.add(dumbbell(#{ a1: 1.125e-6, a2: 0.5625e-6 })); print(s.animate(\"out/help/stroke.gif\", #{ periods: 1, frames: 8 }));"),
    doc_entry!("snapshot", "pictures", "s.snapshot(path)\ns.snapshot(path, #{ plane: \"xy\" | \"xz\" | \"yz\", title, width, height })", "A picture of the scene (SVG or PNG): every swimmer's spheres at their radii and its rod, projected on a plane, coloured by the in-plane direction of N (aligned swimmers share a colour; out-of-plane ones fade to grey). Call it in a loop for the frames of an animation. Without a path, s.snapshot() and s.snapshot(options) return a Picture (:help Picture).", "let s = scene(); s.add(dumbbell()); s.add(dumbbell(#{ center: [12e-6, 3e-6, 0], dir: [0, 1, 0] })); s.snapshot(\"out/help/scene.png\", #{ title: \"two swimmers\" });"),
];
