//! `scene()` and the `Scene` type: build, configure, run and read a simulation from a script.
//!
//! A scene is big and stateful, so scripts hold a cheap handle (`Arc<RwLock<Scene>>`, shareable
//! because `sweep` runs script closures on several threads): `let t = s;` names the same scene,
//! as in Python.

use super::convert::{array3, index, lift, number, script_error, unknown_choice, ScriptResult};
use super::dumbbell_api::DumbbellSpec;
use super::interrupt;
use crate::engine::{Backend, Coefficients, IntegratorSpec, Mobility, Model, Scene, Steric};
use rhai::{Array, Dynamic, Engine, ImmutableString, INT};
use std::sync::{Arc, RwLock, RwLockReadGuard, RwLockWriteGuard};

/// The largest scene file `load_scene` reads (bytes): a saved scene of 10^5 swimmers is ~60 MB.
pub const MAX_SCENE_FILE_BYTES: u64 = 256 << 20;

/// A script's handle on a scene (Rhai type `Scene`).
#[derive(Debug, Clone, Default)]
pub struct SceneHandle(pub Arc<RwLock<Scene>>);

impl SceneHandle {
    /// Wrap a scene.
    pub fn new(scene: Scene) -> Self {
        SceneHandle(Arc::new(RwLock::new(scene)))
    }

    /// Read the scene. A lock poisoned by a panic elsewhere still holds a consistent scene (every
    /// change is made whole or not at all), so it is read anyway.
    pub fn borrow(&self) -> RwLockReadGuard<'_, Scene> {
        self.0.read().unwrap_or_else(|e| e.into_inner())
    }

    /// Change the scene.
    pub fn borrow_mut(&self) -> RwLockWriteGuard<'_, Scene> {
        self.0.write().unwrap_or_else(|e| e.into_inner())
    }

    fn with<T>(&self, f: impl FnOnce(&Scene) -> crate::engine::Result<T>) -> ScriptResult<T> {
        lift(f(&self.borrow()))
    }

    fn with_mut<T>(
        &self,
        f: impl FnOnce(&mut Scene) -> crate::engine::Result<T>,
    ) -> ScriptResult<T> {
        lift(f(&mut self.borrow_mut()))
    }
}

fn string_arg(what: &str, v: &Dynamic) -> ScriptResult<String> {
    v.clone()
        .into_immutable_string()
        .map(|s| s.to_string())
        .map_err(|t| script_error(format!("{what} must be a string, got {v} ({t})")))
}

/// `s.steric = #{ range, stiffness }` (m, N/m) or `()` for none.
fn steric_arg(v: &Dynamic) -> ScriptResult<Option<Steric>> {
    const FIX: &str =
        "use s.steric = #{ range: 1e-7, stiffness: 1e-3 } (m, N/m), or s.steric = () for none";
    if v.is_unit() {
        return Ok(None);
    }
    let Some(map) = v.clone().try_cast::<rhai::Map>() else {
        return Err(script_error(format!(
            "s.steric must be a map or (), got {v}; {FIX}"
        )));
    };
    let (mut range, mut stiffness) = (None, None);
    for (k, val) in &map {
        match k.as_str() {
            "range" => range = Some(number("steric range", val)?),
            "stiffness" => stiffness = Some(number("steric stiffness", val)?),
            other => {
                return Err(script_error(format!(
                    "s.steric: unknown key \"{other}\"; {FIX}"
                )))
            }
        }
    }
    match (range, stiffness) {
        (Some(r), Some(k)) => lift(Steric::new(r, k)).map(Some),
        _ => Err(script_error(format!(
            "s.steric needs both range and stiffness; {FIX}"
        ))),
    }
}

fn swimmer_index(v: &Dynamic) -> ScriptResult<usize> {
    match v.as_int() {
        Ok(i) => index(i),
        Err(t) => Err(script_error(format!(
            "a swimmer index must be an integer such as 0, got {v} ({t})"
        ))),
    }
}

