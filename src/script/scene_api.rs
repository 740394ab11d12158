//! `scene()` and the `Scene` type: build, configure, run and read a simulation from a script.
//!
//! A scene is big and stateful, so scripts hold a cheap handle on its simulation
//! (`Arc<RwLock<Simulation>>`, shareable because `sweep` runs script closures on several threads):
//! `let t = s;` names the same scene, as in Python. Every run of a script's scene stops on Ctrl-C
//! ([`interrupt`]).

use super::convert::{array3, describe, index, lift, number, script_error, ScriptResult};
use super::doc::{self, doc_entry, Doc};
use super::dumbbell_api::DumbbellSpec;
use super::interrupt;
use crate::engine::{Backend, Scene, Simulation};
use crate::view::Server;
use rhai::{Array, Dynamic, Engine, INT};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, RwLock, RwLockReadGuard, RwLockWriteGuard};

/// The largest scene file `load_scene` reads (bytes): a saved scene of 10^5 swimmers is ~60 MB.
pub const MAX_SCENE_FILE_BYTES: u64 = 256 << 20;

/// A script's handle on a scene and its simulation (Rhai type `Scene`).
#[derive(Debug, Clone)]
pub struct SceneHandle {
    sim: Arc<RwLock<Simulation>>,
    /// The sweeps whose calls share this scene now: while any does, it can be read, not changed.
    shared_by_sweeps: SweepCount,
    /// The live view of this scene, if one is served (`s.view()`).
    view: Arc<Mutex<Option<Arc<Server>>>>,
    /// Held by the handles that are the script's scene values (not by a recorder's handle): the
    /// view stops when the last of them is dropped, though recorders keep the scene.
    _owner: Option<Arc<ViewOwner>>,
}

/// Stops a scene's live view when dropped (see [`SceneHandle`]'s `_owner`).
#[derive(Debug)]
struct ViewOwner {
    view: Arc<Mutex<Option<Arc<Server>>>>,
}

impl Drop for ViewOwner {
    fn drop(&mut self) {
        let server = self.view.lock().unwrap_or_else(|e| e.into_inner()).take();
        // Outside the lock: dropping the last handle on a server joins its threads.
        drop(server);
    }
}

/// How many sweeps' calls share a script value now (a scene, a continuum): they run at once on
/// several threads, so while any does, the value may be read through its handle, not changed.
#[derive(Debug, Clone, Default)]
pub(super) struct SweepCount(Arc<AtomicUsize>);

impl SweepCount {
    /// Refuse a change of this `what` ("scene", "continuum") while a sweep shares it; `copy` is
    /// the fix, a change of a copy ("let t = s.copy(); t.run_periods(1); ...").
    pub(super) fn refuse_change(&self, what: &str, copy: &str) -> ScriptResult<()> {
        if self.0.load(Ordering::SeqCst) > 0 {
            return Err(script_error(format!(
                "this {what} is shared by every call of the sweep (captured by its closure, or given in more than one parameter), and the calls run at once on several threads: changing it from them would race, and the results would change from run to run; a call may read it, not change it: build the {what} inside the closure, or change a copy there ({copy})"
            )));
        }
        Ok(())
    }
}

/// While this lives, the values whose counts it holds are shared by the calls of a sweep.
pub(super) struct SweepShare(Vec<SweepCount>);

impl SweepShare {
    /// Share the values of `counts` (each once) until the result is dropped.
    pub(super) fn new(counts: Vec<SweepCount>) -> Self {
        for c in &counts {
            c.0.fetch_add(1, Ordering::SeqCst);
        }
        SweepShare(counts)
    }
}

impl Drop for SweepShare {
    fn drop(&mut self) {
        for c in &self.0 {
            c.0.fetch_sub(1, Ordering::SeqCst);
        }
    }
}

impl Default for SceneHandle {
    fn default() -> Self {
        SceneHandle::new(Scene::default())
    }
}

impl SceneHandle {
    /// A simulation of `scene` whose runs stop on Ctrl-C.
    pub fn new(scene: Scene) -> Self {
        let mut sim = Simulation::new(scene);
        let stop = interrupt::current();
        sim.set_interrupt(Some(Arc::new(move || stop.requested())));
        sim.set_notice(Some(Arc::new(|e: &crate::engine::EngineError| {
            super::console::note(&super::engine_message(e))
        })));
        let view = Arc::<Mutex<Option<Arc<Server>>>>::default();
        SceneHandle {
            sim: Arc::new(RwLock::new(sim)),
            shared_by_sweeps: SweepCount::default(),
            _owner: Some(Arc::new(ViewOwner { view: view.clone() })),
            view,
        }
    }

