//! The continuum theory in scripts: `continuum(s[, opts])` (type `Continuum`), run like a scene
//! (`c.run_periods`, `c.run`), read as the same `Field` values as `s.field`, its linear stability
//! (`c.growth_rates`), prepared states (`c.perturb`), particles drawn from it (`c.sample`), and
//! Fourier modes of either side (`c.mode`, `s.mode`).

use super::convert::{array3, describe, lift, number, script_error, vector3, ScriptResult};
use super::doc::{doc_entry, Doc};
use super::scene_api::{SceneHandle, SweepCount};
use crate::engine::continuum::{
    particle_mode, BaseState, Closure, Continuum, ContinuumSpec, Mode, WholeOption,
};
use crate::engine::fields::{Field, FieldKind};
use rhai::{Array, Dynamic, Engine, Map, INT};
use rustfft::num_complex::Complex64;
use std::sync::{Arc, Mutex, MutexGuard};

/// A continuum shared by the script values that name it.
#[derive(Clone)]
pub struct ContinuumHandle {
    continuum: Arc<Mutex<Continuum>>,
    /// The sweeps whose calls share this continuum now: while any does, it can be read, not
    /// changed.
    shared_by_sweeps: SweepCount,
}

impl ContinuumHandle {
    fn new(c: Continuum) -> Self {
        ContinuumHandle {
            continuum: Arc::new(Mutex::new(c)),
            shared_by_sweeps: SweepCount::default(),
        }
    }

    /// Whether `other` is a handle on the same continuum.
    pub(super) fn is_same_as(&self, other: &ContinuumHandle) -> bool {
        Arc::ptr_eq(&self.continuum, &other.continuum)
    }

    /// The count of sweeps sharing this continuum.
    pub(super) fn sweeps(&self) -> &SweepCount {
        &self.shared_by_sweeps
    }

    /// Read the continuum. A lock poisoned by a panic elsewhere still holds a consistent one
    /// (every change is made whole or not at all), so it is read anyway.
    fn lock(&self) -> MutexGuard<'_, Continuum> {
        self.continuum.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Change the continuum; refused while the calls of a sweep share it: they run at once on
    /// several threads, and changes from them would race (results changing from run to run).
    fn lock_mut(&self) -> ScriptResult<MutexGuard<'_, Continuum>> {
        self.shared_by_sweeps
            .refuse_change("continuum", "let d = c.copy(); d.run_periods(1); ...")?;
        Ok(self.lock())
    }
}

impl std::fmt::Display for ContinuumHandle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let c = self.lock();
        let phases: Vec<String> = c
            .populations()
            .iter()
            .map(|p| format!("{:.4} rad ({} swimmers)", p.phase, p.swimmers))
            .collect();
        let closure = c.closure().map_or(String::new(), |k| {
            format!(
                ", closure D_r {:.4e} 1/s and D_t {:.4e} m²/s (fitted: {})",
                k.rotation, k.translation, k.fitted
            )
        });
        write!(
            f,
            "Continuum(grid {:?}, orientations to degree {}, populations at {}, core {:.3e} m, cutoff {:.3e} m{closure}, t = {:.6e} s)",
            c.grid(),
            c.degree(),
            phases.join(", "),
            c.core(),
            c.cutoff(),
            c.time()
        )
    }
}

const FIX: &str = "use #{ grid: 16 or [nx, ny, nz], orientations: 4, core: metres, width: metres, phases: bins, tol: 1e-6, closure: #{ rotation, translation, fitted } }";

/// A whole-number option of `continuum(s, opts)`: anything but a whole number of 0 or more is
/// refused with what the option accepts (the engine's words, as its own refusals say).
fn whole(what: &str, option: WholeOption, v: &Dynamic) -> ScriptResult<usize> {
    v.as_int()
        .ok()
        .and_then(|n| usize::try_from(n).ok())
        .ok_or_else(|| {
            script_error(format!(
                "{what} takes {}, got {}",
                option.accepts(),
                describe(v)
            ))
        })
}

