//! A seeded fuzz of boxes and Ewald sums, thermal noise, fields and the structure factor,
//! stroboscopic averaging and `auto`, trajectories, checkpoints, pictures and animations, sweeps (shared scenes
//! included), notes and the one-writer-per-file rule. A few hundred short scripts of random calls
//! with random, often hostile, arguments, each starting from one of several scenes (open space, a
//! box, the averaged model, noise). Every script must end by itself or stop promptly when
//! interrupted (as Ctrl-C would); no panic may reach the script boundary, where it would show as an
//! "internal error"; no message may show a Rust path or a Rust debug form. An abort (out of memory)
//! ends this test process, which fails the test.
//!
//! Scenes, swimmers, recorders and files have their own fuzz (`script_api.rs`); the driver is
//! shared (`driver.rs`).

use super::driver::{self, Fuzz};
use crate::common::Rng;

/// Scripts per run: every template is drawn ~60 times, and the run stays well under a minute
/// (most statements of hostile arguments stop at their first check).
const SCRIPTS: usize = 800;
/// Statements per script.
const STATEMENTS: usize = 7;
/// The seed of the scripts: the same scripts on every machine. `SWIMLAB_FUZZ_SEED` and
/// `SWIMLAB_FUZZ_SCRIPTS` explore others (a failure names its script, which reruns alone).
const SEED: u64 = 38_2026;

/// Argument values `V`: ordinary, extreme, of the wrong type, and the newer types.
const VALUES: &[&str] = &[
    "0",
    "1",
    "2",
    "-1",
    "0.5",
    "0.01",
    "1e-300",
    "1e300",
    "1e308",
    "5e-324",
    "1e-9",
    "1e-12",
    "9223372036854775807",
    "-9223372036854775807",
    "(0.0/0.0)",
    "(1.0/0.0)",
    "\"\"",
    "\"x\"",
    "\"density\"",
    "\"polarization\"",
    "\"nematic\"",
    "\"spectral\"",
    "\"beenakker\"",
    "\"auto\"",
    "\"lanczos\"",
    "\"cholesky\"",
    "\"mean\"",
    "\"max\"",
    "\"2\"",
    "[]",
    "[1, 2, 3]",
    "[120e-6, 120e-6, 120e-6]",
    "[1e308, 1e-4, 1e-4]",
    "[1e-4, 1e-4, 1e-2]",
    "[70, 1e-4, 1e-4]",
    "[1e200, 1e200, 1e-4]",
    "[[1e308, 0, 0]]",
    "[[0, 40e-6, 0], [0, -40e-6, 0]]",
    "[4, 4, 4]",
    "[100000, 100000, 100000]",
    "[0, 1, 1]",
    "#{}",
    "#{ grid: [8, 8, 8] }",
    "#{ grid: [8, 8, 8], width: 1e-5 }",
    "#{ width: -1 }",
    "#{ bins: 4 }",
    "#{ bins: 0, k_max: 1e308 }",
    "#{ axis: \"z\", index: 2 }",
    "#{ frames: 2, periods: 0.05 }",
    "#{ frames: 1000000 }",
    "#{ plane: \"xz\", title: \"t\" }",
    "()",
    "true",
    "s",
    "b",
    "r",
    "f",
    "d",
    "R_H(0)",
    "every_periods(0.5)",
    "every_seconds(1e-9)",
    "at_end()",
    "euler(1e-6)",
    "stroboscopic(1e-3)",
    "stroboscopic(1e-8)",
    "stroboscopic(1e-2, rk4(1e-5))",
    "auto(1e-3)",
    "auto(1e-8)",
    "platen(1e-6)",
    "dopri5(1e-6)",
    "|p| p",
    "#{ x: [1, 2], y: [3, 4] }",
    "plot(#{ x: [1, 2], y: [3, 4] })",
];

/// Paths `P`: a scratch folder (the same few names, so writers meet), and paths that cannot be
/// written (never a device to write).
fn paths(dir: &str) -> Vec<String> {
    [
        "t.xyz",
        "t.pvd",
        "u.xyz",
        "a.csv",
        "a.png",
        "a.svg",
        "a.gif",
        "a.vti",
        "s.json",
        "sub/dir/b.pvd",
        "sub/dir/b.gif",
    ]
    .iter()
    .map(|n| format!("\"{dir}/{n}\""))
    .chain([
        format!("\"{dir}\""),
        "\"/proc/x.png\"".into(),
        "\"/proc/nope/x.gif\"".into(),
        "\"/proc/x.xyz\"".into(),
        "\"\"".into(),
    ])
    .collect()
}