/// One-line description of a scene (what `print(s)` shows).
pub fn summary(s: &Scene) -> String {
    let backend = match s.backend() {
        Backend::Cpu => String::new(),
        b => format!(", backend = \"{}\"", b.name()),
    };
    let period = s
        .period()
        .map(|t| format!(", T = {t:.6e} s"))
        .unwrap_or_default();
    format!(
        "Scene({} swimmers, model = \"{}\", mobility = \"{}\", integrator = {}{}, mu = {:e} Pa s, t = {:.6e} s{period}{backend})",
        s.count(),
        s.model().name(),
        s.mobility().name(),
        s.integrator(),
        if s.integrator_is_default() { " [default]" } else { "" },
        s.mu(),
        s.time()
    )
}

/// `s.add_random(d, n, phi, seed[, #{ aligned: [x, y, z], phase: p }])`: n copies of d at
/// random non-overlapping places in a cube sized for sphere volume fraction phi, centred on the
/// origin; random orientations and phases unless fixed by the options. The scene is unchanged if
/// the placement fails.
fn add_random(
    s: &mut SceneHandle,
    d: DumbbellSpec,
    n: INT,
    phi: &Dynamic,
    seed: INT,
    opts: &rhai::Map,
) -> ScriptResult<INT> {
    use crate::engine::build::{box_side, random_suspension, Orientations, Phases};
    if n < 0 {
        return Err(script_error(format!(
            "add_random: the number of swimmers must be >= 0, got {n}"
        )));
    }
    let phi = number("add_random: volume fraction", phi)?;
    let mut orientations = Orientations::Random;
    let mut phases = Phases::Random;
    for (k, v) in opts {
        match k.as_str() {
            "aligned" => orientations = Orientations::Aligned(crate::engine::swimmer::unit_direction(super::convert::vector3("aligned", v)?).map_err(|e| script_error(format!("add_random: aligned: {e}")))?),
            "phase" => phases = Phases::Equal(number("phase", v)?),
            other => {
                return Err(script_error(format!(
                    "add_random: unknown option \"{other}\"; use aligned: [x, y, z] and/or phase: number"
                )))
            }
        }
    }
    let mut trial = s.borrow().clone();
    let side = lift(box_side(n as usize, &d.params, phi))?;
    lift(random_suspension(
        &mut trial,
        n as usize,
        d.params,
        side,
        orientations,
        phases,
        seed as u64,
    ))?;
    let mut scene = s.borrow_mut();
    let recorders_kept = std::mem::replace(&mut *scene, trial);
    scene.adopt_recorders(recorders_kept);
    Ok(scene.count() as INT)
}

/// `s.add_at(d, centres)`: a copy of d (its orientation and phase) at every centre of the array,
/// in order; all or nothing (the scene is unchanged if one does not fit).
fn add_at(s: &mut SceneHandle, d: DumbbellSpec, centres: &Array) -> ScriptResult<INT> {
    let mut trial = s.borrow().clone();
    for (k, c) in centres.iter().enumerate() {
        let c = super::convert::vector3(&format!("add_at: centre {k}"), c)?;
        lift(trial.add(d.params, c, d.dir))
            .map_err(|e| script_error(format!("add_at: centre {k}: {e}")))?;
    }
    let mut scene = s.borrow_mut();
    let recorders_kept = std::mem::replace(&mut *scene, trial);
    scene.adopt_recorders(recorders_kept);
    Ok(scene.count() as INT)
}

/// Run `f` with a progress bar over the next `duration` seconds (only at a terminal).
fn with_bar<T>(
    sc: &mut Scene,
    duration: f64,
    f: impl FnOnce(&mut Scene) -> crate::engine::Result<T>,
) -> crate::engine::Result<T> {
    let t0 = sc.time();
    match super::progress::RunBar::start(t0, t0 + duration, sc.period().ok()) {
        Some((bar, report)) => {
            sc.set_progress(Some(report));
            let r = f(sc);
            sc.set_progress(None);
            drop(bar);
            r
        }
        None => f(sc),
    }
}

