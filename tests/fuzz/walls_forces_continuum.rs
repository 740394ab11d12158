//! A seeded fuzz of the surfaces added after the first two rounds: walls, external forces and
//! gravity, the rigid-stroke model under load, the continuum theory, and the suspension stepper.
//! A fresh generator (its own templates, values and seed): short scripts of random calls with
//! random, often hostile, arguments, each starting from one of several scenes. Every script must
//! end by itself or stop promptly when interrupted (as Ctrl-C would); no panic may reach the
//! script boundary; no message may show a Rust path; and no value a call returns may hold NaN or
//! infinity (each call's value passes through `fin`, which prints a marker for one that does).

use super::driver::{self, Fuzz};
use crate::common::Rng;

/// Scripts per run: every template is drawn ~20 times; most statements with hostile arguments
/// stop at their first check, so the run stays around a minute on this 2-core machine.
const SCRIPTS: usize = 500;
/// Statements per script.
const STATEMENTS: usize = 6;
/// The seed of the scripts: the same scripts on every machine (`SWIMLAB_FUZZ_SEED`,
/// `SWIMLAB_FUZZ_SCRIPTS` explore others).
const SEED: u64 = 48_2026;

/// Argument values `V`: ordinary, extreme, of the wrong type, and this surface's own.
const VALUES: &[&str] = &[
    "0",
    "1",
    "2",
    "5",
    "-1",
    "0.5",
    "1e-3",
    "1e-6",
    "1e-9",
    "1e-12",
    "1e-30",
    "1e-300",
    "1e300",
    "1e308",
    "-1e100",
    "5e-324",
    "9223372036854775807",
    "-9223372036854775807",
    "(0.0/0.0)",
    "(1.0/0.0)",
    "(-1.0/0.0)",
    "\"\"",
    "\"x\"",
    "\"density\"",
    "\"polarization\"",
    "\"nematic\"",
    "\"micro\"",
    "\"rigid\"",
    "\"averaged\"",
    "\"isotropic\"",
    "\"polar\"",
    "[]",
    "[0, 0, 0]",
    "[1, 0, 0]",
    "[0, 1, 2]",
    "[4, 0, 0]",
    "[100, 0, 0]",
    "[-2, 1, 0]",
    "[0, 0, -1e200]",
    "[0, 0, 1e-12]",
    "[1e308, 0, 0]",
    "[0.5, 0, 0]",
    "#{}",
    "#{ z: -20e-6 }",
    "#{ z: 1e-3 }",
    "#{ z: -1e100 }",
    "#{ g: 9.81, density: 2000, fluid_density: 1000 }",
    "#{ g: 1e300, density: 2000, fluid_density: 1000 }",
    "#{ grid: 4, orientations: 2 }",
    "#{ amplitude: 0.1 }",
    "#{ mode: [1, 0, 0], amplitude: 0.1 }",
    "()",
    "true",
    "s",
    "b",
    "c",
    "d",
    "rk4(1e-6)",
    "rk4(1e-3)",
    "dopri5(1e-6)",
    "suspension(1e-3)",
    "auto(1e-3)",
    "|p| p",
];

/// Call templates: `V` is a value. `s` is the script's scene, `b` a scene in a periodic box with
/// two populations, `c` a continuum of `b`, `d` a dumbbell.
const CALLS: &[&str] = &[
    // Walls.
    "s.wall = V",
    "s.wall = #{ z: V }",
    "s.wall = #{ z: -20e-6, range: V, stiffness: V }",
    "s.wall = #{ z: -20e-6, law: V }",
    "s.wall = #{ z: -20e-6, drift: V }",
    "fin(s.wall)",
    "fin(s.observe(wall_gap()))",
    "fin(s.observe(height(V)))",
    "fin(s.observe(wall_angle(V)))",
    // Forces and gravity.
    "s.external_force = V",
    "s.external_force = [0, 0, V]",
    "s.gravity = V",
    "s.gravity = #{ g: V, density: V, fluid_density: V }",
    "fin(s.external_force)",
    // Models, integrators and runs.
    "s.model = V",
    "s.integrator = V",
    "s.integrator = suspension(V)",
    "s.integrator = rk4(V)",
    "s.run(V)",
    "s.run(1e-4)",
    "s.run_periods(V)",
    "s.run_periods(1)",
    "fin(s.velocity(V))",
    "fin(s.observe(R_H(V)))",
    "fin(s.observe(min_gap()))",
    // Placement.
    "s.add_random(d, V, V)",
    "s.add_random(d, V, V, V)",
    "b.add_random(d, V, V)",
    "s.add(dumbbell(#{ center: V }))",
    // The continuum.
    "continuum(b, V)",
    "continuum(b, #{ grid: V, orientations: 2 })",
    "continuum(b, #{ grid: 4, orientations: V })",
    "continuum(b, #{ grid: 4, orientations: 2, core: V })",
    "continuum(b, #{ grid: 4, orientations: 2, width: V })",
    "continuum(b, #{ grid: 4, orientations: 2, phases: V })",
    "continuum(b, #{ grid: 4, orientations: 2, tol: V })",
    "c.run_periods(V)",
    "c.run(V)",
    "c.perturb(V)",
    "c.perturb(#{ mode: V, amplitude: V })",
    "c.perturb(#{ mode: [1, 0, 0], amplitude: 0.1, population: V })",
    "c.perturb(#{ state: V, polarization: V })",
    "fin(c.mode(V, V))",
    "fin(c.mode(\"density\", V))",
    "fin(c.mode(\"density\", [1, 0, 0], V))",
    "fin(b.mode(\"density\", V))",
    "fin(b.mode(\"nematic\", [1, 0, 0], #{ phase: V }))",
    "fin(c.growth_rates(V))",
    "fin(c.wave_vector(V))",
    "fin(c.counts())",
    "fin(c.populations)",
    "fin(c.time)",
    "c.time = V",
    "c.sample(b, V, V)",
    "c.sample(s, V, 1)",
    "fin(c.field(V).values)",
    "sweep([1, 2], |p| { c.perturb(#{ mode: [1, 0, 0], amplitude: 0.01 * p }); 1 })",
    "sweep([1, 2], |p| { b.wall = #{ z: -1e-4 * p }; 1 })",
];

