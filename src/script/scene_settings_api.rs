//! A scene's settings in scripts: `s.mu`, the named choices (`s.model`, `s.mobility`, `s.backend`,
//! `s.coefficients`, `s.overlaps`, each read from its engine table), `s.steric`, `s.cutoff`,
//! `s.integrator`, and the read-only `time`, `count`, `period`, `stiff_rate`, `direct_step`,
//! `backend_info`.

use super::convert::{describe, lift, number, script_error, unknown_choice, ScriptResult};
use super::doc::{doc_entry, Doc};
use super::scene_api::SceneHandle;
use crate::engine::choice::{self, Named};
use crate::engine::ewald::EwaldMethod;
use crate::engine::integrators::METHODS;
use crate::engine::thermal::NoiseRoot;
use crate::engine::{
    Backend, Coefficients, IntegratorSpec, Mobility, Model, Scene, Steric, StericBody, StericLaw,
};
use rhai::{Dynamic, Engine, ImmutableString, INT};

fn string_arg(what: &str, v: &Dynamic) -> ScriptResult<String> {
    v.clone()
        .into_immutable_string()
        .map(|s| s.to_string())
        .map_err(|_| script_error(format!("{what} must be a string, got {}", describe(v))))
}

/// `s.steric = #{ range, stiffness[, body] }` (m, N/m, "spheres" or "rods") or `()` for none.
fn steric_arg(v: &Dynamic) -> ScriptResult<Option<Steric>> {
    const FIX: &str = "use s.steric = #{ range: 1e-7, stiffness: 1e-3 } (m, N/m; add body: \"rods\" to keep whole swimmers apart, law: \"smooth\" for a force without a kink), or s.steric = () for none";
    if v.is_unit() {
        return Ok(None);
    }
    let Some(map) = v.clone().try_cast::<rhai::Map>() else {
        return Err(script_error(format!(
            "s.steric must be a map or (), got {}; {FIX}",
            describe(v)
        )));
    };
    let (mut range, mut stiffness, mut body) = (None, None, StericBody::Spheres);
    let mut law = StericLaw::Harmonic;
    for (k, val) in &map {
        match k.as_str() {
            "range" => range = Some(number("steric range", val)?),
            "stiffness" => stiffness = Some(number("steric stiffness", val)?),
            "body" => body = lift(StericBody::parse(&string_arg("steric body", val)?))?,
            "law" => law = lift(StericLaw::parse(&string_arg("steric law", val)?))?,
            other => {
                return Err(script_error(format!(
                    "s.steric: unknown key \"{other}\"; {FIX}"
                )))
            }
        }
    }
    match (range, stiffness) {
        (Some(r), Some(k)) => {
            lift(Steric::new(r, k)).map(|st| Some(st.with_body(body).with_law(law)))
        }
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
                set(s.borrow_mut()?.scene_mut(), value);
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
    register_choice::<EwaldMethod>(
        engine,
        "ewald_method",
        Scene::ewald_method,
        Scene::set_ewald_method,
        any,
    );
    register_choice::<NoiseRoot>(
        engine,
        "noise_root",
        |s| s.thermal().root,
        Scene::set_noise_root,
        any,
    );
    engine
        .register_get("temperature", |s: &mut SceneHandle| {
            s.borrow().thermal().temperature
        })
        .register_set(
            "temperature",
            |s: &mut SceneHandle, v: Dynamic| -> ScriptResult<()> {
                let t = number("temperature", &v)?;
                s.with_mut(|sc| sc.set_temperature(t))
            },
        )
        .register_get("seed", |s: &mut SceneHandle| {
            s.borrow().thermal().seed as INT
        })
        .register_set(
            "seed",
            |s: &mut SceneHandle, v: Dynamic| -> ScriptResult<()> {
                let seed = v
                    .as_int()
                    .ok()
                    .and_then(|i| u64::try_from(i).ok())
                    .ok_or_else(|| {
                        script_error(format!(
                            "seed must be a whole number of 0 or more, got {}; e.g. s.seed = 42",
                            describe(&v)
                        ))
                    })?;
                s.borrow_mut()?.scene_mut().set_seed(seed);
                Ok(())
            },
        )
        .register_get("lanczos_tol", |s: &mut SceneHandle| {
            s.borrow().thermal().lanczos_tol
        })
        .register_set(
            "lanczos_tol",
            |s: &mut SceneHandle, v: Dynamic| -> ScriptResult<()> {
                let tol = number("lanczos_tol", &v)?;
                s.with_mut(|sc| sc.set_lanczos_tol(tol))
            },
        );
    engine
        .register_get("time", |s: &mut SceneHandle| s.borrow().time())
        .register_get("count", |s: &mut SceneHandle| s.borrow().count() as INT)
        .register_get("period", |s: &mut SceneHandle| s.with(|sc| sc.period()))
        .register_get("stiff_rate", |s: &mut SceneHandle| s.borrow().stiff_rate())
        .register_get("direct_step", |s: &mut SceneHandle| {
            s.borrow().default_micro_step()
        })
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
                m.insert("body".into(), Dynamic::from(st.body.name().to_string()));
                m.insert("law".into(), Dynamic::from(st.law.name().to_string()));
                Dynamic::from_map(m)
            }
            None => Dynamic::UNIT,
        })
        .register_set("steric", |s: &mut SceneHandle, v: Dynamic| -> ScriptResult<()> {
            // The value is read before the scene is locked: describing a wrong one (the scene
            // itself, `s.steric = s`) reads the scene, which would wait on this lock for ever.
            let steric = steric_arg(&v)?;
            s.borrow_mut()?.scene_mut().set_steric(steric);
            Ok(())
        })
        .register_get("cutoff", |s: &mut SceneHandle| {
            s.borrow().cutoff().map_or(Dynamic::UNIT, Dynamic::from_float)
        })
        .register_set("cutoff", |s: &mut SceneHandle, v: Dynamic| -> ScriptResult<()> {
            let c = if v.is_unit() { None } else { Some(number("s.cutoff", &v)?) };
            s.with_mut(|sc| sc.set_cutoff(c))
        })
        .register_get("box", |s: &mut SceneHandle| match s.borrow().periodic() {
            Some(b) => Dynamic::from_array(b.sides().iter().map(|&x| Dynamic::from_float(x)).collect()),
            None => Dynamic::UNIT,
        })
        .register_set("box", |s: &mut SceneHandle, v: Dynamic| -> ScriptResult<()> {
            let sides = if v.is_unit() {
                None
            } else {
                let l = super::convert::vector3("s.box", &v)?;
                Some([l.x, l.y, l.z])
            };
            s.with_mut(|sc| sc.set_box(sides))
        })
        .register_get("ewald_tol", |s: &mut SceneHandle| s.borrow().ewald_tol())
        .register_set("ewald_tol", |s: &mut SceneHandle, v: Dynamic| -> ScriptResult<()> {
            let t = if v.is_unit() { None } else { Some(number("s.ewald_tol", &v)?) };
            s.with_mut(|sc| sc.set_ewald_tol(t))
        })
        .register_get("integrator", |s: &mut SceneHandle| s.borrow().integrator())
        .register_get("integrator_info", |s: &mut SceneHandle| {
            super::convert::lift(s.borrow().integrator_info()).map(ImmutableString::from)
        })
        .register_set(
            "integrator",
            |s: &mut SceneHandle, v: Dynamic| -> ScriptResult<()> {
                if let Some(spec) = v.clone().try_cast::<IntegratorSpec>() {
                    s.borrow_mut()?.scene_mut().set_integrator(Some(spec));
                    return Ok(());
                }
                match v.clone().into_immutable_string() {
                    Ok(name) if name == "default" => {
                        s.borrow_mut()?.scene_mut().set_integrator(None);
                        Ok(())
                    }
                    Ok(name) => match METHODS.iter().find(|m| m.name == name.as_str()) {
                        Some(m) => Err(script_error(format!(
                            "s.integrator = \"{name}\": {name} takes {}, {}: use s.integrator = {name}({}), or \"default\"",
                            m.parameter, m.parameter_about, m.parameter
                        ))),
                        None => Err(unknown_choice("integrator", &name, &["default"])),
                    },
                    Err(_) => Err(script_error(format!(
                        "integrator must be {} or \"default\", got {}",
                        super::integrator_api::call_forms(),
                        describe(&v)
                    ))),
                }
            },
        );
}

