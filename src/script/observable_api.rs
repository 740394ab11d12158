//! Observables as script values (type `Observable`), `s.observe(obs)`, triggers (type `Trigger`),
//! and recorders (type `Recorder`): `s.record([...], trigger)`, `.rows`, `.to_csv(path)`.

use super::convert::{index, lift, number, register_display, script_error, vector3, ScriptResult};
use super::scene_api::SceneHandle;
use crate::engine::{Observable, Recorder, Trigger};
use nalgebra::Vector3;
use rhai::{Array, Dynamic, Engine, Map, INT};

/// A script's handle on one recorder of a scene.
#[derive(Debug, Clone)]
pub struct RecorderHandle {
    scene: SceneHandle,
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

fn trigger_of(v: &Dynamic) -> ScriptResult<Trigger> {
    if let Some(t) = v.clone().try_cast::<Trigger>() {
        return Ok(t);
    }
    if v.is_int() || v.is_float() {
        return Ok(Trigger::EveryPeriods(number("record(..., every)", v)?));
    }
    Err(script_error(format!(
        "the trigger must be a number of periods or every_periods(n), every_seconds(t), at_times([..]), at_end(); got {v} ({})",
        v.type_name()
    )))
}

fn observables_of(list: &Array) -> ScriptResult<Vec<Observable>> {
    list.iter()
        .enumerate()
        .map(|(k, o)| {
            o.clone().try_cast::<Observable>().ok_or_else(|| {
                script_error(format!(
                    "record: element {k} is not an observable (got {} ({})); use R_H(0), q(0, 1), polarization(), ...",
                    o,
                    o.type_name()
                ))
            })
        })
        .collect()
}

/// Register observables, triggers and recorders.
pub fn register(engine: &mut Engine) {
    register_display::<Observable>(engine);
    register_display::<Trigger>(engine);
    register_display::<RecorderHandle>(engine);
    engine
        .register_type_with_name::<Observable>("Observable")
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
        .register_fn("nematic", || Observable::Nematic)
        .register_fn("mean_speed", || Observable::MeanSpeed)
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
                lift(s.borrow_mut().measure(&o)).map(value)
            },
        );

    engine
        .register_type_with_name::<Trigger>("Trigger")
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
        .register_type_with_name::<RecorderHandle>("Recorder")
        .register_fn(
            "record",
            |s: &mut SceneHandle, list: Array, every: Dynamic| -> ScriptResult<RecorderHandle> {
                let obs = observables_of(&list)?;
                let trigger = trigger_of(&every)?;
                let id = lift(s.borrow_mut().record(obs, trigger))?;
                Ok(RecorderHandle {
                    scene: s.clone(),
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
                let mut scene = r.scene.borrow_mut();
                lift(
                    scene
                        .recorder_mut(r.id)
                        .and_then(|rec| rec.stream_csv(std::path::Path::new(path))),
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