fn spec(opts: &Map) -> ScriptResult<ContinuumSpec> {
    let mut s = ContinuumSpec::default();
    for (k, v) in opts {
        match k.as_str() {
            "grid" => {
                if v.is_int() {
                    s.grid = [whole("continuum grid", WholeOption::Grid, v)?; 3];
                } else {
                    let arr = v.clone().try_cast::<Array>().filter(|a| a.len() == 3);
                    let Some(arr) = arr else {
                        return Err(script_error(format!(
                            "continuum grid must be a cell count such as 16 or three such as [16, 16, 16] ({}), got {}",
                            WholeOption::Grid.accepts(),
                            describe(v)
                        )));
                    };
                    for (d, x) in arr.iter().enumerate() {
                        s.grid[d] = whole(&format!("continuum grid[{d}]"), WholeOption::Grid, x)?;
                    }
                }
            }
            "orientations" => s.degree = whole("continuum orientations", WholeOption::Degree, v)?,
            "core" => s.core = Some(number("continuum core", v)?),
            "width" => s.width = Some(number("continuum width", v)?),
            "phases" => s.phase_bins = Some(whole("continuum phases", WholeOption::PhaseBins, v)?),
            "tol" => s.tol = number("continuum tol", v)?,
            "closure" => s.closure = Some(closure(v)?),
            other => {
                return Err(script_error(format!(
                    "continuum: unknown option \"{other}\"; {FIX}"
                )))
            }
        }
    }
    Ok(s)
}

const CLOSURE_FIX: &str =
    "use closure: #{ rotation: 1/s, translation: m²/s, fitted: \"where it was measured\" }";

/// `closure: #{ rotation, translation, fitted }`: an effective diffusion measured from particle
/// runs, and where.
fn closure(v: &Dynamic) -> ScriptResult<Closure> {
    let Some(m) = v.clone().try_cast::<Map>() else {
        return Err(script_error(format!(
            "continuum closure must be a map, got {}; {CLOSURE_FIX}",
            describe(v)
        )));
    };
    check_keys(
        "continuum closure",
        &m,
        &["rotation", "translation", "fitted"],
    )?;
    let coefficient = |key: &str| match m.get(key) {
        Some(x) => number(&format!("continuum closure {key}"), x),
        None => Ok(0.0),
    };
    let fitted = match m.get("fitted") {
        Some(f) if f.is_string() => f.clone().into_string().unwrap_or_default(),
        Some(f) => {
            return Err(script_error(format!(
                "continuum closure fitted must be a string saying where the closure was measured, got {}; {CLOSURE_FIX}",
                describe(f)
            )))
        }
        None => String::new(),
    };
    lift(Closure::new(
        coefficient("rotation")?,
        coefficient("translation")?,
        &fitted,
    ))
}

fn build(s: &SceneHandle, opts: &Map) -> ScriptResult<ContinuumHandle> {
    let sp = spec(opts)?;
    let c = s.with(|sc| Continuum::of(sc, &sp))?;
    Ok(ContinuumHandle::new(c))
}

/// Run `c` for `seconds` as a scene runs: stopped by Ctrl-C (or a kernel's interrupt) at a step
/// boundary, with the same progress bar.
fn run(c: &ContinuumHandle, seconds: f64) -> ScriptResult<()> {
    let mut g = c.lock_mut()?;
    let stop = super::interrupt::current();
    g.set_interrupt(Some(Arc::new(move || stop.requested())));
    let (t0, period) = (g.time(), Some(g.period()));
    let r = super::progress::with_bar(&mut *g, t0, seconds, period, Continuum::set_progress, |c| {
        c.run(seconds)
    });
    g.set_interrupt(None);
    lift(r)
}

fn field_kind(name: &str) -> ScriptResult<FieldKind> {
    lift(FieldKind::parse(name))
}

fn population(v: &Dynamic) -> ScriptResult<usize> {
    v.as_int()
        .ok()
        .and_then(|n| usize::try_from(n).ok())
        .ok_or_else(|| {
            script_error(format!(
                "a population index is a whole number from 0 (see c.populations), got {}",
                describe(v)
            ))
        })
}