/// The help text of this file's script names (`:help NAME`), gathered by [`super::docs`].
pub(super) const DOCS: &[Doc] = &[
    doc_entry!("model", "numerics", "s.model -> string\ns.model = \"micro\" | \"rigid\" | \"averaged\"", "The model: \"micro\" (spheres, springs, mobility), \"rigid\" (the same with lengths following L(t) exactly: k0 -> infinity, not stiff) or \"averaged\" (stroke-averaged R_H and N). Switching converts the state.", "let s = scene(); s.add(dumbbell()); s.model = \"averaged\"; print(s.model);"),
    doc_entry!("backend", "numerics", "s.backend -> string\ns.backend = \"cpu\" | \"gpu\" | \"auto\"", "Where the dynamics run: the CPU (default), a GPU through wgpu (Vulkan, Metal, DX12; f64 shaders required; euler, rk4 and adaptive dopri5, micro and averaged models), or \"auto\": the GPU when one is present and the scene is at least as large as the crossover measured on this machine. Results agree to round-off (tested to 1e-12 per step; dopri5 takes the same steps and rejections).", "let s = scene(); s.backend = \"auto\"; print(s.backend);"),
    doc_entry!("backend_info", "numerics", "s.backend_info -> string", "Which backend the next run uses and why (for \"auto\": the measured crossover).", "let s = scene(); print(s.backend_info);"),
    doc_entry!("mobility", "numerics", "s.mobility -> string\ns.mobility = \"rpy\" | \"oseen\"", "Pair mobility of the microscopic model: Rotne-Prager-Yamakawa (default) or Oseen.", "let s = scene(); s.mobility = \"oseen\"; print(s.mobility);"),
    doc_entry!("overlaps", "numerics", "s.overlaps -> string\ns.overlaps = \"stop\" | \"allow\"", "What happens when spheres of different swimmers touch: \"stop\" (default) ends the run with an error naming them; \"allow\" lets them overlap, moved by the RPY tensor for overlapping spheres (Zuk et al. 2014, positive definite; the averaged model, a far-field model, then runs on with its D^-5 terms). A swimmer's own spheres touching always stops the run. CPU only.", "let s = scene(); s.overlaps = \"allow\"; print(s.overlaps);"),
    doc_entry!("steric", "numerics", "s.steric -> map or ()\ns.steric = #{ range, stiffness[, body, law] } | ()", "A soft repulsion between swimmers: force stiffness * (range - gap) (N) when their surface gap is below range (m). Off by default (). law: \"harmonic\" (default) as written; \"smooth\" stiffness * (range - gap)^2 / range, the same force at contact but starting with no kink, which adaptive steps cross far more cheaply (suspensions held in contact by the far field). body: \"spheres\" (default) repels spheres of different swimmers along their line of centres; \"rods\" treats each swimmer as a rod from sphere to sphere, thickened by the radii, so swimmers can neither touch nor pass through each other (the force acts at the rods' closest points, shared by the two spheres; within about 6 degrees of parallel, where closest points jump from end to end, at points drawn smoothly towards the middle of the facing parts). Microscopic model: the forces join the spring forces in the mobility. Rigid-stroke model: the same forces, and the constraint tensions keep each stroke's length against them. Averaged model: each swimmer moves as a free-draining rigid dumbbell of length ell under them. CPU only; one pass per right-hand side through cell lists in large scenes.", "let s = scene(); s.steric = #{ range: 1e-7, stiffness: 1e-3, body: \"rods\" }; print(s.steric.body);"),
    doc_entry!("cutoff", "numerics", "s.cutoff -> float or ()\ns.cutoff = distance | ()", "Far-field cutoff of the averaged model (m): pairs further apart are left out. Off by default () in open space; in a box at most L/2, and 0.476 L when not set (s.box). Each left-out pair's contribution is bounded by 9/64 v0 (28|A_R|(Lambda/ell) xi^3 + 84 c_J xi^4) with xi = ell/cutoff (the book: Suspensions, boxes and fields).", "let s = scene(); s.cutoff = 100e-6; print(s.cutoff);"),
    doc_entry!("box", "numerics", "s.box -> array or ()\ns.box = [Lx, Ly, Lz] | ()", "A periodic box of these sides (m) centred on the origin (-L/2 to L/2), or () for open space (the default). Pairs are measured by their minimum images; the sphere models use the periodic RPY (or Oseen) mobility by Ewald summation (Beenakker 1986, or spectral Ewald for many spheres: s.ewald_method; to s.ewald_tol, no net flow); the averaged model sums pairs within a cutoff of at most L/2 (when s.cutoff is not set, L/2 / 1.05 = 0.476 L: the longest that leaves a suspension's neighbour lists their skin; a cutoff set to L/2 leaves them none, so every right-hand side rebuilds them, and a run says so when it starts). Snapshots, trajectories and fields show positions wrapped into the box; displacements and drift observables follow the unwrapped motion. add_random fills the box (s.add_random(d, n, seed)). Sides, like swimmer centres, may reach 1e8 times the smallest sphere radius (75 m for the paper's swimmers; beyond, f64 no longer resolves the spheres); longer ones are refused. CPU only. Saved with the scene.", "let s = scene(); s.box = [200e-6, 200e-6, 200e-6]; s.add_random(dumbbell(), 20, 1); print(s.box);"),
    doc_entry!("ewald_method", "numerics", "s.ewald_method -> string\ns.ewald_method = \"auto\" | \"beenakker\" | \"spectral\"", "How the box's mobility products are summed for the spring model, the rigid model's tension iteration, s.sphere_velocities and the Lanczos noise root: \"beenakker\" sums over the pairs within a cutoff (through cell lists where it is at most L/2) and over waves through structure factors, both in vector lanes (O(N^1.5) per product at the splitting chosen); \"spectral\" is spectral Ewald (Lindbo & Tornberg 2010, the wave part of Fiore et al.'s positively split Ewald): real-space pairs within a cutoff of at most L/2 through cell lists, the wave part on an FFT grid (O(N log N)); \"auto\" (default) takes Beenakker below 12,000 spheres and spectral from there (the measured crossover, swimlab bench ewald); \"spectral\" chosen for fewer than 175 spheres, where its grid makes every product far costlier, says so on stderr (a note) when a run starts. Both keep s.ewald_tol. Blocks (a few rigid swimmers' eliminated tensions, the dense noise root) are always Beenakker's. Saved with the scene.", "let s = scene(); s.ewald_method = \"spectral\"; print(s.ewald_method);"),
    doc_entry!("ewald_tol", "numerics", "s.ewald_tol -> float\ns.ewald_tol = tol | ()", "Tolerance of the box's Ewald sums, relative to a sphere's Stokes mobility (1e-15 to 1e-2). Both the real-space and the reciprocal sums are cut where their terms fall below it; the splitting is chosen for speed and the result does not depend on it. A run's drift lies within 1-5 tol of the exact sums' (relative; measured by scripts/validate/ewald_tolerance.rhai), so unless one is set it follows the run's integrator: a tenth of its drift tolerance (the default auto(1.1e-5): 1.1e-6; dopri5(rtol), rosw(rtol), stroboscopic(tol) alike), and 1e-10 for fixed steps (euler, rk4, platen, the noisy defaults). Reading it gives the one in use. s.ewald_tol = () follows the integrator again. Saved with the scene when set.", "let s = scene(); print(s.ewald_tol); s.ewald_tol = 1e-12; print(s.ewald_tol); s.ewald_tol = (); s.integrator = rk4(1e-4); print(s.ewald_tol);"),
    doc_entry!("coefficients", "numerics", "s.coefficients -> string\ns.coefficients = \"paper\" | \"leading_order\"", "Coefficients of the averaged model's I and J terms: as published, or the leading-order ones.", "let s = scene(); s.coefficients = \"leading_order\"; print(s.coefficients);"),
    doc_entry!("integrator_info", "numerics", "s.integrator_info -> string", "What the integrator runs on this scene: for auto(tol) the method it chose and why, else the integrator and whether it is the model's default; and, when stroboscopic averaging fell back to direct integration in the last run (its macro steps failing at their shortest length), when, why and for how many periods. Such a run also says so on stderr (a note) as it falls back.", "let s = scene(); s.add(dumbbell()); s.integrator = auto(1e-3); print(s.integrator_info);"),
    doc_entry!("integrator", "numerics", "s.integrator -> Integrator\ns.integrator = euler(dt) | rk4(dt) | dopri5(rtol) | rosw(rtol) | stroboscopic(tol) | auto(tol) | \"default\"", "The time integrator (s.integrator_info says what it runs and why). The default: auto(1.1e-5) for the spring and rigid-stroke models (stroboscopic averaging on runs of 16 periods or more, RK4 or dopri5 directly on shorter ones; RK4 at 0.8/s.stiff_rate on the gpu backend); dopri5(1e-8) for the averaged model, suspension(1e-3) for a suspension of it; with a temperature above 0, euler(dt). \"default\" returns to it.", "let s = scene(); s.add(dumbbell()); print(s.integrator); s.integrator = rk4(5e-6); print(s.integrator);"),
    doc_entry!("temperature", "thermal", "s.temperature -> float\ns.temperature = kelvin", "Temperature (K) of the solvent; 0 (the default) turns thermal noise off and leaves every result as before. Above 0 the spring model's spheres take Brownian steps with covariance 2 kT M dt for the full mobility M (RPY is divergence-free, so no drift term), and the averaged model's swimmers diffuse as rigid dumbbells (s.diffusion(i)). Needs euler(dt) (Euler-Maruyama) or platen(dt) (weak order 2); the default becomes euler at 0.1/s.stiff_rate (spring model) or T/20 (averaged). Not in the rigid-stroke model; CPU only.", "let s = scene(); s.add(dumbbell()); s.temperature = 300; s.run_periods(0.1); print(s.integrator);"),
    doc_entry!("seed", "thermal", "s.seed -> int\ns.seed = n", "Seed of the thermal noise (default 0). The noise of step k is a function of the seed and k alone (Philox4x32-10), so runs are reproducible, independent of the thread count, and a run split in two or saved and loaded between draws the same noise.", "let s = scene(); s.seed = 7; print(s.seed);"),
    doc_entry!("noise_root", "thermal", "s.noise_root -> string\ns.noise_root = \"auto\" | \"cholesky\" | \"lanczos\"", "How the square root of the mobility is applied to the noise: the dense Cholesky factor (exact, O(N^3) a step), the Lanczos iteration on the pair kernel (O(N^2) a product, to s.lanczos_tol), or \"auto\": Cholesky up to 48 spheres, Lanczos above (the crossover measured by examples/noise_roots.rs: 45-50 spheres).", "let s = scene(); s.noise_root = \"lanczos\"; print(s.noise_root);"),
    doc_entry!("lanczos_tol", "thermal", "s.lanczos_tol -> float\ns.lanczos_tol = tol", "Tolerance of the Lanczos square root: it stops when sqrt(M) xi changes by less than tol of its size from one iteration to the next (default 1e-6).", "let s = scene(); s.lanczos_tol = 1e-8; print(s.lanczos_tol);"),
    doc_entry!("mu", "numerics", "s.mu -> float\ns.mu = x", "Viscosity (Pa s).", "let s = scene(); s.mu = 2e-3; print(s.mu);"),
doc_entry!("direct_step", "numerics", "s.direct_step -> float", "The spring model's direct RK4 step (s): 0.8 / s.stiff_rate, at most 1/200 of the shortest period. The default auto(tol) steps at it where it cannot average (and samples with it); the gpu backend's default is rk4 at it. rk4(s.direct_step) runs a scene directly, without averaging.", "let s = scene(); s.add(dumbbell()); s.integrator = rk4(s.direct_step); print(s.integrator);"),
        doc_entry!("stiff_rate", "numerics", "s.stiff_rate -> float", "The largest spring relaxation rate k0 (1/gamma1 + 1/gamma2) (1/s); explicit steps need dt below ~2.8/rate.", "let s = scene(); s.add(dumbbell()); print(s.stiff_rate);"),
    doc_entry!("time", "running", "s.time -> float", "Current time (s).", "let s = scene(); print(s.time);"),
    doc_entry!("period", "running", "s.period -> float", "The common stroke period (s).", "let s = scene(); s.add(dumbbell()); print(s.period);"),
    doc_entry!("count", "running", "s.count -> int", "Number of swimmers.", "let s = scene(); print(s.count);"),
];