/// Register the `Scene` type and its methods and properties.
pub fn register(engine: &mut Engine) {
    engine
        .register_type_with_name::<SceneHandle>("Scene")
        .register_fn("scene", SceneHandle::default)
        .register_fn("to_string", |s: &mut SceneHandle| summary(&s.borrow()))
        .register_fn("to_debug", |s: &mut SceneHandle| summary(&s.borrow()));

    // Building.
    engine.register_fn(
        "add",
        |s: &mut SceneHandle, d: DumbbellSpec| -> ScriptResult<INT> {
            s.with_mut(|sc| sc.add(d.params, d.center, d.dir))
                .map(|i| i as INT)
        },
    );
    engine.register_fn(
        "add",
        |_: &mut SceneHandle, d: Dynamic| -> ScriptResult<INT> {
            Err(script_error(format!(
                "add expects a Dumbbell such as dumbbell(#{{ phase: 0.0 }}), got {d} ({})",
                d.type_name()
            )))
        },
    );

    engine.register_fn(
        "add_random",
        |s: &mut SceneHandle,
         d: DumbbellSpec,
         n: INT,
         phi: Dynamic,
         seed: INT|
         -> ScriptResult<INT> { add_random(s, d, n, &phi, seed, &rhai::Map::new()) },
    );
    engine.register_fn(
        "add_random",
        |s: &mut SceneHandle,
         d: DumbbellSpec,
         n: INT,
         phi: Dynamic,
         seed: INT,
         opts: rhai::Map|
         -> ScriptResult<INT> { add_random(s, d, n, &phi, seed, &opts) },
    );

    engine.register_fn(
        "add_at",
        |s: &mut SceneHandle, d: DumbbellSpec, centres: Array| -> ScriptResult<INT> {
            add_at(s, d, &centres)
        },
    );

    // Properties.
    engine
        .register_get("time", |s: &mut SceneHandle| s.borrow().time())
        .register_get("count", |s: &mut SceneHandle| s.borrow().count() as INT)
        .register_get("period", |s: &mut SceneHandle| s.with(|sc| sc.period()))
        .register_get("stiff_rate", |s: &mut SceneHandle| s.borrow().stiff_rate())
        .register_get("mu", |s: &mut SceneHandle| s.borrow().mu())
        .register_set(
            "mu",
            |s: &mut SceneHandle, v: Dynamic| -> ScriptResult<()> {
                let mu = number("mu", &v)?;
                s.with_mut(|sc| sc.set_mu(mu))
            },
        )
        .register_get("model", |s: &mut SceneHandle| ImmutableString::from(s.borrow().model().name()))
        .register_set(
            "model",
            |s: &mut SceneHandle, v: Dynamic| -> ScriptResult<()> {
                let name = string_arg("model", &v)?;
                let m = lift(Model::parse(&name))?;
                s.borrow_mut().set_model(m);
                Ok(())
            },
        )
        .register_get("mobility", |s: &mut SceneHandle| ImmutableString::from(s.borrow().mobility().name()))
        .register_set(
            "mobility",
            |s: &mut SceneHandle, v: Dynamic| -> ScriptResult<()> {
                let name = string_arg("mobility", &v)?;
                let m = lift(Mobility::parse(&name))?;
                s.borrow_mut().set_mobility(m);
                Ok(())
            },
        )
        .register_get("backend", |s: &mut SceneHandle| ImmutableString::from(s.borrow().backend().name()))
        .register_set(
            "backend",
            |s: &mut SceneHandle, v: Dynamic| -> ScriptResult<()> {
                let name = string_arg("backend", &v)?;
                let b = lift(Backend::parse(&name))?;
                if b == Backend::Gpu {
                    crate::engine::gpu::device().map_err(|e| {
                        script_error(format!(
                            "s.backend = \"gpu\": {e}; use s.backend = \"cpu\" or \"auto\""
                        ))
                    })?;
                }
                s.borrow_mut().set_backend(b);
                Ok(())
            },
        )
        .register_get("backend_info", |s: &mut SceneHandle| {
            s.with(|sc| sc.backend_info()).map(ImmutableString::from)
        })
        .register_get("coefficients", |s: &mut SceneHandle| ImmutableString::from(s.borrow().coefficients().name()))
        .register_set(
            "coefficients",
            |s: &mut SceneHandle, v: Dynamic| -> ScriptResult<()> {
                let name = string_arg("coefficients", &v)?;
                let c = lift(Coefficients::parse(&name))?;
                s.borrow_mut().set_coefficients(c);
                Ok(())
            },
        )
        .register_get("overlaps", |s: &mut SceneHandle| {
            ImmutableString::from(if s.borrow().contacts().allow_overlap { "allow" } else { "stop" })
        })
        .register_set(
            "overlaps",
            |s: &mut SceneHandle, v: Dynamic| -> ScriptResult<()> {
                let name = string_arg("overlaps", &v)?;
                let allow = match name.as_str() {
                    "stop" => false,
                    "allow" => true,
                    _ => return Err(unknown_choice("overlaps setting", &name, &["stop", "allow"])),
                };
                s.borrow_mut().set_allow_overlap(allow);
                Ok(())
            },
        )
        .register_get("steric", |s: &mut SceneHandle| match s.borrow().contacts().steric {
            Some(st) => {
                let mut m = rhai::Map::new();
                m.insert("range".into(), Dynamic::from_float(st.range));
                m.insert("stiffness".into(), Dynamic::from_float(st.stiffness));
                Dynamic::from_map(m)
            }
            None => Dynamic::UNIT,
        })
        .register_set("steric", |s: &mut SceneHandle, v: Dynamic| -> ScriptResult<()> {
            s.borrow_mut().set_steric(steric_arg(&v)?);
            Ok(())
        })
        .register_get("cutoff", |s: &mut SceneHandle| {
            s.borrow().cutoff().map_or(Dynamic::UNIT, Dynamic::from_float)
        })
        .register_set("cutoff", |s: &mut SceneHandle, v: Dynamic| -> ScriptResult<()> {
            let c = if v.is_unit() { None } else { Some(number("s.cutoff", &v)?) };
            s.with_mut(|sc| sc.set_cutoff(c))
        })
        .register_get("integrator", |s: &mut SceneHandle| s.borrow().integrator())
        .register_set(
            "integrator",
            |s: &mut SceneHandle, v: Dynamic| -> ScriptResult<()> {
                if let Some(spec) = v.clone().try_cast::<IntegratorSpec>() {
                    s.borrow_mut().set_integrator(Some(spec));
                    return Ok(());
                }
                match v.clone().into_immutable_string() {
                    Ok(name) if name == "default" => {
                        s.borrow_mut().set_integrator(None);
                        Ok(())
                    }
                    Ok(name) => Err(unknown_choice("integrator", &name, &["default"])),
                    Err(t) => Err(script_error(format!(
                        "integrator must be euler(dt), rk4(dt), dopri5(rtol), rosw(rtol) or \"default\", got {v} ({t})"
                    ))),
                }
            },
        );

    // Reading one swimmer.
    engine
        .register_fn(
            "center",
            |s: &mut SceneHandle, i: Dynamic| -> ScriptResult<Array> {
                let i = swimmer_index(&i)?;
                s.with(|sc| sc.center(i)).map(|v| array3(&v))
            },
        )
        .register_fn(
            "dir",
            |s: &mut SceneHandle, i: Dynamic| -> ScriptResult<Array> {
                let i = swimmer_index(&i)?;
                s.with(|sc| sc.dir(i)).map(|v| array3(&v))
            },
        )
        .register_fn(
            "velocity",
            |s: &mut SceneHandle, i: Dynamic| -> ScriptResult<Array> {
                let i = swimmer_index(&i)?;
                s.with(|sc| sc.rates(i)).map(|(v, _)| array3(&v))
            },
        )
        .register_fn(
            "spin",
            |s: &mut SceneHandle, i: Dynamic| -> ScriptResult<Array> {
                let i = swimmer_index(&i)?;
                s.with(|sc| sc.rates(i)).map(|(_, w)| array3(&w))
            },
        )
        .register_fn(
            "length",
            |s: &mut SceneHandle, i: Dynamic| -> ScriptResult<f64> {
                let i = swimmer_index(&i)?;
                s.with(|sc| sc.length(i))
            },
        )
        .register_fn(
            "swimmer",
            |s: &mut SceneHandle, i: Dynamic| -> ScriptResult<DumbbellSpec> {
                let i = swimmer_index(&i)?;
                s.with(|sc| {
                    Ok(DumbbellSpec {
                        params: *sc.swimmer(i)?,
                        center: sc.center(i)?,
                        dir: sc.dir(i)?,
                    })
                })
            },
        )
        .register_fn(
            "set_phase",
            |s: &mut SceneHandle, i: Dynamic, phase: Dynamic| -> ScriptResult<()> {
                let i = swimmer_index(&i)?;
                let phase = number("phase", &phase)?;
                s.with_mut(|sc| sc.set_phase(i, phase))
            },
        );

    // Phases, copies, files.
    engine
        .register_get("phases", |s: &mut SceneHandle| -> Array {
            s.borrow()
                .phases()
                .into_iter()
                .map(Dynamic::from_float)
                .collect()
        })
        .register_set(
            "phases",
            |s: &mut SceneHandle, v: Dynamic| -> ScriptResult<()> {
                let arr = v.clone().try_cast::<Array>().ok_or_else(|| {
                    script_error(format!(
                        "phases must be an array of numbers, got {v} ({})",
                        v.type_name()
                    ))
                })?;
                let ph = arr
                    .iter()
                    .enumerate()
                    .map(|(k, x)| number(&format!("phases[{k}]"), x))
                    .collect::<ScriptResult<Vec<f64>>>()?;
                s.with_mut(|sc| sc.set_phases(&ph))
            },
        )
        .register_fn(
            "phase",
            |s: &mut SceneHandle, i: Dynamic| -> ScriptResult<f64> {
                let i = swimmer_index(&i)?;
                s.with(|sc| sc.swimmer(i).map(|d| d.phase))
            },
        )
        .register_fn("copy", |s: &mut SceneHandle| {
            SceneHandle::new(s.borrow().clone())
        })
        .register_fn(
            "save",
            |s: &mut SceneHandle, path: &str| -> ScriptResult<()> {
                let json = s.with(|sc| sc.to_json())?;
                lift(crate::engine::files::write_atomically(
                    std::path::Path::new(path),
                    |w| w.write_all(json.as_bytes()),
                ))
            },
        )
        .register_fn("load_scene", |path: &str| -> ScriptResult<SceneHandle> {
            let text = super::read_text(
                std::path::Path::new(path),
                MAX_SCENE_FILE_BYTES,
                "scene file",
            )
            .map_err(script_error)?;
            Scene::from_json(&text)
                .map(SceneHandle::new)
                .map_err(|e| script_error(format!("load_scene(\"{path}\"): {e}")))
        });

    // Running.
    engine
        .register_fn(
            "run",
            |s: &mut SceneHandle, duration: Dynamic| -> ScriptResult<()> {
                let d = number("run(duration)", &duration)?;
                s.with_mut(|sc| with_bar(sc, d, |sc| sc.run(d, &interrupt::requested)))
            },
        )
        .register_fn(
            "run_periods",
            |s: &mut SceneHandle, n: Dynamic| -> ScriptResult<()> {
                let n = number("run_periods(n)", &n)?;
                s.with_mut(|sc| {
                    let d = sc.period().map_or(0.0, |t| n * t);
                    with_bar(sc, d, |sc| sc.run_periods(n, &interrupt::requested))
                })
            },
        )
        .register_get("stats", |s: &mut SceneHandle| {
            let st = s.borrow().stats();
            let mut m = rhai::Map::new();
            m.insert("steps".into(), (st.steps as INT).into());
            m.insert("rejected".into(), (st.rejected as INT).into());
            m.insert("rhs_evals".into(), (st.rhs_evals as INT).into());
            m.insert(
                "rejected_by_guard".into(),
                (st.rejected_by_guard as INT).into(),
            );
            m
        });
}