fn complex_map(v: &[Complex64]) -> Map {
    let mut m = Map::new();
    let re: Array = v.iter().map(|x| Dynamic::from_float(x.re)).collect();
    let im: Array = v.iter().map(|x| Dynamic::from_float(x.im)).collect();
    let abs = v.iter().map(|x| x.norm_sqr()).sum::<f64>().sqrt();
    m.insert("re".into(), re.into());
    m.insert("im".into(), im.into());
    m.insert("abs".into(), abs.into());
    m
}

fn mode_index(v: &Array) -> ScriptResult<[i64; 3]> {
    if v.len() != 3 {
        return Err(script_error(format!(
            "a box mode is three whole numbers such as [1, 0, 0] (k = 2 pi n / L), got {} values",
            v.len()
        )));
    }
    let mut out = [0i64; 3];
    for (d, x) in v.iter().enumerate() {
        out[d] = x.as_int().map_err(|_| {
            script_error(format!(
                "a box mode is three whole numbers such as [1, 0, 0], got {} at [{d}]",
                describe(x)
            ))
        })?;
    }
    Ok(out)
}

/// `#{ state: "isotropic" | "polar", polarization: [x, y, z] }` as a base state.
fn base(opts: &Map) -> ScriptResult<BaseState> {
    let mut state = "isotropic".to_string();
    let mut pol = None;
    for (k, v) in opts {
        match k.as_str() {
            "state" => {
                state = v
                    .clone()
                    .into_immutable_string()
                    .map_err(|_| {
                        script_error(format!(
                            "state must be \"isotropic\" or \"polar\", got {}",
                            describe(v)
                        ))
                    })?
                    .to_string()
            }
            "polarization" => pol = Some(vector3("polarization", v)?),
            _ => {}
        }
    }
    match (state.as_str(), pol) {
        ("isotropic", None) => Ok(BaseState::Isotropic),
        ("isotropic", Some(_)) => Err(script_error(
            "an isotropic state has no polarization; give state: \"polar\" with it",
        )),
        ("polar", Some(p)) => Ok(BaseState::Polar([p.x, p.y, p.z])),
        ("polar", None) => Err(script_error(
            "a polar state needs its polarization P, e.g. #{ state: \"polar\", polarization: [0, 0, 0.3] } (|P| <= 1/3)",
        )),
        (other, _) => Err(super::convert::unknown_choice(
            "state",
            other,
            &["isotropic", "polar"],
        )),
    }
}

fn check_keys(what: &str, opts: &Map, known: &[&str]) -> ScriptResult<()> {
    match opts.keys().find(|k| !known.contains(&k.as_str())) {
        Some(k) => Err(script_error(format!(
            "{what}: unknown key \"{k}\" (known: {})",
            known.join(", ")
        ))),
        None => Ok(()),
    }
}

fn modes_array(modes: &[Mode]) -> Array {
    modes
        .iter()
        .map(|m| {
            let mut r = Map::new();
            r.insert("rate".into(), m.rate.into());
            r.insert("frequency".into(), m.frequency.into());
            r.insert("degree".into(), (m.degree as INT).into());
            r.insert("population".into(), (m.population as INT).into());
            r.into()
        })
        .collect()
}

fn growth_rates(c: &ContinuumHandle, k: &Dynamic, opts: &Map) -> ScriptResult<Array> {
    check_keys("growth_rates", opts, &["state", "polarization"])?;
    let k = vector3("growth_rates: wave vector (1/m)", k)?;
    let b = base(opts)?;
    let modes = lift(c.lock().growth_rates(&b, [k.x, k.y, k.z]))?;
    Ok(modes_array(&modes))
}