/// Call templates: `V` is a value, `P` a path. `s` and `b` are scenes (`b` in a box), `r` a
/// recorder of `s`, `f` a field of `s`, `d` a dumbbell.
const CALLS: &[&str] = &[
    // Boxes and Ewald sums.
    "s.box = V",
    "b.box = V",
    "b.ewald_method = V",
    "b.ewald_tol = V",
    "b.add_at(d, V)",
    "s.add_at(d, V)",
    "b.add_at(d, lattice::fill(b.box, V, V, V))",
    "b.add_at(d, lattice::fill(V, 2, 1, 1))",
    "s.add_at(d, lattice::cubic(V, V, 2, 20e-6))",
    "s.phases = phases::alternating(s.count, V)",
    "b.add_random(d, V, 0.01, V)",
    "b.sphere_velocities(V)",
    "b.run_periods(V)",
    "b.run(V)",
    "b.cutoff = V",
    "b.model = V",
    // Thermal noise.
    "s.temperature = V",
    "b.temperature = V",
    "s.seed = V",
    "s.noise_root = V",
    "s.lanczos_tol = V",
    "s.integrator = platen(V)",
    "s.integrator = euler(V)",
    "s.diffusion(V)",
    "s.observe(msd())",
    "s.observe(peclet(V, V))",
    // Fields and the structure factor.
    "s.field(V)",
    "s.field(V, V)",
    "b.field(V, V)",
    "f.stat(V)",
    "f.plot(V)",
    "f.plot(P)",
    "f.plot(P, V)",
    "f.to_vtk(P)",
    "f.integral()",
    "f.values.len()",
    "display(f)",
    "b.structure_factor(V)",
    "b.structure_factor()",
    "s.structure_factor()",
    "b.observe(field_stat(V, V))",
    "b.observe(field_stat(\"density\", \"max\", V))",
    "s.record([field_stat(\"density\", V)], V)",
    // Stroboscopic averaging and auto.
    "s.integrator = V",
    "b.integrator = V",
    "s.integrator = stroboscopic(V)",
    "s.integrator = stroboscopic(V, V)",
    "s.integrator = auto(V)",
    "s.integrator_info",
    "b.integrator_info",
    "s.stats",
    "s.run_periods(V)",
    "s.run(V)",
    // Trajectories and recorders.
    "s.trajectory(P, V)",
    "b.trajectory(P, V)",
    "s.trajectory(P, every_seconds(V))",
    "s.copy().trajectory(P, 0.5)",
    "r.stream_csv(P)",
    "r.to_csv(P)",
    "write_csv(P, [#{ a: V }])",
    "s.save(P)",
    "s = load_scene(P)",
    "load_scene(P).run_periods(V)",
    // Checkpoints.
    "s.checkpoint(P, V)",
    "b.checkpoint(P, V)",
    "s.checkpoint(P, every_seconds(V))",
    "s.run_to(V)",
    "s.run_to_periods(V)",
    "b.run_to_periods(V)",
    "s.checksum",
    // Pictures and animations.
    "plot(V)",
    "plot(P, V)",
    "plot(V).save(P)",
    "s.snapshot()",
    "s.snapshot(P)",
    "s.snapshot(P, V)",
    "b.snapshot(V)",
    "s.animate(P)",
    "s.animate(P, V)",
    "b.animate(P, #{ frames: 2, periods: V })",
    "display(V)",
    "tplot(V)",
    // The live view.
    "s.view()",
    "s.view(V)",
    "b.view(#{ port: V, every: V, pace: V, fields: V })",
    "s.close_view()",
    "b.close_view()",
    "r.plot(P, \"time\", V)",
    "r.plot(\"time\", V)",
    // Sweeps.
    "sweep(V, |p| p)",
    "sweep([1, 2, 3], |p| { s.run_periods(0.01); s.time }, 2)",
    "sweep([1, 2], |p| { let t = s.copy(); t.run_periods(V); t.time })",
    "sweep([s, s], |x| { x.mu = V; })",
    "sweep([s, b], |x| { x.run_periods(0.01); x.time })",
    "sweep([1, 2], |p| { r.stream_csv(P); })",
    "sweep([1, 2], |p| { s.observe(V) })",
    "sweep([1, 2], |p| { s.trajectory(P, 1) })",
    "sweep(V, V, V)",
    "sweep([1, 2], |a, b| a)",
    "sweep([1, 2], V)",
    // Smaller items.
    "param(V, V)",
    "lattice::cubic(V, 2, 1, V)",
    "lattice::hexagonal(V, V, 1e-5)",
    "1.0 / V",
    "V + s",
    // The continuum.
    "continuum(b, V)",
    "continuum(s, V)",
    "continuum(V)",
    "c.run_periods(V)",
    "c.run(V)",
    "c.field(V)",
    "c.field(V, V)",
    "c.mode(V, V)",
    "c.mode(V, V, V)",
    "b.mode(V, V)",
    "b.mode(V, V, V)",
    "s.mode(V, V)",
    "c.growth_rates(V)",
    "c.growth_rates(V, V)",
    "c.perturb(V)",
    "c.perturb(#{ shape: V, amplitude: V, mode: V, axis: V })",
    "c.sample(b, V, V)",
    "c.sample(s, V, V)",
    "c.wave_vector(V)",
    "c.counts()",
    "display(c)",
];

