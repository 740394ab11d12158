//! Observables as script values (type `Observable`), `s.observe(obs)`, triggers (type `Trigger`),
//! and recorders (type `Recorder`): `s.record([...], trigger)`, `.rows`, `.to_csv(path)`.

use super::convert::{describe, index, lift, number, script_error, vector3, ScriptResult};
use super::doc::{self, doc_entry, Doc};
use super::scene_api::SceneHandle;
use crate::engine::{Observable, Recorder, Trigger};
use nalgebra::Vector3;
use rhai::{Array, Dynamic, Engine, ImmutableString, Map, INT};

/// A script's handle on one recorder of a scene.
#[derive(Debug, Clone)]
pub struct RecorderHandle {
    /// Its scene, through a handle that does not keep the scene's live view up.
    pub(super) scene: SceneHandle,
    id: usize,
}

/// One line: `Recorder(3 rows of R_H[0].x, ..., every 0.5 periods)`.
impl std::fmt::Display for RecorderHandle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.describe())
    }
}

impl RecorderHandle {
    fn describe(&self) -> String {
        self.with(|rec| {
            format!(
                "Recorder({} rows of {}, {})",
                rec.rows.len(),
                rec.columns()[1..].join(", "),
                rec.trigger.describe()
            )
        })
        .unwrap_or_else(|e| e.to_string())
    }

    pub(crate) fn with<T>(&self, f: impl FnOnce(&Recorder) -> T) -> ScriptResult<T> {
        let s = self.scene.borrow();
        lift(s.recorder(self.id)).map(f)
    }
}

fn value(v: Vec<f64>) -> Dynamic {
    if v.len() == 1 {
        Dynamic::from_float(v[0])
    } else {
        Dynamic::from_array(v.into_iter().map(Dynamic::from_float).collect())
    }
}

fn axis(v: &Dynamic) -> ScriptResult<Vector3<f64>> {
    let a = vector3("axis", v)?;
    let n = a.norm();
    if !(n > 0.0 && n.is_finite()) {
        return Err(script_error(
            "axis must be a non-zero vector such as [1, 0, 0]",
        ));
    }
    Ok(a / n)
}

pub(super) fn trigger_of(v: &Dynamic) -> ScriptResult<Trigger> {
    if let Some(t) = v.clone().try_cast::<Trigger>() {
        return Ok(t);
    }
    if v.is_int() || v.is_float() {
        return Ok(Trigger::EveryPeriods(number("record(..., every)", v)?));
    }
    Err(script_error(format!(
        "the trigger must be a number of periods or every_periods(n), every_seconds(t), at_times([..]), at_end(); got {}",
        describe(v)
    )))
}

fn observables_of(list: &Array) -> ScriptResult<Vec<Observable>> {
    list.iter()
        .enumerate()
        .map(|(k, o)| {
            o.clone().try_cast::<Observable>().ok_or_else(|| {
                script_error(format!(
                    "record: element {k} is not an observable (got {}); use R_H(0), q(0, 1), polarization(), ...",
                    describe(o)
                ))
            })
        })
        .collect()
}

