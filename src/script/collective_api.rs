//! Collective observables in scripts: the pair correlation g(r) and its orientational parts
//! (`pair_correlation`, `pair_polar`, `pair_nematic` to record; `s.pair_correlation(bins, r_max)`
//! as a map), the orientation autocorrelation, the origins it and `msd()` are measured from
//! (`s.reset_origins()`), and effective diffusion coefficients with their standard errors from
//! recorded series (`translational_diffusion`, `rotational_diffusion`).

use super::convert::{describe, lift, number, script_error, ScriptResult};
use super::doc::{doc_entry, Doc};
use super::observable_api::RecorderHandle;
use super::scene_api::SceneHandle;
use crate::engine::effective_diffusion::{estimate, Estimate, Series};
use crate::engine::pair_correlation::{self, PairPart};
use crate::engine::{Observable, Scene};
use rhai::{Array, Dynamic, Engine, Map, INT};

fn floats(v: &[f64]) -> Dynamic {
    Dynamic::from_array(v.iter().map(|x| Dynamic::from_float(*x)).collect())
}

/// The observable of one part of g(r), its shells checked (the box is checked when measured).
fn part(part: PairPart, bins: INT, r_max: &Dynamic) -> ScriptResult<Observable> {
    let o = Observable::PairCorrelation {
        bins: usize::try_from(bins).unwrap_or(0),
        r_max: number(&format!("{}(bins, r_max): r_max", part.name()), r_max)?,
        part,
    };
    lift(o.check(&Scene::default())).map(|_| o)
}

/// `s.pair_correlation(bins, r_max)` as a map of arrays.
fn correlation_map(s: &SceneHandle, bins: INT, r_max: &Dynamic) -> ScriptResult<Map> {
    let r_max = number("s.pair_correlation(bins, r_max): r_max", r_max)?;
    let bins = usize::try_from(bins).unwrap_or(0);
    lift(
        Observable::PairCorrelation {
            bins,
            r_max,
            part: PairPart::Density,
        }
        .check(&Scene::default()),
    )?;
    let pc = s.with(|sc| pair_correlation::of_scene(sc, bins, r_max))?;
    let mut m = Map::new();
    m.insert("r".into(), floats(&pc.r));
    m.insert("g".into(), floats(&pc.g));
    m.insert("err".into(), floats(&pc.g_err));
    m.insert("g1".into(), floats(&pc.polar));
    m.insert("g2".into(), floats(&pc.nematic));
    m.insert("pairs".into(), floats(&pc.pairs));
    m.insert("ideal".into(), floats(&pc.ideal));
    Ok(m)
}

/// An array of numbers as f64s.
fn numbers(what: &str, a: &Array) -> ScriptResult<Vec<f64>> {
    a.iter()
        .enumerate()
        .map(|(k, v)| number(&format!("{what}[{k}]"), v))
        .collect()
}

/// The window and blocks of an estimate, and the one option of its kind (`dims` or `order`).
struct Window {
    from: Option<f64>,
    to: Option<f64>,
    blocks: Option<usize>,
    kind: Option<INT>,
}

fn window(call: &str, kind: &str, opts: &Map) -> ScriptResult<Window> {
    let mut w = Window {
        from: None,
        to: None,
        blocks: None,
        kind: None,
    };
    let whole = |k: &str, v: &Dynamic| {
        v.as_int().map_err(|_| {
            script_error(format!(
                "{call}: {k} must be a whole number, got {}",
                describe(v)
            ))
        })
    };
    for (k, v) in opts {
        match k.as_str() {
            "from" => w.from = Some(number(&format!("{call}: from"), v)?),
            "to" => w.to = Some(number(&format!("{call}: to"), v)?),
            "blocks" => w.blocks = Some(usize::try_from(whole(k, v)?).unwrap_or(0)),
            name if name == kind => w.kind = Some(whole(k, v)?),
            other => {
                return Err(script_error(format!(
                    "{call}: unknown option \"{other}\"; use #{{ from: s, to: s, blocks: n, {kind}: n }}"
                )))
            }
        }
    }
    Ok(w)
}