fn perturb(c: &ContinuumHandle, opts: &Map) -> ScriptResult<()> {
    check_keys(
        "perturb",
        opts,
        &[
            "state",
            "polarization",
            "shape",
            "axis",
            "mode",
            "amplitude",
            "population",
        ],
    )?;
    let b = base(opts)?;
    let shape = match opts.get("shape") {
        Some(v) => field_kind(&v.clone().into_immutable_string().map_err(|_| {
            script_error(format!(
                "perturb shape must be \"density\", \"polarization\" or \"nematic\", got {}",
                describe(v)
            ))
        })?)?,
        None => FieldKind::Density,
    };
    let axis = match opts.get("axis") {
        Some(v) => vector3("perturb axis", v)?,
        None => nalgebra::Vector3::z(),
    };
    let mode = match opts.get("mode") {
        Some(v) => mode_index(&v.clone().try_cast::<Array>().ok_or_else(|| {
            script_error(format!(
                "perturb mode must be three whole numbers such as [1, 0, 0], got {}",
                describe(v)
            ))
        })?)?,
        None => [1, 0, 0],
    };
    let amplitude = match opts.get("amplitude") {
        Some(v) => number("perturb amplitude", v)?,
        None => 0.01,
    };
    let pop = opts.get("population").map(population).transpose()?;
    lift(
        c.lock_mut()?
            .perturb(&b, shape, [axis.x, axis.y, axis.z], mode, amplitude, pop),
    )
}

fn sample(
    c: &ContinuumHandle,
    s: &SceneHandle,
    n: INT,
    seed: INT,
    opts: &Map,
) -> ScriptResult<INT> {
    check_keys("sample", opts, &["gap"])?;
    let gap = opts
        .get("gap")
        .map(|v| number("sample gap", v))
        .transpose()?;
    let n = usize::try_from(n).map_err(|_| {
        script_error(format!(
            "sample: the number of swimmers must be 0 or more, got {n}"
        ))
    })?;
    let mut trial = s.borrow().scene().clone();
    lift(c.lock().sample(&mut trial, n, seed as u64, gap))?;
    s.replace(trial)
}

fn scene_mode(s: &SceneHandle, kind: &str, mode: &Array, opts: &Map) -> ScriptResult<Map> {
    check_keys("mode", opts, &["phase"])?;
    let k = field_kind(kind)?;
    let m = mode_index(mode)?;
    let phase = opts
        .get("phase")
        .map(|v| number("mode phase", v))
        .transpose()?;
    let v = s.with(|sc| particle_mode(sc, k, m, phase))?;
    Ok(complex_map(&v))
}

fn continuum_mode(
    c: &ContinuumHandle,
    kind: &str,
    mode: &Array,
    p: Option<usize>,
) -> ScriptResult<Map> {
    let k = field_kind(kind)?;
    let m = mode_index(mode)?;
    let v = lift(c.lock().mode(k, p, m))?;
    Ok(complex_map(&v))
}

fn continuum_field(c: &ContinuumHandle, kind: &str, p: Option<usize>) -> ScriptResult<Field> {
    let k = field_kind(kind)?;
    lift(c.lock().field(k, p))
}