    /// A handle on the same scene that does not keep its live view up (a recorder's): the view
    /// stops with the script's last scene value even while this handle lives.
    pub(super) fn without_view(&self) -> SceneHandle {
        SceneHandle {
            _owner: None,
            ..self.clone()
        }
    }

    /// Whether `other` is a handle on the same scene.
    pub(super) fn is_same_as(&self, other: &SceneHandle) -> bool {
        Arc::ptr_eq(&self.sim, &other.sim)
    }

    /// Shows the scene's watcher (its live view) the scene as it is as a change, from any
    /// thread, while the scene lives: the view's late drawing of a change, at the view's rate.
    pub(super) fn redraw(&self) -> crate::view::Refresh {
        let sim = Arc::downgrade(&self.sim);
        Arc::new(move || {
            if let Some(sim) = sim.upgrade() {
                sim.read().unwrap_or_else(|e| e.into_inner()).show_change();
            }
        })
    }

    /// The scene's live view, if one is served.
    pub(super) fn view(&self) -> std::sync::MutexGuard<'_, Option<Arc<Server>>> {
        self.view.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The count of sweeps sharing this scene.
    pub(super) fn sweeps(&self) -> &SweepCount {
        &self.shared_by_sweeps
    }

    /// Read the simulation (and through it the scene). A lock poisoned by a panic elsewhere still
    /// holds a consistent one (every change is made whole or not at all), so it is read anyway.
    pub fn borrow(&self) -> RwLockReadGuard<'_, Simulation> {
        self.sim.read().unwrap_or_else(|e| e.into_inner())
    }

    /// Change the simulation; refused while the calls of a sweep share the scene: they run at once
    /// on several threads, and changes from them would race (results changing from run to run).
    pub fn borrow_mut(&self) -> ScriptResult<RwLockWriteGuard<'_, Simulation>> {
        self.shared_by_sweeps
            .refuse_change("scene", "let t = s.copy(); t.run_periods(1); ...")?;
        Ok(self.write())
    }

    /// The simulation to measure with (a probe runs copies, and keeps its buffers in the
    /// simulation): a reading, allowed while a sweep shares the scene; the lock keeps the calls'
    /// measurements one at a time.
    pub(super) fn borrow_to_measure(&self) -> RwLockWriteGuard<'_, Simulation> {
        self.write()
    }

    fn write(&self) -> RwLockWriteGuard<'_, Simulation> {
        self.sim.write().unwrap_or_else(|e| e.into_inner())
    }

    pub(super) fn with<T>(
        &self,
        f: impl FnOnce(&Scene) -> crate::engine::Result<T>,
    ) -> ScriptResult<T> {
        lift(f(&self.borrow()))
    }

    /// Change the scene's settings or swimmers; a live view, if any, is shown the scene after.
    pub(super) fn with_mut<T>(
        &self,
        f: impl FnOnce(&mut Scene) -> crate::engine::Result<T>,
    ) -> ScriptResult<T> {
        let mut sim = self.borrow_mut()?;
        let result = f(sim.scene_mut());
        sim.show_change();
        lift(result)
    }

    /// Run.
    pub(super) fn with_sim<T>(
        &self,
        f: impl FnOnce(&mut Simulation) -> crate::engine::Result<T>,
    ) -> ScriptResult<T> {
        lift(f(&mut *self.borrow_mut()?))
    }

    /// Put `trial` in place of the scene (the recorders stay); returns the new count.
    pub(super) fn replace(&self, trial: Scene) -> ScriptResult<INT> {
        let mut sim = self.borrow_mut()?;
        sim.replace_scene(trial);
        sim.show_change();
        Ok(sim.count() as INT)
    }
}

fn swimmer_index(v: &Dynamic) -> ScriptResult<usize> {
    match v.as_int() {
        Ok(i) => index(i),
        Err(_) => Err(script_error(format!(
            "a swimmer index must be an integer such as 0, got {}",
            describe(v)
        ))),
    }
}

/// [`summary`] of the scene.
impl std::fmt::Display for SceneHandle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&summary(&self.borrow()))
    }
}

/// The thermal part of a scene's summary: empty at 0 K.
fn thermal_summary(s: &Scene) -> String {
    let th = s.thermal();
    if th.is_on() {
        format!(" at {} K (seed {})", th.temperature, th.seed)
    } else {
        String::new()
    }
}