/// An estimate as the map scripts get: the coefficient under `name`, its error and the blocks.
fn estimate_map(name: &str, e: Estimate) -> Map {
    let mut m = Map::new();
    m.insert(name.into(), Dynamic::from_float(e.value));
    m.insert("err".into(), Dynamic::from_float(e.error));
    m.insert("blocks".into(), Dynamic::from_int(e.slopes.len() as INT));
    m.insert("slopes".into(), floats(&e.slopes));
    m.insert("from".into(), Dynamic::from_float(e.from));
    m.insert("to".into(), Dynamic::from_float(e.to));
    m
}

fn translational(times: &[f64], msd: &[f64], opts: &Map) -> ScriptResult<Map> {
    let w = window("translational_diffusion", "dims", opts)?;
    let dims = usize::try_from(w.kind.unwrap_or(3)).unwrap_or(0);
    let e = lift(estimate(
        times,
        msd,
        Series::Msd { dims },
        w.from,
        w.to,
        w.blocks,
    ))?;
    Ok(estimate_map("D", e))
}

fn rotational(times: &[f64], c: &[f64], order: INT, w: &Window) -> ScriptResult<Map> {
    let order = u8::try_from(order).unwrap_or(0);
    let e = lift(estimate(
        times,
        c,
        Series::Orientation { order },
        w.from,
        w.to,
        w.blocks,
    ))?;
    Ok(estimate_map("D_r", e))
}

/// The recorder's `time` column and its column `name`.
fn recorded(r: &RecorderHandle, name: &str, fix: &str) -> ScriptResult<(Vec<f64>, Vec<f64>)> {
    r.with(|rec| {
        let cols = rec.columns();
        let k = cols.iter().position(|c| c == name).ok_or_else(|| {
            script_error(format!(
                "the recorder has no column \"{name}\" (it has {}); {fix}",
                cols.join(", ")
            ))
        })?;
        Ok(rec.rows.iter().map(|row| (row[0], row[k])).unzip())
    })?
}

