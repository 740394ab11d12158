//! A wall and external forces in scripts: `s.wall`, `s.external_force`, `s.gravity`.

use super::convert::{describe, engine_message, lift, number, script_error, vector3, ScriptResult};
use super::doc::{doc_entry, Doc};
use super::scene_api::SceneHandle;
use crate::engine::forces::Gravity;
use crate::engine::wall::Wall;
use crate::engine::StericLaw;
use rhai::{Dynamic, Engine};

/// The keys a map argument of `what` may hold; the first unknown one is refused with `fix`.
fn check_keys(what: &str, map: &rhai::Map, known: &[&str], fix: &str) -> ScriptResult<()> {
    match map.keys().find(|k| !known.contains(&k.as_str())) {
        Some(k) => Err(script_error(format!(
            "{what}: unknown key \"{k}\" (known: {}); {fix}",
            known.join(", ")
        ))),
        None => Ok(()),
    }
}

/// `s.wall = #{ z[, range, stiffness, law, drift] }` or `()` for none.
fn wall_arg(v: &Dynamic) -> ScriptResult<Option<Wall>> {
    const FIX: &str = "use s.wall = #{ z: 0.0 } (m; optional range and stiffness of its repulsion in m and N/m, law: \"smooth\", drift: false), or s.wall = () for none";
    if v.is_unit() {
        return Ok(None);
    }
    let Some(map) = v.clone().try_cast::<rhai::Map>() else {
        return Err(script_error(format!(
            "s.wall must be a map or (), got {}; {FIX}",
            describe(v)
        )));
    };
    check_keys(
        "s.wall",
        &map,
        &["z", "range", "stiffness", "law", "drift"],
        FIX,
    )?;
    let Some(z) = map.get("z") else {
        return Err(script_error(format!(
            "s.wall needs the height z of the plane; {FIX}"
        )));
    };
    let fixed = |e| script_error(format!("{}; {FIX}", engine_message(&e)));
    let mut wall = Wall::at(number("wall z", z)?).map_err(fixed)?;
    if let Some(r) = map.get("range") {
        wall.range = number("wall range", r)?;
    }
    if let Some(k) = map.get("stiffness") {
        wall.stiffness = number("wall stiffness", k)?;
    }
    if let Some(l) = map.get("law") {
        let name = l.clone().into_immutable_string().map_err(|_| {
            script_error(format!(
                "the wall's law must be a string, got {}; {FIX}",
                describe(l)
            ))
        })?;
        wall.law = lift(StericLaw::parse(&name))?;
    }
    if let Some(d) = map.get("drift") {
        wall.drift = d.as_bool().map_err(|_| {
            script_error(format!(
                "the wall's drift must be true or false, got {}; {FIX}",
                describe(d)
            ))
        })?;
    }
    wall.checked().map(Some).map_err(fixed)
}

/// `s.gravity = #{ g, density, fluid_density }` or `()` for none.
fn gravity_arg(v: &Dynamic) -> ScriptResult<Option<Gravity>> {
    const FIX: &str = "use s.gravity = #{ g: 9.81, density: 1050.0, fluid_density: 1000.0 } (m/s², kg/m³; gravity pulls towards -z), or s.gravity = () for none";
    if v.is_unit() {
        return Ok(None);
    }
    let Some(map) = v.clone().try_cast::<rhai::Map>() else {
        return Err(script_error(format!(
            "s.gravity must be a map or (), got {}; {FIX}",
            describe(v)
        )));
    };
    let keys = ["g", "density", "fluid_density"];
    check_keys("s.gravity", &map, &keys, FIX)?;
    let mut values = [0.0; 3];
    for (value, key) in values.iter_mut().zip(keys) {
        let Some(x) = map.get(key) else {
            return Err(script_error(format!("s.gravity needs {key}; {FIX}")));
        };
        *value = number(&format!("gravity {key}"), x)?;
    }
    let [g, density, fluid_density] = values;
    Gravity {
        g,
        density,
        fluid_density,
    }
    .checked()
    .map(Some)
    .map_err(|e| script_error(format!("{}; {FIX}", engine_message(&e))))
}

fn float_map(entries: &[(&str, Dynamic)]) -> Dynamic {
    let mut m = rhai::Map::new();
    for (k, v) in entries {
        m.insert((*k).into(), v.clone());
    }
    Dynamic::from_map(m)
}