/// The scenes a script starts from.
const PROLOGUES: &[&str] = &[
    // A pair in open space.
    "let s = scene();\ns.add(dumbbell(#{ center: [-25e-6, 0, 0] }));\ns.add(dumbbell(#{ center: [25e-6, 0, 0], phase: 1.0 }));\n",
    // The Fig-1 mirror pair.
    "let s = paper::mirror(10.0, true, true);\n",
    // A pair under thermal noise.
    "let s = scene();\ns.add(dumbbell(#{ center: [-25e-6, 0, 0] }));\ns.add(dumbbell(#{ center: [25e-6, 0, 0], phase: 1.0 }));\ns.temperature = 300;\n",
    // The averaged model.
    "let s = scene();\ns.model = \"averaged\";\ns.add(dumbbell(#{ center: [-25e-6, 0, 0] }));\ns.add(dumbbell(#{ center: [25e-6, 0, 0], phase: 1.0 }));\n",
];

/// Every script has a box scene `b`, a recorder `r`, a field `f` and a continuum `c` of `b`
/// besides its `s`. `b`'s sums are set to 1e-4: a fuzz needs no accuracy, and at the default
/// tolerance the box's waves take a quarter of the fuzz's time (`b.ewald_tol = V` draws `()`,
/// which follows the integrator again, among its values).
const COMMON: &str = "let b = scene();\nb.box = [120e-6, 120e-6, 120e-6];\nb.ewald_tol = 1e-4;\nb.add(dumbbell(#{ center: [-30e-6, 0, 0] }));\nb.add(dumbbell(#{ phase: 1.0 }));\nlet d = dumbbell();\nlet r = s.record([R_H(0)], 1);\nlet f = s.field(\"density\", #{ grid: [8, 8, 8] });\nlet c = continuum(b, #{ grid: 4, orientations: 2 });\n";

fn script(rng: &mut Rng, paths: &[String]) -> String {
    let p: Vec<&str> = paths.iter().map(String::as_str).collect();
    let mut src = String::from(
        "import \"paper\" as paper;\nimport \"lattice\" as lattice;\nimport \"phases\" as phases;\n",
    );
    src.push_str(rng.pick(PROLOGUES));
    src.push_str(COMMON);
    for _ in 0..STATEMENTS {
        let out = driver::fill(rng.pick(CALLS), rng, VALUES, &p);
        src.push_str(&format!("try {{ {out}; }} catch (e) {{ print(e); }}\n"));
    }
    src
}

#[test]
fn box_noise_field_and_output_scripts_neither_panic_nor_hang_nor_leak_rust_names() {
    let dir = std::env::temp_dir().join(format!(
        "swimlab-fuzz-boxes-noise-fields-outputs-{}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let paths = paths(&dir.display().to_string());
    let report = Fuzz {
        name: "boxes, noise, fields, outputs",
        seed: SEED,
        scripts: SCRIPTS,
        captured: true,
        rendered_every: 16,
    }
    .run(|rng| script(rng, &paths), |_, _, _| {});
    eprintln!("{report}");
}