/// Register the collective observables and estimators.
pub fn register(engine: &mut Engine) {
    for (name, p) in [
        ("pair_correlation", PairPart::Density),
        ("pair_polar", PairPart::Polar),
        ("pair_nematic", PairPart::Nematic),
    ] {
        engine.register_fn(
            name,
            move |bins: INT, r_max: Dynamic| -> ScriptResult<Observable> { part(p, bins, &r_max) },
        );
    }
    engine
        .register_fn(
            "pair_correlation",
            |s: &mut SceneHandle, bins: INT, r_max: Dynamic| -> ScriptResult<Map> {
                correlation_map(s, bins, &r_max)
            },
        )
        .register_fn("orientation_autocorrelation", || {
            Observable::OrientationAutocorrelation(1)
        })
        .register_fn(
            "orientation_autocorrelation",
            |l: INT| -> ScriptResult<Observable> {
                let o = Observable::OrientationAutocorrelation(u8::try_from(l).unwrap_or(0));
                lift(o.check(&Scene::default())).map(|_| o)
            },
        )
        .register_fn("reset_origins", |s: &mut SceneHandle| -> ScriptResult<()> {
            s.with_mut(|sc| {
                sc.reset_origins();
                Ok(())
            })
        });

    const MSD_FIX: &str = "record msd() with the times, e.g. s.record([msd()], 1)";
    const C_FIX: &str =
        "record orientation_autocorrelation() with the times, e.g. s.record([orientation_autocorrelation()], 1)";
    engine
        .register_fn(
            "translational_diffusion",
            |t: Array, v: Array| -> ScriptResult<Map> {
                translational(&numbers("times", &t)?, &numbers("values", &v)?, &Map::new())
            },
        )
        .register_fn(
            "translational_diffusion",
            |t: Array, v: Array, opts: Map| -> ScriptResult<Map> {
                translational(&numbers("times", &t)?, &numbers("values", &v)?, &opts)
            },
        )
        .register_fn(
            "translational_diffusion",
            |r: &mut RecorderHandle| -> ScriptResult<Map> {
                let (t, v) = recorded(r, "msd", MSD_FIX)?;
                translational(&t, &v, &Map::new())
            },
        )
        .register_fn(
            "translational_diffusion",
            |r: &mut RecorderHandle, opts: Map| -> ScriptResult<Map> {
                let (t, v) = recorded(r, "msd", MSD_FIX)?;
                translational(&t, &v, &opts)
            },
        );
    let rotational_of = |r: &RecorderHandle, opts: &Map| -> ScriptResult<Map> {
        let w = window("rotational_diffusion", "order", opts)?;
        let order = match w.kind {
            Some(l) => l,
            None if r.with(|rec| rec.columns().iter().any(|c| c == "C1"))? => 1,
            None => 2,
        };
        let (t, c) = recorded(r, &format!("C{order}"), C_FIX)?;
        rotational(&t, &c, order, &w)
    };
    engine
        .register_fn(
            "rotational_diffusion",
            |t: Array, v: Array| -> ScriptResult<Map> {
                let w = window("rotational_diffusion", "order", &Map::new())?;
                rotational(&numbers("times", &t)?, &numbers("values", &v)?, 1, &w)
            },
        )
        .register_fn(
            "rotational_diffusion",
            |t: Array, v: Array, opts: Map| -> ScriptResult<Map> {
                let w = window("rotational_diffusion", "order", &opts)?;
                let order = w.kind.unwrap_or(1);
                rotational(&numbers("times", &t)?, &numbers("values", &v)?, order, &w)
            },
        )
        .register_fn(
            "rotational_diffusion",
            move |r: &mut RecorderHandle| -> ScriptResult<Map> { rotational_of(r, &Map::new()) },
        )
        .register_fn(
            "rotational_diffusion",
            move |r: &mut RecorderHandle, opts: Map| -> ScriptResult<Map> {
                rotational_of(r, &opts)
            },
        );
}

const PAIRS_EXAMPLE: &str = "let s = scene(); s.box = [100e-6, 100e-6, 100e-6]; s.add_random(dumbbell(), 40, 1); let g = s.pair_correlation(10, 50e-6); print(g.g); print(g.g1);";
const BROWNIAN_EXAMPLE: &str = "let s = scene(); s.model = \"averaged\"; for k in 0..8 { s.add(dumbbell(#{ center: [k * 30e-6, 0, 0], phase: 0.0 })); } s.temperature = 300; let rec = s.record([msd(), orientation_autocorrelation()], 1); s.run_periods(10); print(translational_diffusion(rec)); print(rotational_diffusion(rec));";