/// Register `Continuum` and its functions, and `s.mode`.
pub fn register(engine: &mut Engine) {
    engine
        .register_fn("continuum", |s: &mut SceneHandle| build(s, &Map::new()))
        .register_fn("continuum", |s: &mut SceneHandle, o: Map| build(s, &o))
        .register_fn("run_periods", |c: &mut ContinuumHandle, n: Dynamic| {
            let n = number("run_periods(n)", &n)?;
            let t = c.lock().period();
            run(c, n * t)
        })
        .register_fn("run", |c: &mut ContinuumHandle, t: Dynamic| {
            run(c, number("run(seconds)", &t)?)
        })
        .register_get("time", |c: &mut ContinuumHandle| c.lock().time())
        .register_fn("copy", |c: &mut ContinuumHandle| {
            ContinuumHandle::new(c.lock().clone())
        })
        .register_get("stats", |c: &mut ContinuumHandle| {
            let st = *c.lock().stats();
            let mut m = Map::new();
            m.insert("steps".into(), (st.steps as INT).into());
            m.insert("rejected".into(), (st.rejected as INT).into());
            m.insert("rhs_evals".into(), (st.rhs_evals as INT).into());
            m
        })
        .register_get("populations", |c: &mut ContinuumHandle| -> Array {
            c.lock()
                .populations()
                .iter()
                .map(|p| {
                    let mut m = Map::new();
                    m.insert("phase".into(), p.phase.into());
                    m.insert("swimmers".into(), (p.swimmers as INT).into());
                    m.into()
                })
                .collect()
        })
        .register_fn("counts", |c: &mut ContinuumHandle| -> Array {
            c.lock()
                .counts()
                .into_iter()
                .map(Dynamic::from_float)
                .collect()
        })
        .register_fn("field", |c: &mut ContinuumHandle, k: &str| {
            continuum_field(c, k, None)
        })
        .register_fn("field", |c: &mut ContinuumHandle, k: &str, p: INT| {
            continuum_field(c, k, Some(population(&Dynamic::from_int(p))?))
        })
        .register_fn("mode", |c: &mut ContinuumHandle, k: &str, m: Array| {
            continuum_mode(c, k, &m, None)
        })
        .register_fn(
            "mode",
            |c: &mut ContinuumHandle, k: &str, m: Array, p: INT| {
                continuum_mode(c, k, &m, Some(population(&Dynamic::from_int(p))?))
            },
        )
        .register_fn("mode", |s: &mut SceneHandle, k: &str, m: Array| {
            scene_mode(s, k, &m, &Map::new())
        })
        .register_fn("mode", |s: &mut SceneHandle, k: &str, m: Array, o: Map| {
            scene_mode(s, k, &m, &o)
        })
        .register_fn(
            "wave_vector",
            |c: &mut ContinuumHandle, m: Array| -> ScriptResult<Array> {
                let m = mode_index(&m)?;
                let l = c.lock().sides();
                let k = nalgebra::Vector3::from_fn(|d, _| {
                    2.0 * std::f64::consts::PI * m[d] as f64 / l[d]
                });
                Ok(array3(&k))
            },
        )
        .register_fn("growth_rates", |c: &mut ContinuumHandle, k: Dynamic| {
            growth_rates(c, &k, &Map::new())
        })
        .register_fn(
            "growth_rates",
            |c: &mut ContinuumHandle, k: Dynamic, o: Map| growth_rates(c, &k, &o),
        )
        .register_fn("perturb", |c: &mut ContinuumHandle, o: Map| perturb(c, &o))
        .register_fn(
            "sample",
            |c: &mut ContinuumHandle, s: SceneHandle, n: INT, seed: INT| {
                sample(c, &s, n, seed, &Map::new())
            },
        )
        .register_fn(
            "sample",
            |c: &mut ContinuumHandle, s: SceneHandle, n: INT, seed: INT, o: Map| {
                sample(c, &s, n, seed, &o)
            },
        );
}

/// A scene of two phase populations in a box, and its continuum (help examples).
const TWO: &str = "let s = scene(); s.model = \"averaged\"; s.box = [60e-6, 60e-6, 60e-6]; s.add_random(dumbbell(), 20, 1, #{ phase: 0.0 }); s.add_random(dumbbell(), 20, 2, #{ phase: pi() / 2.0 }); let c = continuum(s, #{ grid: 8, orientations: 2 });";