/// The scenes a script starts from.
const PROLOGUES: &[&str] = &[
    // A pair of spring dumbbells above a wall.
    "let s = scene();\ns.wall = #{ z: -20e-6 };\ns.add(dumbbell(#{ center: [-25e-6, 0, 0] }));\ns.add(dumbbell(#{ center: [25e-6, 0, 0], phase: 1.0 }));\n",
    // A rigid-stroke pair under gravity above a wall.
    "let s = scene();\ns.model = \"rigid\";\ns.wall = #{ z: -20e-6 };\ns.gravity = #{ g: 9.81, density: 2000, fluid_density: 1000 };\ns.add(dumbbell(#{ center: [-25e-6, 0, 0] }));\ns.add(dumbbell(#{ center: [25e-6, 0, 0], phase: 1.0 }));\n",
    // A spring pair pushed by a constant force.
    "let s = scene();\ns.external_force = [0, 0, -1e-12];\ns.add(dumbbell(#{ center: [-25e-6, 0, 0] }));\ns.add(dumbbell(#{ center: [25e-6, 0, 0], phase: 1.0 }));\n",
    // An averaged suspension in a box under the suspension stepper.
    "let s = scene();\ns.model = \"averaged\";\ns.box = [100e-6, 100e-6, 100e-6];\ns.add_random(dumbbell(), 12, 7);\ns.integrator = suspension(1e-3);\n",
];

/// Every script has a box scene `b` with two populations, a continuum `c` of it and a dumbbell
/// `d` besides its `s`; `fin(v)` marks a returned value that holds NaN or infinity.
const COMMON: &str = r#"fn nonfinite(v) {
    switch type_of(v) {
        "f64" => !v.is_finite,
        "array" => v.some(|x| nonfinite(x)),
        "map" => v.values().some(|x| nonfinite(x)),
        _ => false
    }
}
fn fin(v) {
    if nonfinite(v) { print(`NONFINITE: ${v}`); }
    v
}
let b = scene();
b.model = "averaged";
b.box = [120e-6, 120e-6, 120e-6];
b.add(dumbbell(#{ center: [-30e-6, 0, 0] }));
b.add(dumbbell(#{ center: [30e-6, 0, 0], phase: 1.5707963267948966 }));
b.add(dumbbell(#{ center: [0, 30e-6, 0] }));
b.add(dumbbell(#{ center: [0, -30e-6, 0], phase: 1.5707963267948966 }));
let d = dumbbell();
let c = continuum(b, #{ grid: 4, orientations: 2 });
"#;

fn script(rng: &mut Rng) -> String {
    let mut src = String::from(rng.pick(PROLOGUES));
    src.push_str(COMMON);
    for _ in 0..STATEMENTS {
        src.push_str(&format!(
            "try {{ {}; }} catch (e) {{ print(e); }}\n",
            driver::fill(rng.pick(CALLS), rng, VALUES, &[])
        ));
    }
    src
}

#[test]
fn walls_forces_continuum_and_suspensions_neither_panic_nor_hang_nor_return_nan() {
    let report = Fuzz {
        name: "walls-forces-continuum",
        seed: SEED,
        scripts: SCRIPTS,
        captured: true,
        rendered_every: 16,
    }
    .run(script, |k, src, printed| {
        if let Some(line) = printed.lines().find(|l| l.starts_with("NONFINITE")) {
            driver::fail(format!(
                "script {k} returned a value with NaN or inf:\n{src}\n---\n{line}"
            ));
        }
    });
    eprintln!("{report}");
}