/// The help text of this file's script names (`:help NAME`), gathered by [`super::docs`].
pub(super) const DOCS: &[Doc] = &[
    doc_entry!("pair_correlation", "collective", "pair_correlation(bins, r_max) -> Observable\ns.pair_correlation(bins, r_max) -> map", "The pair correlation g(r) of the hydrodynamic centres R_H in the periodic box, in bins shells of width r_max/bins (r_max at most half the box's shortest side: beyond it the minimum-image shells are cut by the box). g = pairs in the shell / the ideal gas's expected count N(N-1)/2 * V_shell/V, so uniform independent centres give 1 (N - 1: no self pair). As an observable it is recorded as columns g[0], g[1], ...; s.pair_correlation(bins, r_max) gives #{ r: shell centres (m), g, err: the ideal-gas (Poisson) standard error sqrt(pairs)/ideal of this one configuration, g1, g2 (see pair_polar, pair_nematic), pairs, ideal }. Needs a box (open space and a wall have no volume to normalise by: pair_distances gives the raw counts there) and two swimmers. Average g over recorded rows or runs for smooth curves.", PAIRS_EXAMPLE),
    doc_entry!("pair_polar", "collective", "pair_polar(bins, r_max) -> Observable", "g1(r) = <N_i . N_j> over the pairs whose centres lie in each shell of pair_correlation (minimum images in the box): polar order between neighbours at distance r, 1 for parallel, -1 for antiparallel, 0 for independent orientations; 0 in a shell without pairs (where g is 0). Recorded as columns g1[0], g1[1], ...; to average over rows weight each by its g (sum g*g1 / sum g).", "let s = scene(); s.box = [100e-6, 100e-6, 100e-6]; s.add_random(dumbbell(), 40, 1); print(s.observe(pair_polar(5, 50e-6)));"),
    doc_entry!("pair_nematic", "collective", "pair_nematic(bins, r_max) -> Observable", "g2(r) = <P2(N_i . N_j)> = <3 (N_i . N_j)^2 - 1>/2 over the pairs in each shell of pair_correlation: nematic order between neighbours at distance r, 1 for parallel or antiparallel, -1/2 for perpendicular, 0 for independent orientations; 0 in a shell without pairs. Recorded as columns g2[0], g2[1], ...", "let s = scene(); s.box = [100e-6, 100e-6, 100e-6]; s.add_random(dumbbell(), 40, 1); print(s.observe(pair_nematic(5, 50e-6)));"),
    doc_entry!("orientation_autocorrelation", "collective", "orientation_autocorrelation() -> Observable\norientation_autocorrelation(l) -> Observable", "The orientation autocorrelation averaged over the swimmers since each one's origin (its placement, or the last s.reset_origins(), as msd()): l = 1 (default) C1 = <N(t) . N(t0)>, l = 2 C2 = <P2(N(t) . N(t0))>, columns C1, C2. Free rotational diffusion gives C_l = exp(-l(l+1) D_r t): C1 = exp(-2 D_r t) with D_r from s.diffusion(i).rotation; rotational_diffusion(rec) fits it. Refused without swimmers.", "let s = scene(); s.add(dumbbell()); s.temperature = 300; s.model = \"averaged\"; s.run_periods(2); print(s.observe(orientation_autocorrelation()));"),
    doc_entry!("reset_origins", "collective", "s.reset_origins()", "Measure msd() and orientation_autocorrelation() from every swimmer's state now, as if all were placed now (a transient left out). Saved with the scene.", "let s = scene(); s.add(dumbbell()); s.run_periods(1); s.reset_origins(); print(s.observe(msd()));"),
    doc_entry!("translational_diffusion", "collective", "translational_diffusion(rec[, opts]) -> map\ntranslational_diffusion(times, msd[, opts]) -> map", "The effective translational diffusion D (m^2/s) from a mean squared displacement, MSD = 2 dims D t, with its standard error: the rows with from <= t <= to (default all) are cut into blocks (default 10, or one row interval each when fewer) of equal row counts, each gives the slope dMSD / (2 dims dt), and D is their mean with error sd/sqrt(blocks). A slope needs no t0, so a ballistic start before the window drops out. The error holds when the block slopes are uncorrelated: exactly for free diffusion, for swimmers once blocks are longer than the persistence time 1/(2 D_r). A recorder gives its time and msd columns. opts: #{ from: s, to: s, blocks: n, dims: 3 }. Returns #{ D, err, blocks, slopes, from, to }.", BROWNIAN_EXAMPLE),
    doc_entry!("rotational_diffusion", "collective", "rotational_diffusion(rec[, opts]) -> map\nrotational_diffusion(times, C[, opts]) -> map", "The effective rotational diffusion D_r (1/s) from an orientation autocorrelation C_l = exp(-l(l+1) D_r t), with its standard error: blocks of the window as translational_diffusion, each giving -d ln C / (l(l+1) dt), D_r their mean with error sd/sqrt(blocks). End the window while C is well above its noise (C near 0 has no logarithm: refused). A recorder gives its time and C1 column (C2 when it has no C1). opts: #{ from: s, to: s, blocks: n, order: 1 | 2 }. Returns #{ D_r, err, blocks, slopes, from, to }.", BROWNIAN_EXAMPLE),
];