pub(super) fn register(engine: &mut Engine) {
    engine
        .register_get("wall", |s: &mut SceneHandle| match s.borrow().wall() {
            Some(w) => float_map(&[
                ("z", Dynamic::from_float(w.z)),
                ("range", Dynamic::from_float(w.range)),
                ("stiffness", Dynamic::from_float(w.stiffness)),
                ("law", Dynamic::from(w.law.name().to_string())),
                ("drift", Dynamic::from_bool(w.drift)),
            ]),
            None => Dynamic::UNIT,
        })
        .register_set(
            "wall",
            |s: &mut SceneHandle, v: Dynamic| -> ScriptResult<()> {
                let wall = wall_arg(&v)?;
                s.with_mut(|sc| sc.set_wall(wall))
            },
        )
        .register_get("external_force", |s: &mut SceneHandle| {
            let f = s.borrow().external().force;
            Dynamic::from_array(f.iter().map(|&x| Dynamic::from_float(x)).collect())
        })
        .register_set(
            "external_force",
            |s: &mut SceneHandle, v: Dynamic| -> ScriptResult<()> {
                let f = if v.is_unit() {
                    [0.0; 3]
                } else {
                    let f = vector3("s.external_force", &v)?;
                    [f.x, f.y, f.z]
                };
                s.with_mut(|sc| sc.set_external_force(f))
            },
        )
        .register_get("gravity", |s: &mut SceneHandle| {
            match s.borrow().external().gravity {
                Some(g) => float_map(&[
                    ("g", Dynamic::from_float(g.g)),
                    ("density", Dynamic::from_float(g.density)),
                    ("fluid_density", Dynamic::from_float(g.fluid_density)),
                ]),
                None => Dynamic::UNIT,
            }
        })
        .register_set(
            "gravity",
            |s: &mut SceneHandle, v: Dynamic| -> ScriptResult<()> {
                let g = gravity_arg(&v)?;
                s.with_mut(|sc| sc.set_gravity(g))
            },
        );
}

/// The help text of this file's script names (`:help NAME`), gathered by [`super::docs`].
pub(super) const DOCS: &[Doc] = &[
    doc_entry!("wall", "numerics", "s.wall -> map or ()\ns.wall = #{ z[, range, stiffness, law, drift] } | ()", "A no-slip plane wall z = z0 (m) with the fluid above, or () for open space (the default). The sphere models then use the Rotne-Prager-Blake mobility (open space's RPY plus the wall's image system, Swan & Brady 2007, for unequal radii; spheres whose centre comes within one radius of the wall are damped as Balboa Usabiaga et al. 2017 do, so the mobility stays positive definite), and the wall repels spheres whose surface comes within range (m, default 1e-7) of it with force stiffness * (range - gap) (N/m, default 1e-3; law: \"smooth\" as for s.steric). A sphere that touches the wall stops the run and names itself. With thermal noise the drift kT div M is added, so the Boltzmann distribution is the equilibrium (drift: false leaves it out, to show what goes wrong without). Observables wall_gap(), height(i), wall_angle(i). The height, like swimmer centres, may lie at most 1e8 times the smallest sphere radius from the origin (75 m for the paper's swimmers); further is refused, when set or when a run starts. Not with a periodic box, the averaged model or the GPU. Saved with the scene.", "let s = scene(); s.wall = #{ z: 0.0 }; s.add(dumbbell(#{ center: [0.0, 0.0, 5e-6], dir: [1.0, 0.0, 0.0] })); print(s.observe(height(0)));"),
    doc_entry!("external_force", "numerics", "s.external_force -> array\ns.external_force = [fx, fy, fz] | ()", "The same constant force (N) on every sphere, in addition to the springs: swimmers are force-free by default ([0, 0, 0]; () sets that). Together with s.gravity. A force that carries a sphere across the reach of positions (1e8 times the smallest sphere radius) within one stroke period stops the run at its first steps, naming it. Microscopic and rigid-stroke models, CPU only. Saved with the scene.", "let s = scene(); s.external_force = [0.0, 0.0, -1e-14]; print(s.external_force);"),
    doc_entry!("gravity", "numerics", "s.gravity -> map or ()\ns.gravity = #{ g, density, fluid_density } | ()", "Gravity along -z with buoyancy: each sphere of radius a feels (4/3) pi a^3 (density - fluid_density) g downwards (m/s^2, kg/m^3), so dense swimmers sediment onto a wall. () for none (the default). Adds to s.external_force. Microscopic and rigid-stroke models, CPU only. Saved with the scene.", "let s = scene(); s.gravity = #{ g: 9.81, density: 1050.0, fluid_density: 1000.0 }; print(s.gravity.g);"),
];