/// One-line description of a scene (what `print(s)` shows).
pub fn summary(s: &Scene) -> String {
    let backend = match s.backend() {
        Backend::Cpu => String::new(),
        b => format!(", backend = \"{}\"", b.name()),
    };
    let thermal = thermal_summary(s);
    let periodic = s
        .periodic()
        .map(|b| {
            let [x, y, z] = b.sides();
            format!(", box = [{x:e}, {y:e}, {z:e}] m")
        })
        .unwrap_or_default();
    let period = s
        .period()
        .map(|t| format!(", T = {t:.6e} s"))
        .unwrap_or_default();
    format!(
        "Scene({} swimmers, model = \"{}\", mobility = \"{}\", integrator = {}{}, mu = {:e} Pa s, t = {:.6e} s{period}{periodic}{backend}{thermal})",
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
    use crate::engine::build::{box_side, random_suspension_apart, Draw, Orientations, Phases};
    if n < 0 {
        return Err(script_error(format!(
            "add_random: the number of swimmers must be >= 0, got {n}"
        )));
    }
    let in_box = s.borrow().scene().periodic().map(|b| b.sides());
    let phi = match (in_box, phi.is_unit()) {
        (Some(_), false) => {
            return Err(script_error(
                "add_random: the scene has a periodic box, whose volume sets the volume fraction: use s.add_random(d, n, seed) to fill it".to_string(),
            ))
        }
        (None, true) => {
            return Err(script_error(
                "add_random: in open space give a volume fraction, s.add_random(d, n, volume_fraction, seed), or set a box first (s.box = [Lx, Ly, Lz]) and fill it with s.add_random(d, n, seed)".to_string(),
            ))
        }
        (_, true) => 0.0,
        (None, false) => number("add_random: volume fraction", phi)?,
    };
    let mut orientations = Orientations::Random;
    let mut phases = Phases::Random;
    let mut gap = None;
    for (k, v) in opts {
        match k.as_str() {
            "aligned" => orientations = Orientations::Aligned(crate::engine::swimmer::unit_direction(super::convert::vector3("aligned", v)?).map_err(|e| script_error(format!("add_random: aligned: {e}")))?),
            "phase" => phases = Phases::Equal(number("phase", v)?),
            "gap" => gap = Some(number("add_random: gap", v)?),
            other => {
                return Err(script_error(format!(
                    "add_random: unknown option \"{other}\"; use aligned: [x, y, z], phase: number and/or gap: metres"
                )))
            }
        }
    }
    let mut trial = s.borrow().scene().clone();
    let sides = match in_box {
        Some(l) => l,
        None => [lift(box_side(n as usize, &d.params, phi))?; 3],
    };
    lift(random_suspension_apart(
        &mut trial,
        n as usize,
        d.params,
        sides,
        Draw {
            orientations,
            phases,
            seed: seed as u64,
            gap,
        },
    ))?;
    s.replace(trial)
}

/// `s.add_at(d, centres)`: a copy of d (its orientation and phase) at every centre of the array,
/// in order; all or nothing (the scene is unchanged if one does not fit).
fn add_at(s: &mut SceneHandle, d: DumbbellSpec, centres: &Array) -> ScriptResult<INT> {
    // The centres up to the first that is not a point; the swimmers before it are checked
    // first, as adding them one by one would.
    let mut items = Vec::with_capacity(centres.len());
    let mut unreadable = None;
    for (k, c) in centres.iter().enumerate() {
        match super::convert::vector3(&format!("add_at: centre {k}"), c) {
            Ok(c) => items.push((d.params, c, d.dir)),
            Err(e) => {
                unreadable = Some(e);
                break;
            }
        }
    }
    let mut trial = s.borrow().scene().clone();
    trial.add_many(&items).map_err(|(k, e)| {
        script_error(format!(
            "add_at: centre {k}: {}",
            super::convert::engine_message(&e)
        ))
    })?;
    if let Some(e) = unreadable {
        return Err(e);
    }
    s.replace(trial)
}

/// Register the `Scene` type and its methods and properties.
pub fn register(engine: &mut Engine) {
    engine.register_fn("scene", SceneHandle::default);

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
                "add expects a Dumbbell such as dumbbell(#{{ phase: 0.0 }}), got {}",
                describe(&d)
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
    // In a periodic box, whose volume sets the volume fraction.
    engine.register_fn(
        "add_random",
        |s: &mut SceneHandle, d: DumbbellSpec, n: INT, seed: INT| -> ScriptResult<INT> {
            add_random(s, d, n, &Dynamic::UNIT, seed, &rhai::Map::new())
        },
    );
    engine.register_fn(
        "add_random",
        |s: &mut SceneHandle,
         d: DumbbellSpec,
         n: INT,
         seed: INT,
         opts: rhai::Map|
         -> ScriptResult<INT> { add_random(s, d, n, &Dynamic::UNIT, seed, &opts) },
    );

    engine.register_fn(
        "add_at",
        |s: &mut SceneHandle, d: DumbbellSpec, centres: Array| -> ScriptResult<INT> {
            add_at(s, d, &centres)
        },
    );

    // Reading one swimmer.
    engine
        .register_fn(
            "sphere_velocities",
            |s: &mut SceneHandle, forces: Array| -> ScriptResult<Array> {
                let f: Vec<nalgebra::Vector3<f64>> = forces
                    .iter()
                    .enumerate()
                    .map(|(k, v)| super::convert::vector3(&format!("forces[{k}]"), v))
                    .collect::<ScriptResult<_>>()?;
                let v = s.with(|sc| sc.sphere_velocities(&f))?;
                Ok(v.iter().map(|x| Dynamic::from(array3(x))).collect())
            },
        )
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
                        "phases must be an array of numbers, got {}",
                        describe(&v)
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
            SceneHandle::new(s.borrow().scene().clone())
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

    engine.register_fn(
        "diffusion",
        |s: &mut SceneHandle, i: INT| -> ScriptResult<rhai::Map> {
            let i = usize::try_from(i).map_err(|_| {
                super::convert::script_error(format!("swimmer index {i} is negative"))
            })?;
            let d = s.with(|sc| sc.rigid_diffusion(i))?;
            let mut m = rhai::Map::new();
            for (k, v) in [
                ("parallel", d.parallel),
                ("perpendicular", d.perpendicular),
                ("translation", d.translation()),
                ("rotation", d.rotation),
                ("offset", d.offset),
            ] {
                m.insert(k.into(), v.into());
            }
            Ok(m)
        },
    );
}

/// The help text of this file's script names (`:help NAME`), gathered by [`super::docs`].
pub(super) const DOCS: &[Doc] = &[
    doc_entry!("scene", "building", "scene() -> Scene", "An empty scene: no swimmers, mu = 1e-3 Pa s, model \"micro\", mobility \"rpy\", default integrator.", "let s = scene(); print(s);"),
    doc_entry!("add", "building", "s.add(d: Dumbbell) -> int", "Add a swimmer at length L(t) of the scene's time, its hydrodynamic centre at d.center, pointing along d.dir; returns its 0-based index. Refuses overlapping swimmers.", "let s = scene(); let i = s.add(dumbbell()); print(i);"),
    doc_entry!("copy", "building", "s.copy() -> Scene", "An independent copy of the scene (same state, no recorders). `let t = s;` would name the same scene.", "let s = scene(); let t = s.copy(); t.add(dumbbell()); print(s.count);"),
    doc_entry!("phase", "phases", "phase(x) -> float\ns.phase(i) -> float", "phase(x): x radians wrapped to [0, 2 pi). s.phase(i): the stroke phase of swimmer i.", "print(phase(7.0)); let s = scene(); s.add(dumbbell(#{ phase: 1.0 })); print(s.phase(0));"),
    doc_entry!("phases", "phases", "s.phases -> array\ns.phases = [..]", "All stroke phases (rad) in swimmer order; assign one per swimmer.", doc::PAIR_PHASES),
    doc_entry!("set_phase", "phases", "s.set_phase(i, phi)", "Set the stroke phase of swimmer i (rad).", "let s = scene(); s.add(dumbbell()); s.set_phase(0, pi()); print(s.phases);"),
    doc_entry!("add_random", "scene", "s.add_random(d, n, volume_fraction, seed) -> int\ns.add_random(d, n, volume_fraction, seed, #{ aligned: [x, y, z], phase: p }) -> int\ns.add_random(d, n, seed[, opts]) -> int  (in a periodic box)", "Add n copies of dumbbell d at random places in a cube centred on the origin, sized so that all spheres fill the given volume fraction (in a periodic box: the box itself, measured by minimum images), without overlaps (random sequential addition, seeded: the same seed gives the same scene). Above a wall only places clear of it are taken (put the wall below the cube to fill all of it; a wall above the cube, where no centre can be clear of it, is refused). A count that cannot fit is refused before the first draw, naming how many do: each swimmer keeps clear a body of its two spheres widened by half the gap, and random sequential addition fills about 27% (equal spheres far apart) to 35% (overlapping ones) of the space with such bodies within its 100 draws for every body the space holds, where it stops with \"placed only k of n\". Orientations and phases are random unless fixed by the options; gap: m sets the smallest sphere gap at placement (default 4 lambda max(w1, w2), what the strokes can close). Returns the new swimmer count; on failure the scene is unchanged.", "let s = scene(); s.add_random(dumbbell(#{}), 20, 0.01, 1); print(s.count);"),
    doc_entry!("add_at", "scene", "s.add_at(d, centres: array) -> int", "Add a copy of dumbbell d (its orientation and phase) at every centre [x, y, z] (m) of the array, e.g. a lattice from the stdlib module \"lattice\". All or nothing: if one does not fit, the scene is unchanged. Returns the new swimmer count.", "import \"lattice\" as lattice; let s = scene(); s.add_at(dumbbell(), lattice::cubic(2, 2, 2, 20e-6)); print(s.count);"),
    doc_entry!("diffusion", "thermal", "s.diffusion(i) -> map", "Swimmer i's diffusion as a rigid dumbbell of length ell at the scene's temperature and mobility: parallel and perpendicular translation D_par, D_perp (m^2/s), their orientation average translation = (D_par + 2 D_perp)/3 (a centre's mean squared displacement grows as 6 translation t), rotation D_r (1/s), and offset: where along N from R_H translation and rotation decouple (m). All zero at 0 K. The averaged model's noise; for a symmetric dumbbell translation equals kT/(12 pi mu)(1/a + 1/ell).", "let s = scene(); s.add(dumbbell()); s.temperature = 300; print(s.diffusion(0).translation);"),
    doc_entry!("sphere_velocities", "reading", "s.sphere_velocities(forces) -> [[vx, vy, vz], ...]", "Sphere velocities (m/s) for given forces (N): one [fx, fy, fz] per sphere, swimmer by swimmer, the a1 sphere first; the scene's mobility and viscosity at the present sphere positions, Stokes drag included. For checks against other codes; the scene does not move.", "let s = scene(); s.add(dumbbell()); print(s.sphere_velocities([[1e-12, 0, 0], [0, 0, 0]]));"),
    doc_entry!("center", "reading", "s.center(i) -> [x, y, z]", "Hydrodynamic centre R_H of swimmer i (m).", "let s = scene(); s.add(dumbbell()); print(s.center(0));"),
    doc_entry!("dir", "reading", "s.dir(i) -> [x, y, z]", "Unit orientation N of swimmer i (from the a1 sphere to the a2 sphere).", "let s = scene(); s.add(dumbbell(#{ dir: [0, 1, 0] })); print(s.dir(0));"),
    doc_entry!("velocity", "reading", "s.velocity(i) -> [x, y, z]", "dR_H/dt of swimmer i now (m/s).", doc::PAIR_VELOCITY),
    doc_entry!("spin", "reading", "s.spin(i) -> [x, y, z]", "dN/dt of swimmer i now (1/s).", "let s = scene(); s.add(dumbbell()); print(s.spin(0));"),
    doc_entry!("length", "reading", "s.length(i) -> float\nlength(i) -> Observable", "Length |X2 - X1| of swimmer i (m); as a global function, the observable.", "let s = scene(); s.add(dumbbell()); print(s.length(0)); print(length(0));"),
    doc_entry!("swimmer", "reading", "s.swimmer(i) -> Dumbbell", "Parameters and current pose of swimmer i.", "let s = scene(); s.add(dumbbell()); print(s.swimmer(0));"),
    doc_entry!("save", "files", "s.save(path)", "Save the whole scene (swimmers, phases, model, integrator, time, state) as JSON; load_scene reads it back exactly. Recorders are not saved; an adaptive integrator restarts its step-size control after loading.", "let s = scene(); s.add(dumbbell()); s.save(\"out/help/scene.json\"); let t = load_scene(\"out/help/scene.json\"); print(t.count);"),
    doc_entry!("load_scene", "files", "load_scene(path) -> Scene", "A scene saved with s.save(path).", "let s = scene(); s.save(\"out/help/empty.json\"); print(load_scene(\"out/help/empty.json\"));"),
];
