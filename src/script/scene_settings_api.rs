//! A scene's settings in scripts: `s.mu`, the named choices (`s.model`, `s.mobility`, `s.backend`,
//! `s.coefficients`, `s.overlaps`, each read from its engine table), `s.steric`, `s.cutoff`,
//! `s.integrator`, and the read-only `time`, `count`, `period`, `stiff_rate`, `backend_info`.

use super::convert::{lift, number, script_error, unknown_choice, ScriptResult};
use super::scene_api::SceneHandle;
use crate::engine::choice::{self, Named};
use crate::engine::integrators::METHODS;
use crate::engine::{Backend, Coefficients, IntegratorSpec, Mobility, Model, Scene, Steric};
use rhai::{Dynamic, Engine, ImmutableString, INT};

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

/// `s.<property>` as a name and `s.<property> = "name"` for a choice of the engine's table;
/// `check` may refuse a value the table holds (the GPU without an adapter).
fn register_choice<T: Named + Send + Sync>(
    engine: &mut Engine,
    property: &'static str,
    get: fn(&Scene) -> T,
    set: fn(&mut Scene, T),
    check: fn(T) -> ScriptResult<()>,
) {
    engine
        .register_get(property, move |s: &mut SceneHandle| {
            ImmutableString::from(choice::name(get(&s.borrow())))
        })
        .register_set(
            property,
            move |s: &mut SceneHandle, v: Dynamic| -> ScriptResult<()> {
                let name = string_arg(property, &v)?;
                let value = lift(choice::parse::<T>(&name))?;
                check(value)?;
                set(s.borrow_mut().scene_mut(), value);
                Ok(())
            },
        );
}

/// `s.backend = "gpu"` needs an f64-capable adapter now, not at the next run.
fn gpu_present(b: Backend) -> ScriptResult<()> {
    if b == Backend::Gpu {
        crate::engine::gpu::device().map_err(|e| {
            script_error(format!(
                "s.backend = \"gpu\": {e}; use s.backend = \"cpu\" or \"auto\""
            ))
        })?;
    }
    Ok(())
}

/// Every value the table holds is accepted.
fn any<T>(_: T) -> ScriptResult<()> {
    Ok(())
}

/// Register the settings of the `Scene` type.
pub fn register(engine: &mut Engine) {
    register_choice::<Model>(engine, "model", Scene::model, Scene::set_model, any);
    register_choice::<Mobility>(
        engine,
        "mobility",
        Scene::mobility,
        Scene::set_mobility,
        any,
    );
    register_choice::<Backend>(
        engine,
        "backend",
        Scene::backend,
        Scene::set_backend,
        gpu_present,
    );
    register_choice::<Coefficients>(
        engine,
        "coefficients",
        Scene::coefficients,
        Scene::set_coefficients,
        any,
    );
    register_choice(
        engine,
        "overlaps",
        |s| s.contacts().overlaps(),
        Scene::set_overlaps,
        any,
    );
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
        .register_get("backend_info", |s: &mut SceneHandle| {
            lift(s.borrow().backend_info()).map(ImmutableString::from)
        })
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
            s.borrow_mut().scene_mut().set_steric(steric_arg(&v)?);
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
                    s.borrow_mut().scene_mut().set_integrator(Some(spec));
                    return Ok(());
                }
                match v.clone().into_immutable_string() {
                    Ok(name) if name == "default" => {
                        s.borrow_mut().scene_mut().set_integrator(None);
                        Ok(())
                    }
                    Ok(name) => match METHODS.iter().find(|m| m.name == name.as_str()) {
                        Some(m) => Err(script_error(format!(
                            "s.integrator = \"{name}\": {name} takes {}, {}: use s.integrator = {name}({}), or \"default\"",
                            m.parameter, m.parameter_about, m.parameter
                        ))),
                        None => Err(unknown_choice("integrator", &name, &["default"])),
                    },
                    Err(t) => Err(script_error(format!(
                        "integrator must be {} or \"default\", got {v} ({t})",
                        super::integrator_api::call_forms()
                    ))),
                }
            },
        );
}