/// Register observables, triggers and recorders.
pub fn register(engine: &mut Engine) {
    engine
        .register_get("name", |o: &mut Observable| o.name())
        .register_get("unit", |o: &mut Observable| o.unit().to_string());

    macro_rules! one {
        ($name:literal, $variant:ident) => {
            engine.register_fn($name, |i: INT| -> ScriptResult<Observable> {
                Ok(Observable::$variant(index(i)?))
            });
        };
    }
    one!("R_H", CenterH);
    one!("R_G", CenterG);
    one!("N", Dir);
    one!("length", Length);
    one!("tension", Tension);
    macro_rules! two {
        ($name:literal, $variant:ident) => {
            engine.register_fn($name, |i: INT, j: INT| -> ScriptResult<Observable> {
                Ok(Observable::$variant(index(i)?, index(j)?))
            });
        };
    }
    two!("q", Q);
    two!("D_H", DistanceH);
    two!("delta_q", DeltaQ);
    two!("delta_D_H", DeltaDistanceH);
    two!("peclet", Peclet);
    engine
        .register_fn("pair_mean", |i: INT, j: INT| -> ScriptResult<Observable> {
            Ok(Observable::PairMean(index(i)?, index(j)?, Vector3::x()))
        })
        .register_fn(
            "pair_mean",
            |i: INT, j: INT, a: Dynamic| -> ScriptResult<Observable> {
                Ok(Observable::PairMean(index(i)?, index(j)?, axis(&a)?))
            },
        )
        .register_fn(
            "pair_separation",
            |i: INT, j: INT| -> ScriptResult<Observable> {
                Ok(Observable::PairSeparation(
                    index(i)?,
                    index(j)?,
                    Vector3::x(),
                ))
            },
        )
        .register_fn(
            "pair_separation",
            |i: INT, j: INT, a: Dynamic| -> ScriptResult<Observable> {
                Ok(Observable::PairSeparation(index(i)?, index(j)?, axis(&a)?))
            },
        )
        .register_fn("polarization", || Observable::Polarization)
        .register_fn("min_gap", || Observable::MinGap)
        .register_fn("wall_gap", || Observable::WallGap)
        .register_fn("height", |i: INT| -> ScriptResult<Observable> {
            Ok(Observable::Height(index(i)?))
        })
        .register_fn("wall_angle", |i: INT| -> ScriptResult<Observable> {
            Ok(Observable::WallAngle(index(i)?))
        })
        .register_fn("nematic", || Observable::Nematic)
        .register_fn("mean_speed", || Observable::MeanSpeed)
        .register_fn("msd", || Observable::Msd)
        .register_fn(
            "pair_distances",
            |bins: INT, r_max: Dynamic| -> ScriptResult<Observable> {
                let o = Observable::PairDistances {
                    bins: usize::try_from(bins).unwrap_or(0),
                    r_max: number("pair_distances(bins, r_max): r_max", &r_max)?,
                };
                lift(o.check(&crate::engine::Scene::default())).map(|_| o)
            },
        )
        .register_fn(
            "observe",
            |s: &mut SceneHandle, o: Observable| -> ScriptResult<Dynamic> {
                lift(s.borrow_to_measure().measure(&o)).map(value)
            },
        );

    engine
        .register_fn("every_periods", |n: Dynamic| -> ScriptResult<Trigger> {
            let t = Trigger::EveryPeriods(number("every_periods(n): n", &n)?);
            lift(t.validate()).map(|_| t)
        })
        .register_fn("every_seconds", |x: Dynamic| -> ScriptResult<Trigger> {
            let t = Trigger::EverySeconds(number("every_seconds(t): t", &x)?);
            lift(t.validate()).map(|_| t)
        })
        .register_fn("at_times", |ts: Array| -> ScriptResult<Trigger> {
            let times = ts
                .iter()
                .enumerate()
                .map(|(k, t)| number(&format!("at_times: element {k}"), t))
                .collect::<ScriptResult<Vec<f64>>>()?;
            let t = Trigger::AtTimes(times);
            lift(t.validate()).map(|_| t)
        })
        .register_fn("at_end", || Trigger::AtEnd);

    engine
        .register_fn(
            "record",
            |s: &mut SceneHandle, list: Array, every: Dynamic| -> ScriptResult<RecorderHandle> {
                let obs = observables_of(&list)?;
                let trigger = trigger_of(&every)?;
                let id = lift(s.borrow_mut()?.record(obs, trigger))?;
                Ok(RecorderHandle {
                    scene: s.without_view(),
                    id,
                })
            },
        )
        .register_fn(
            "trajectory",
            |s: &mut SceneHandle,
             path: ImmutableString,
             every: Dynamic|
             -> ScriptResult<RecorderHandle> {
                let trigger = trigger_of(&every)?;
                let id = lift(
                    s.borrow_mut()?
                        .trajectory(std::path::Path::new(path.as_str()), trigger),
                )?;
                Ok(RecorderHandle {
                    scene: s.without_view(),
                    id,
                })
            },
        )
        .register_get("len", |r: &mut RecorderHandle| -> ScriptResult<INT> {
            r.with(|rec| rec.rows.len() as INT)
        })
        .register_get("columns", |r: &mut RecorderHandle| -> ScriptResult<Array> {
            r.with(|rec| rec.columns().into_iter().map(Dynamic::from).collect())
        })
        .register_get("header", |r: &mut RecorderHandle| -> ScriptResult<Array> {
            r.with(|rec| rec.header().into_iter().map(Dynamic::from).collect())
        })
        .register_get("rows", |r: &mut RecorderHandle| -> ScriptResult<Array> {
            let (n, cols) = r.with(|rec| (rec.rows.len(), rec.columns().len()))?;
            super::limits::check_maps("rec.rows", n, cols)?;
            r.with(|rec| {
                let cols = rec.columns();
                rec.rows
                    .iter()
                    .map(|row| {
                        let m: Map = cols
                            .iter()
                            .zip(row)
                            .map(|(c, v)| (c.as_str().into(), Dynamic::from_float(*v)))
                            .collect();
                        Dynamic::from_map(m)
                    })
                    .collect()
            })
        })
        .register_fn(
            "column",
            |r: &mut RecorderHandle, name: &str| -> ScriptResult<Array> {
                let col = r.with(|rec| rec.columns().iter().position(|c| c == name))?;
                let k = col.ok_or_else(|| {
                    script_error(format!(
                        "the recorder has no column \"{name}\"; see rec.columns"
                    ))
                })?;
                let n = r.with(|rec| rec.rows.len())?;
                super::limits::check_array("rec.column(name)", n as f64)?;
                r.with(|rec| {
                    rec.rows
                        .iter()
                        .map(|row| Dynamic::from_float(row[k]))
                        .collect()
                })
            },
        )
        .register_fn(
            "stream_csv",
            |r: &mut RecorderHandle, path: &str| -> ScriptResult<()> {
                lift(
                    r.scene
                        .borrow_mut()?
                        .stream_csv(r.id, std::path::Path::new(path)),
                )
            },
        )
        .register_fn(
            "to_csv",
            |r: &mut RecorderHandle, path: &str| -> ScriptResult<()> {
                r.with(|rec| rec.write_csv(std::path::Path::new(path)))
                    .and_then(lift)
            },
        );
}

