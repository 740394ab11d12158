//! A seeded fuzz of the whole script API: a few hundred short scripts of random calls with
//! random, often hostile, arguments (NaN, infinities, 5e-324, i64::MAX, wrong types, bad paths).
//! Every script must end by itself or stop promptly when interrupted (as Ctrl-C would), and no
//! panic may reach the script boundary, where it would show as an "internal error". An abort
//! (out of memory) ends this test process, which fails the test too.
//!
//! The driver is shared with the other fuzzers (`driver.rs`).

use super::driver::Fuzz;
use crate::common::Rng;

/// Scripts per run: enough to touch every template many times (~1 minute of CI time).
const SCRIPTS: usize = 300;
/// Statements per script.
const STATEMENTS: usize = 6;

/// Argument values: ordinary, extreme, and of the wrong type.
const VALUES: &[&str] = &[
    "0",
    "1",
    "2",
    "-1",
    "0.5",
    "-0.0",
    "3.0",
    "1e-300",
    "1e300",
    "5e-324",
    "1e-9",
    "9223372036854775807",
    "-9223372036854775807",
    "(0.0/0.0)",
    "(1.0/0.0)",
    "(-1.0/0.0)",
    "\"\"",
    "\"micro\"",
    "\"averaged\"",
    "\"rigid\"",
    "\"x\"",
    "[]",
    "[1, 2, 3]",
    "[0.0, 0.0, 0.0]",
    "[1e300, 0, 0]",
    "#{}",
    "#{ a1: 1e-6 }",
    "#{ center: [1e-5, 0, 0] }",
    "()",
    "true",
    "s",
    "d",
    "r",
    "R_H(0)",
    "every_periods(1)",
    "at_end()",
    "rk4(1e-6)",
    "dopri5(1e-6)",
    "[R_H(0), q(0, 1)]",
    "[0.0, 1.0]",
    "#{ x: [1, 2], y: [3, 4] }",
];

/// Paths: a scratch folder and ones that cannot be written or read (never a device to write).
fn paths(dir: &str) -> Vec<String> {
    vec![
        format!("\"{dir}/a.csv\""),
        format!("\"{dir}/b.json\""),
        format!("\"{dir}/c.svg\""),
        format!("\"{dir}/d.png\""),
        format!("\"{dir}/sub/e.png\""),
        format!("\"{dir}\""),
        "\"/proc/nope/x.png\"".into(),
        "\"\"".into(),
        "\"/dev/null\"".into(),
    ]
}

/// Call templates: `V` is a value, `P` a path.
const CALLS: &[&str] = &[
    "s.run_periods(V)",
    "s.run(V)",
    "s.add(V)",
    "s.add(dumbbell(V))",
    "s.add_random(d, V, V, V)",
    "s.add_random(d, 3, 0.01, V, V)",
    "s.add_at(d, V)",
    "s.record(V, V)",
    "s.observe(V)",
    "s.model = V",
    "s.mobility = V",
    "s.integrator = V",
    "s.mu = V",
    "s.phases = V",
    "s.set_phase(V, V)",
    "s.cutoff = V",
    "s.steric = V",
    "s.overlaps = V",
    "s.coefficients = V",
    "s.temperature = V",
    "s.seed = V",
    "s.noise_root = V",
    "s.lanczos_tol = V",
    "s.integrator = platen(V)",
    "s.diffusion(V)",
    "s.observe(msd())",
    "s.observe(peclet(V, V))",
    "s.copy()",
    "s.save(P)",
    "load_scene(P)",
    "r.to_csv(P)",
    "r.stream_csv(P)",
    "r.rows",
    "r.column(V)",
    "r.len",
    "plot(P, V)",
    "plot(P, V, V)",
    "plot(P, #{ x: [V, V], y: [V, 1] })",
    "plot(P, #{ x: [1, V], y: [V, 2] }, #{ log_x: true, log_y: V })",
    "tplot(V)",
    "r.tplot(\"time\", V)",
    "s.snapshot(P)",
    "s.snapshot(P, V)",
    "dumbbell(V)",
    "euler(V)",
    "rk4(V)",
    "dopri5(V)",
    "rosw(V)",
    "every_periods(V)",
    "every_seconds(V)",
    "at_times(V)",
    "R_H(V)",
    "N(V)",
    "pair_mean(V, V)",
    "q(V, V)",
    "delta_q(V, V)",
    "D_H(V, V)",
    "mean_speed()",
    "min_gap()",
    "polarization()",
    "pair_distances(V, V)",
    "pair_correlation(V, V)",
    "pair_polar(V, V)",
    "s.pair_correlation(V, V)",
    "s.observe(orientation_autocorrelation(V))",
    "s.reset_origins()",
    "translational_diffusion(V, V)",
    "translational_diffusion(r, V)",
    "rotational_diffusion(V, V, #{ from: V, blocks: V })",
    "rotational_diffusion(r)",
    "lpad(V, V)",
    "rpad(V, V)",
    "sci(V)",
    "sci(V, V)",
    "fixed(V, V)",
    "uniform_randoms(V, V)",
    "sweep(V, |p| p, V)",
    "sweep([1, 2], |p| { let t = scene(); t.add(dumbbell()); t.count })",
    "write_csv(P, V)",
    "write_csv(P, [\"a\"], V)",
    "s.velocity(V)",
    "s.center(V)",
    "s.dir(V)",
    "s.length(V)",
    "s.tension(V)",
    "s.swimmer(V)",
    "s.phase(V)",
    "s.period",
    "s.backend_info",
    "s.stats",
    "s.backend = \"cpu\"",
    "s = load_scene(P)",
    "s.integrator = \"default\"",
    "s.record([R_H(0)], every_seconds(V))",
    "s.record([R_H(0)], every_periods(V))",
];

fn script(rng: &mut Rng, paths: &[String]) -> String {
    let p: Vec<&str> = paths.iter().map(String::as_str).collect();
    let mut src = String::from(
        "let s = scene();\ns.add(dumbbell(#{ center: [-25e-6, 0, 0] }));\ns.add(dumbbell(#{ center: [25e-6, 0, 0], phase: 1.0 }));\nlet d = dumbbell();\nlet r = s.record([R_H(0)], 1);\n",
    );
    for _ in 0..STATEMENTS {
        let mut call = rng.pick(CALLS).to_string();
        while let Some(k) = call.find('V') {
            call.replace_range(k..k + 1, rng.pick(VALUES));
        }
        while let Some(k) = call.find('P') {
            call.replace_range(k..k + 1, rng.pick(&p));
        }
        src.push_str(&format!("try {{ {call}; }} catch (e) {{ }}\n"));
    }
    src
}

#[test]
fn no_script_panics_hangs_or_aborts() {
    let dir = std::env::temp_dir().join(format!("swimlab-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let paths = paths(&dir.display().to_string());
    // Through the renderer's path alone: these scripts catch every error and print none.
    let report = Fuzz {
        name: "script API",
        seed: 20261201,
        scripts: SCRIPTS,
        captured: false,
        rendered_every: 1,
    }
    .run(|rng| script(rng, &paths), |_, _, _| {});
    eprintln!("{report}");
}