/// The help text of this file's script names (`:help NAME`), gathered by [`super::docs`].
pub(super) const DOCS: &[Doc] = &[
    doc_entry!("continuum", "continuum", "continuum(s) -> Continuum\ncontinuum(s, #{ grid, orientations, core, width, phases, tol, closure })\nc.copy() -> Continuum", "The kinetic theory of the averaged model for scene s's swimmers: one distribution f_p(x, n) per phase population in s's periodic box, moved by the mean field that the averaged pair terms (I, J, K, L, s.coefficients) give when summed over the distribution, and by the rigid dumbbells' diffusion when s.temperature > 0. It starts from the swimmers smoothed by a Gaussian of the given width (m; default one cell; from a quarter of the largest cell side to half the box's longest side), as s.field smooths them. Pairs closer than core (m; default one length l; from l/4 up to the cutoff: the pair terms are the leading terms of an expansion in l/D for swimmers far apart, and closer than l/4 they describe no pair the particles have) or beyond s's cutoff (as in the particle runs) are left out. grid: cells per axis (a number or [nx, ny, nz], 4 or more per axis, at most 32768 cells, default 16); orientations: harmonic degree L of the orientation basis (2-8, default 4); phases: bin the phases into this many populations (1-16; default: one per distinct phase, at most 16); tol: the time stepping's tolerance relative to the structure (1e-10 <= tol < 1, default 1e-6); closure: #{ rotation (1/s), translation (m²/s), fitted } adds an effective rotational and isotropic translational diffusion to the thermal one (or gives one at temperature 0): the fluctuations and correlations of a suspension the mean field leaves out, measured from particle runs (e.g. rotational_diffusion and translational_diffusion of an averaged-model suspension), with fitted saying where (required; shown by display(c)). One swimmer kind (equal radii, length, amplitude, omega). Every pair term carries sin(phi_p - phi_q): one population, or phases spread evenly, has no mean-field motion. A continuum runs (c.run_periods(n), c.run(seconds)) up to 1e9 stroke periods, as a scene. c.copy() is an independent copy (same state); `let d = c;` would name the same continuum.", TWO),
    doc_entry!("counts", "continuum", "c.counts() -> array", "The number of swimmers in each population (the integral of its density): conserved by the dynamics to round-off.", "let s = scene(); s.model = \"averaged\"; s.box = [60e-6, 60e-6, 60e-6]; s.add_random(dumbbell(), 20, 1, #{ phase: 0.0 }); s.add_random(dumbbell(), 20, 2, #{ phase: pi() / 2.0 }); let c = continuum(s, #{ grid: 8, orientations: 2 }); print(c.counts());"),
    doc_entry!("populations", "continuum", "c.populations -> array", "The phase populations: #{ phase (rad), swimmers (how many the scene had) } each, in the order fields and modes number them.", "let s = scene(); s.model = \"averaged\"; s.box = [60e-6, 60e-6, 60e-6]; s.add_random(dumbbell(), 20, 1, #{ phase: 0.0 }); s.add_random(dumbbell(), 20, 2, #{ phase: pi() / 2.0 }); let c = continuum(s, #{ grid: 8, orientations: 2 }); print(c.populations);"),
    doc_entry!("mode", "continuum", "c.mode(kind, [nx, ny, nz]) -> map\nc.mode(kind, [nx, ny, nz], population) -> map\ns.mode(kind, [nx, ny, nz]) -> map\ns.mode(kind, [nx, ny, nz], #{ phase }) -> map", "The Fourier amplitude at box wave vector k = 2 pi n / L of the swimmers' density (kind \"density\": sum_j exp(-i k.R_j)), polarization (sum_j N_j exp(-i k.R_j)) or nematic tensor (sum_j (3 N_j N_j - I)/2 exp(-i k.R_j), row by row): the integral of rho, rho Pi or rho Q times exp(-i k.x) for a continuum, the sum over the swimmers (of one phase, if given: one the swimmers have) for a scene, so the two compare directly. #{ re: [...], im: [...], abs }. A continuum holds the modes its grid keeps against aliasing, |n| < cells/3 per axis (|n| <= 1 on 4 cells, 2 on 8, 5 on 16); a scene's modes go to 1e9 per axis (beyond, f64 rounds the phase 2 pi n.x/L by more than 1e-6 rad).", "let s = scene(); s.model = \"averaged\"; s.box = [60e-6, 60e-6, 60e-6]; s.add_random(dumbbell(), 20, 1, #{ phase: 0.0 }); s.add_random(dumbbell(), 20, 2, #{ phase: pi() / 2.0 }); let c = continuum(s, #{ grid: 8, orientations: 2 }); print(s.mode(\"density\", [1, 0, 0]).abs); print(c.mode(\"density\", [1, 0, 0]).abs);"),
    doc_entry!("wave_vector", "continuum", "c.wave_vector([nx, ny, nz]) -> array", "The box wave vector 2 pi n / L (1/m) of mode n.", "let s = scene(); s.model = \"averaged\"; s.box = [60e-6, 60e-6, 60e-6]; s.add_random(dumbbell(), 20, 1, #{ phase: 0.0 }); s.add_random(dumbbell(), 20, 2, #{ phase: pi() / 2.0 }); let c = continuum(s, #{ grid: 8, orientations: 2 }); print(c.wave_vector([1, 0, 0]));"),
    doc_entry!("growth_rates", "continuum", "c.growth_rates(k) -> array\nc.growth_rates(k, #{ state: \"isotropic\" | \"polar\", polarization: [x, y, z] })", "Linear stability of a homogeneous state at each population's mean density: the eigenvalues sigma = rate + i frequency (1/s) of the operator linearised about it at wave vector k (1/m, any, e.g. c.wave_vector([1, 0, 0])), fastest growing first, each #{ rate, frequency, degree (the harmonic with most of the mode: 0 density, 1 polarization, 2 nematic), population }. States: isotropic (default), or polar rho(1 + 3 P.n)/4pi with |P| <= 1/3 (at temperature 0 and without a closure's rotation only: rotational diffusion makes it decay). Both are stationary (neither makes a mean field of its own); the harmonics of degree <= 2 are exact at any orientations >= 2, higher ones are carried along.", "let s = scene(); s.model = \"averaged\"; s.box = [60e-6, 60e-6, 60e-6]; s.add_random(dumbbell(#{ a1: 1.1e-6, a2: 0.56e-6 }), 20, 1, #{ phase: 0.0 }); s.add_random(dumbbell(#{ a1: 1.1e-6, a2: 0.56e-6 }), 20, 2, #{ phase: pi() / 2.0 }); let c = continuum(s, #{ grid: 8, orientations: 2 }); print(c.growth_rates(c.wave_vector([0, 0, 1]), #{ state: \"polar\", polarization: [0, 0, 0.3] })[0]);"),
    doc_entry!("perturb", "continuum", "c.perturb(#{ state, polarization, shape, axis, mode, amplitude, population })", "Set the continuum to a homogeneous state (as growth_rates takes it; default isotropic) at each population's mean density plus a plane wave cos(k.x) at box mode (default [1, 0, 0]; not [0, 0, 0], the mean, which would change the conserved numbers; within the modes the grid keeps, as c.mode) of relative amplitude (default 0.01) in the density (shape \"density\", default), the polarization along axis (\"polarization\": <N> gains amplitude * axis) or the nematic order along axis (\"nematic\": Q gains amplitude * (3 axis axis - I)/2), in one population (an index of c.populations) or all (default). The amplitude keeps f >= 0 everywhere: about the isotropic state |amplitude| <= 1 (density), 1/3 (polarization), 1/5 (nematic); about a polar state less (1 - 3|P| for the density); a larger one is refused with its bound. A refused call leaves the continuum as it was. To prepare a comparison with particles (c.sample).", "let s = scene(); s.model = \"averaged\"; s.box = [60e-6, 60e-6, 60e-6]; s.add_random(dumbbell(), 20, 1, #{ phase: 0.0 }); s.add_random(dumbbell(), 20, 2, #{ phase: pi() / 2.0 }); let c = continuum(s, #{ grid: 8, orientations: 2 }); c.perturb(#{ shape: \"nematic\", axis: [0, 0, 1], amplitude: 0.2 }); print(c.mode(\"nematic\", [1, 0, 0]).abs);"),
    doc_entry!("sample", "continuum", "c.sample(s, n, seed) -> int\nc.sample(s, n, seed, #{ gap })", "Add n swimmers of the continuum's kind to scene s (which has the continuum's box) drawn from its distribution: a population in proportion to its number (with its phase), a cell in proportion to the density there, a place uniform in the cell, an orientation from f at the cell. Draws that would bring spheres closer than gap (as add_random) are drawn again. Returns the new count; all or nothing.", "let s = scene(); s.model = \"averaged\"; s.box = [60e-6, 60e-6, 60e-6]; s.add_random(dumbbell(), 20, 1, #{ phase: 0.0 }); s.add_random(dumbbell(), 20, 2, #{ phase: pi() / 2.0 }); let c = continuum(s, #{ grid: 8, orientations: 2 }); c.perturb(#{ amplitude: 0.5 }); let t = scene(); t.model = \"averaged\"; t.box = [60e-6, 60e-6, 60e-6]; print(c.sample(t, 40, 7));"),
];