/// The help text of this file's script names (`:help NAME`), gathered by [`super::docs`].
pub(super) const DOCS: &[Doc] = &[
    doc_entry!("observe", "observables", "s.observe(obs) -> float | array", "Evaluate an observable now.", "let s = scene(); s.add(dumbbell()); print(s.observe(R_H(0)));"),
    doc_entry!("R_H", "observables", "R_H(i) -> Observable", "Hydrodynamic centre of swimmer i (m).", "print(R_H(0));"),
    doc_entry!("R_G", "observables", "R_G(i) -> Observable", "Geometric centre (X1 + X2)/2 of swimmer i (m).", "print(R_G(0));"),
    doc_entry!("N", "observables", "N(i) -> Observable", "Unit orientation of swimmer i.", "print(N(0));"),
    doc_entry!("tension", "observables", "tension(i) -> Observable", "Spring tension k0 (d - L) of swimmer i (N), microscopic model.", "print(tension(0));"),
    doc_entry!("pair_mean", "observables", "pair_mean(i, j) -> Observable\npair_mean(i, j, axis) -> Observable", "(R_H^i + R_H^j)/2 along axis (default x) (m).", "print(pair_mean(0, 1, [0, 0, 1]));"),
    doc_entry!("pair_separation", "observables", "pair_separation(i, j) -> Observable\npair_separation(i, j, axis) -> Observable", "R_H^j - R_H^i along axis (default x) (m).", "print(pair_separation(0, 1));"),
    doc_entry!("q", "observables", "q(i, j) -> Observable", "q = N^i . N^j.", "print(q(0, 1));"),
    doc_entry!("D_H", "observables", "D_H(i, j) -> Observable", "Distance |R_H^i - R_H^j| (m).", "print(D_H(0, 1));"),
    doc_entry!("delta_q", "observables", "delta_q(i, j) -> Observable", "q(0) - q(T) over the next period, measured on a copy (the scene is not advanced).", doc::PAIR_DELTA_Q),
    doc_entry!("delta_D_H", "observables", "delta_D_H(i, j) -> Observable", "[D_H(0) - D_H(T)]/ell over the next period, on a copy; > 0: approaching.", "print(delta_D_H(0, 1));"),
    doc_entry!("mean_speed", "observables", "mean_speed() -> Observable", "Mean swimming speed <|V|> over the swimmers (m/s). Averaged model: V = dR_H/dt. Sphere models: the displacement of R_H over the next period divided by T, measured on a copy of the scene (costs one period per evaluation). Refused without swimmers.", "let s = scene(); s.add(dumbbell()); s.add(dumbbell(#{ center: [20e-6, 0, 0], phase: 1.0 })); s.model = \"averaged\"; print(s.observe(mean_speed()));"),
    doc_entry!("pair_distances", "observables", "pair_distances(bins, r_max) -> Observable", "Histogram of the hydrodynamic-centre distances D_H of all pairs: an array of bins counts, bin k covering [k, k+1) * r_max / bins (m); pairs at r_max or beyond are not counted. Recorded as columns D_H_hist[0], D_H_hist[1], ...", "let s = scene(); s.add_random(dumbbell(#{}), 30, 0.01, 2); print(s.observe(pair_distances(10, 100e-6)));"),
    doc_entry!("polarization", "observables", "polarization() -> Observable", "|<N>| over all swimmers (refused without swimmers: an average over none has no value).", "let s = scene(); s.add(dumbbell()); print(s.observe(polarization()));"),
    doc_entry!("msd", "observables", "msd() -> Observable", "Mean squared displacement of the hydrodynamic centres since each swimmer's origin (its placement, or the last s.reset_origins()), averaged over the swimmers (m^2). With thermal noise it grows as 6 D_t t for free swimmers (s.diffusion(i).translation); translational_diffusion(rec) estimates D with its standard error. Refused without swimmers.", "let s = scene(); s.add(dumbbell()); s.temperature = 300; s.run_periods(0.2); print(s.observe(msd()));"),
    doc_entry!("peclet", "observables", "peclet(i, j) -> Observable", "Peclet number of the pair (i, j): the deterministic drift of its mean position over one period, |V| T, against the rms diffusion of that mean along one axis in the same time, sqrt(2 D T), with D = (D_t^i + D_t^j)/4 (s.diffusion). The drift comes from a noise-free copy run one period with the model's default integrator (the averaged model: its rates now); needs a temperature above 0 (and one at which D does not round to 0 in f64). Swimming beats diffusion after about 1/Pe^2 periods.", "let s = scene(); s.add(dumbbell()); s.add(dumbbell(#{ center: [25e-6, 0, 0], phase: 1.0 })); s.model = \"averaged\"; s.temperature = 300; print(s.observe(peclet(0, 1)));"),
    doc_entry!("min_gap", "observables", "min_gap() -> Observable", "The smallest gap between the surfaces of any two spheres of the scene (m): how close the closest approach is. Through cell lists from 1,024 spheres (all pairs when the scene is too sparse for them to be sure), parallel for large scenes. Refused without swimmers.", "let s = scene(); s.add(dumbbell(#{})); s.add(dumbbell(#{ center: [2e-5, 0.0, 0.0] })); print(s.observe(min_gap()));"),
    doc_entry!("wall_gap", "observables", "wall_gap() -> Observable", "The smallest gap between a sphere's surface and the wall (m). Needs s.wall and a swimmer.", "let s = scene(); s.wall = #{ z: 0.0 }; s.add(dumbbell(#{ center: [0.0, 0.0, 5e-6], dir: [1.0, 0.0, 0.0] })); print(s.observe(wall_gap()));"),
    doc_entry!("height", "observables", "height(i) -> Observable", "Height of swimmer i's hydrodynamic centre R_H above the wall (m). Needs s.wall.", "let s = scene(); s.wall = #{ z: 0.0 }; s.add(dumbbell(#{ center: [0.0, 0.0, 5e-6], dir: [1.0, 0.0, 0.0] })); print(s.observe(height(0)));"),
    doc_entry!("wall_angle", "observables", "wall_angle(i) -> Observable", "Angle of swimmer i's orientation N to the wall's plane (rad, in [-pi/2, pi/2]): positive when N points away from the wall, 0 when parallel to it. Needs s.wall.", "let s = scene(); s.wall = #{ z: 0.0 }; s.add(dumbbell(#{ center: [0.0, 0.0, 5e-6], dir: [1.0, 0.0, 1.0] })); print(s.observe(wall_angle(0)));"),
    doc_entry!("nematic", "observables", "nematic() -> Observable", "Largest eigenvalue of Q = <3NN - I>/2 (refused without swimmers).", "let s = scene(); s.add(dumbbell()); print(s.observe(nematic()));"),
    doc_entry!("record", "recording", "s.record([obs, ...], every) -> Recorder", "Record observables on a trigger: a number (every n periods), every_periods(n), every_seconds(t), at_times([..]) or at_end(). Periodic recorders take a row at once. Only the recorded observables are evaluated, only at their times.", doc::PAIR_RECORD),
    doc_entry!("trajectory", "recording", "s.trajectory(path, every) -> Recorder", "Write the spheres frame by frame as the runs go, on a trigger as s.record takes (a number of periods, every_periods, every_seconds, at_times, at_end), for particle viewers: path.xyz is extended XYZ (ASE, OVITO: one particle per sphere, species a1 or a2 so viewers colour the two kinds apart, positions and radius in um, swimmer index, sphere 1 or 2, the orientation N as dipoles (OVITO's Dipole Orientation, ready for arrows), Z = 0 for ASE, the time in s on each comment line), each frame appended with one write when it is due, so a kill or Ctrl-C loses no frame already written; path.pvd is a ParaView series, one .vtp file per frame in the folder <name>_frames beside it (point arrays radius, swimmer, sphere and N, N the active vectors ParaView's glyphs follow; the length unit as field data) and the .pvd listing them with their times, appended in place (a kill leaves it listing whole frames). One writer per file: a path another trajectory or CSV stream of this session writes is refused (an input that declares the other's scene anew, a cell run again, lets it go). The recorder's rows are the frames' times.", "let s = scene(); s.add(dumbbell()); let t = s.trajectory(\"out/help/pair.xyz\", 0.5); s.run_periods(1); print(t.len);"),
    doc_entry!("every_periods", "recording", "every_periods(n) -> Trigger", "Every n periods from now.", "print(every_periods(2));"),
    doc_entry!("every_seconds", "recording", "every_seconds(t) -> Trigger", "Every t seconds from now.", "print(every_seconds(1e-3));"),
    doc_entry!("at_times", "recording", "at_times([t1, t2, ...]) -> Trigger", "At the given absolute times (s).", "print(at_times([0.01, 0.02]));"),
    doc_entry!("at_end", "recording", "at_end() -> Trigger", "At the end of every run.", "print(at_end());"),
    doc_entry!("rows", "recording", "rec.rows -> array of maps", "The recorded rows, keyed by column name (time, R_H[0].x, ...).", doc::PAIR_ROWS),
    doc_entry!("columns", "recording", "rec.columns -> array\nrec.header -> array\nrec.column(name) -> array", "Column names (without / with units) and one column's values.", doc::PAIR_COLUMNS),
    doc_entry!("stream_csv", "recording", "rec.stream_csv(path)", "From now on append every row to path as CSV the moment it is recorded (one whole line per row, unbuffered; the file starts with the header and the rows so far). A kill or Ctrl-C loses no row already recorded; a write that fails (a full disk) is cut back to the last whole row and stops the run with the error, the rows staying in memory. A path another CSV stream or trajectory of this session writes is refused. A name ending in another format's extension (.png, .svg, .gif, .vti, .vtp, .pvd, .xyz, .json, ...) is refused: CSV text under it would open in no program for that format.", "let s = scene(); s.add(dumbbell()); let r = s.record([R_H(0)], 1); r.stream_csv(\"out/help/stream.csv\"); s.run_periods(2);"),
    doc_entry!("to_csv", "recording", "rec.to_csv(path)", "Write the rows as CSV; the header carries names and units. Folders are created; the file is written whole to a temporary file and renamed, so a crash keeps the old one. A name ending in another format's extension (.png, .svg, .gif, .vti, .vtp, .pvd, .xyz, .json, ...) is refused: CSV text under it would open in no program for that format.", "let s = scene(); s.add(dumbbell()); let r = s.record([R_H(0)], 1); s.run_periods(1); r.to_csv(\"out/help/r.csv\");"),
    doc_entry!("name", "observables", "obs.name -> string\nobs.unit -> string", "An observable's name (its column prefix) and unit.", "print(q(0, 1).name); print(R_H(0).unit);"),
    doc_entry!("unit", "observables", "obs.unit -> string", "An observable's unit (m, N, ell, or 1).", "print(D_H(0, 1).unit);"),
    doc_entry!("len", "recording", "rec.len -> int", "Number of rows recorded.", "let s = scene(); s.add(dumbbell()); let r = s.record([R_H(0)], 1); s.run_periods(2); print(r.len);"),
    doc_entry!("header", "recording", "rec.header -> array", "Column names with units, as written to CSV.", doc::PAIR_COLUMNS),
    doc_entry!("column", "recording", "rec.column(name) -> array", "One column's values.", doc::PAIR_COLUMNS),
];
