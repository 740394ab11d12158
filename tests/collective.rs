//! Collective observables against cases with known answers: the pair correlation g(r) of an
//! ideal gas is 1 and a lattice's sits on its coordination shells (with the polar and nematic
//! parts of a lattice of alternating orientations); free Brownian dumbbells decorrelate as
//! C_l = e^{−l(l+1) D_r t} and spread as MSD = 6 D_t t, and the block estimators give D_r and D_t
//! within their standard errors, errors that match the exact ones.

use nalgebra::Vector3;
use rhai::{Map, Scope};
use swimlab::engine::effective_diffusion::{estimate, Series};
use swimlab::engine::{Dumbbell, IntegratorSpec, Model, Observable, Scene, Simulation, Trigger};
use swimlab::script::run_source;

/// The map a script leaves in its variable `out`.
fn eval(src: &str) -> Map {
    let mut scope = Scope::new();
    run_source("collective", src, &mut scope).unwrap_or_else(|e| panic!("{e}\n{src}"));
    scope
        .get_value::<Map>("out")
        .expect("the script sets out to a map")
}

/// The error of a script that must fail.
fn error(src: &str) -> String {
    match run_source("collective", src, &mut Scope::new()) {
        Ok(()) => panic!("no error:\n{src}"),
        Err(e) => e.to_string(),
    }
}

fn floats(m: &Map, key: &str) -> Vec<f64> {
    m[key]
        .clone()
        .into_array()
        .unwrap()
        .into_iter()
        .map(|v| v.as_float().unwrap())
        .collect()
}

/// An ideal gas of swimmers: 800 default dumbbells at uniform random places (random sequential
/// addition, which only refuses draws within contact) in a periodic cube of 400 µm, 20 shells up
/// to 200 µm. Shell 0 (r < 10 µm) holds the contact distances, at most ℓ + 2a + gap < 10 µm, and
/// is left out; every other shell within 4 of its reported standard errors (each fails with
/// probability 6e-5, the 19 together 1e-3: the ideal gas's pair counts have variance at most
/// their mean, see the engine's unit test), and their mean within 4 of its own. The recorded
/// observable is the same function of the same state: exactly the map's g.
#[test]
fn an_ideal_gas_of_swimmers_has_g_one() {
    let m = eval(
        "let s = scene(); s.box = [400e-6, 400e-6, 400e-6]; s.add_random(dumbbell(), 800, 3);
         let rec = s.record([pair_correlation(20, 200e-6)], at_end()); s.run_periods(0);
         let g = s.pair_correlation(20, 200e-6);
         g.recorded = rec.rows[0]; let out = g;",
    );
    let (g, err) = (floats(&m, "g"), floats(&m, "err"));
    for k in 1..20 {
        assert!(
            (g[k] - 1.0).abs() < 4.0 * err[k],
            "shell {k}: {} ± {}",
            g[k],
            err[k]
        );
    }
    let mean = g[1..].iter().sum::<f64>() / 19.0;
    let e = err[1..].iter().map(|e| e * e).sum::<f64>().sqrt() / 19.0;
    assert!((mean - 1.0).abs() < 4.0 * e, "mean g {mean} ± {e}");
    let row = m["recorded"].clone().cast::<Map>();
    for (k, gk) in g.iter().enumerate() {
        assert_eq!(row[format!("g[{k}]").as_str()].as_float().unwrap(), *gk);
    }
}

/// A simple cubic lattice of 6³ swimmers filling the box, spacing a = 20 µm, N up or down by the
/// parity of i + j + k. Each has 6, 12, 8, 6, 24, 24, 12 neighbours at a √1, √2, √3, √4, √5, √6,
/// √8 and none at √7 (all within 2.9a < 3a, half the side); the 45 shells of width 2.9a/45 hold
/// each distance at least 0.01 of a shell from an edge. The counts are exact: N z/2 pairs per
/// shell, none between. Neighbours whose offsets sum to an odd number point opposite ways
/// (d² = 1, 3, 5: g1 = −1), the others alike (d² = 2, 4, 6, 8: g1 = 1); P2 of ±1 is 1, so g2 = 1
/// on every shell. Exact counts and ±1 products: the checks are exact to rounding (1e-12).
#[test]
fn a_lattice_of_swimmers_has_its_coordination_shells() {
    let m = eval(
        "let a = 20e-6; let s = scene(); s.box = [6 * a, 6 * a, 6 * a];
         for i in 0..6 { for j in 0..6 { for k in 0..6 {
             let up = if (i + j + k) % 2 == 0 { 1.0 } else { -1.0 };
             s.add(dumbbell(#{ center: [i * a, j * a, k * a], dir: [0, 0, up] }));
         } } }
         let out = s.pair_correlation(45, 2.9 * a);",
    );
    let (pairs, g, ideal) = (floats(&m, "pairs"), floats(&m, "g"), floats(&m, "ideal"));
    let (g1, g2, r) = (floats(&m, "g1"), floats(&m, "g2"), floats(&m, "r"));
    let (a, n, width) = (20e-6, 216.0, 2.9 * 20e-6 / 45.0);
    let shells = [
        (1, 6.0),
        (2, 12.0),
        (3, 8.0),
        (4, 6.0),
        (5, 24.0),
        (6, 24.0),
        (8, 12.0),
    ];
    for k in 0..45 {
        assert!((r[k] / ((k as f64 + 0.5) * width) - 1.0).abs() < 1e-12);
        let shell = shells
            .iter()
            .find(|(d2, _)| (f64::sqrt(*d2 as f64) * a / width) as usize == k);
        if let Some(&(d2, z)) = shell {
            assert_eq!(pairs[k], n * z / 2.0, "shell {k} (d² = {d2})");
            assert!((g[k] * ideal[k] / (n * z / 2.0) - 1.0).abs() < 1e-12);
            let polar = if d2 % 2 == 1 { -1.0 } else { 1.0 };
            assert!((g1[k] - polar).abs() < 1e-12, "g1 at d² = {d2}: {}", g1[k]);
            assert!((g2[k] - 1.0).abs() < 1e-12, "g2 at d² = {d2}: {}", g2[k]);
        } else {
            assert_eq!(
                (pairs[k], g[k], g1[k], g2[k]),
                (0.0, 0.0, 0.0, 0.0),
                "shell {k}"
            );
        }
    }
}

/// The theoretical variance of one swimmer's P_l(N(t)·N(0)) under free rotational diffusion at
/// x = D_r t: E[P1²] = 1/3 + (2/3) e^{−6x} and E[P2²] = 1/5 + (2/7) e^{−6x} + (18/35) e^{−20x} (P_l²
/// in Legendre polynomials), less the mean squared, e^{−2l(l+1)x}.
fn legendre_variance(l: u8, x: f64) -> f64 {
    match l {
        1 => 1.0 / 3.0 + 2.0 / 3.0 * (-6.0 * x).exp() - (-4.0 * x).exp(),
        _ => {
            0.2 + 2.0 / 7.0 * (-6.0 * x).exp() + 18.0 / 35.0 * (-20.0 * x).exp() - (-12.0 * x).exp()
        }
    }
}

/// Free Brownian dumbbells: 1,000 symmetric swimmers of the averaged model in one phase (pairs in
/// phase do not interact: each is free), 300 K, Euler-Maruyama steps of h = 0.2 s (D_r h = 0.004:
/// the normalised scheme's orientation error is far below the statistics), recorded every step
/// to t = 16 s (x = D_r t = 0.33). The symmetric dumbbell's R_H is its centre of mobility, so
/// MSD = 6 D_t t exactly and C_l = e^{−l(l+1) D_r t}, D_t and D_r from `rigid_diffusion`.
///
/// The 10 equal blocks from t = 0 telescope: D̂_t = MSD(16 s)/(6 · 16 s), with exact standard
/// error D_t √(2/(3N)) (|ΔR|² of an isotropic Gaussian step is (2 D_t t) χ²_3; the dumbbell's
/// D_∥ ≠ D_⊥ adds 2% to the variance), and D̂_r = −ln C_l(16 s)/(l(l+1) 16 s), with error
/// sd(P_l)/(√N C_l l(l+1) t) to first order ([`legendre_variance`]). Each estimate within 4 exact
/// errors of its coefficient (false failure 6e-5 each), and each estimator's own error, from 10
/// block slopes (9 degrees of freedom), within 0.4 to 2.5 times the exact one (χ²_9 below 1.44
/// or above 56: probability 3e-3 and 1e-8). `reset_origins` then starts both anew: msd 0, C 1.
#[test]
fn free_brownian_dumbbells_decorrelate_and_spread_at_their_coefficients() {
    let mut s = Scene::new();
    let d = Dumbbell::default();
    for x in 0..10 {
        for y in 0..10 {
            for z in 0..10 {
                let c = Vector3::new(x as f64, y as f64, z as f64) * 30e-6;
                let a = (x * 100 + y * 10 + z) as f64 * 0.61;
                s.add(d, c, Vector3::new(a.cos(), a.sin(), (1.7 * a).sin()))
                    .unwrap();
            }
        }
    }
    s.set_model(Model::Averaged);
    s.set_temperature(300.0).unwrap();
    let h = 0.2;
    s.set_integrator(Some(IntegratorSpec::Euler { dt: h }));
    let rd = s.rigid_diffusion(0).unwrap();
    assert!(
        rd.offset.abs() < 1e-12 * d.ell,
        "symmetric: R_H is the centre of mobility"
    );
    let mut sim = Simulation::new(s);
    let obs = vec![
        Observable::Msd,
        Observable::OrientationAutocorrelation(1),
        Observable::OrientationAutocorrelation(2),
    ];
    let id = sim.record(obs, Trigger::EverySeconds(h)).unwrap();
    let steps = 80;
    sim.run(steps as f64 * h).unwrap();
    let rows = &sim.recorder(id).unwrap().rows;
    assert_eq!(rows.len(), steps + 1);
    let column = |c: usize| rows.iter().map(|r| r[c]).collect::<Vec<f64>>();
    let t = column(0);
    let n = 1000.0f64;
    let t_end = t[steps];

    let e = estimate(&t, &column(1), Series::Msd { dims: 3 }, None, None, None).unwrap();
    let exact = rd.translation() * (2.0 / (3.0 * n)).sqrt();
    println!(
        "D_t {:e} ± {:e} (exact error {exact:e}) against {:e}",
        e.value,
        e.error,
        rd.translation()
    );
    assert_eq!(e.slopes.len(), 10);
    assert!((e.value - rd.translation()).abs() < 4.0 * exact);
    assert!(
        (0.4..2.5).contains(&(e.error / exact)),
        "error {:e} against {exact:e}",
        e.error
    );

    for l in [1u8, 2] {
        let series = Series::Orientation { order: l };
        let e = estimate(&t, &column(l as usize + 1), series, None, None, None).unwrap();
        let rate = f64::from(l * (l + 1));
        let x = rd.rotation * t_end;
        let c = (-rate * x).exp();
        let exact = legendre_variance(l, x).sqrt() / (n.sqrt() * c * rate * t_end);
        println!(
            "D_r from C{l}: {:e} ± {:e} (exact error {exact:e}) against {:e}",
            e.value, e.error, rd.rotation
        );
        assert!((e.value - rd.rotation).abs() < 4.0 * exact);
        assert!(
            (0.4..2.5).contains(&(e.error / exact)),
            "error {:e} against {exact:e}",
            e.error
        );
    }

    // A file from before the origins: displacements from the placement, as before; orientations
    // from the state as loaded.
    let mut file: serde_json::Value =
        serde_json::from_str(&sim.scene().to_json().unwrap()).unwrap();
    file["scene"].as_object_mut().unwrap().remove("origins");
    let old = Scene::from_json(&file.to_string()).unwrap();
    assert_eq!(
        Observable::Msd.evaluate(&old).unwrap(),
        sim.measure(&Observable::Msd).unwrap()
    );
    let c1 = Observable::OrientationAutocorrelation(1)
        .evaluate(&old)
        .unwrap()[0];
    assert!(
        (c1 - 1.0).abs() < 1e-15,
        "C1 of an old file as loaded: {c1}"
    );

    sim.scene_mut().reset_origins();
    let msd = sim.measure(&Observable::Msd).unwrap()[0];
    let c1 = sim
        .measure(&Observable::OrientationAutocorrelation(1))
        .unwrap()[0];
    assert_eq!(msd, 0.0);
    assert!((c1 - 1.0).abs() < 1e-15, "C1 right after the reset: {c1}");
    let loaded = Scene::from_json(&sim.scene().to_json().unwrap()).unwrap();
    assert_eq!(loaded.origin(7).unwrap(), sim.scene().origin(7).unwrap());
}

/// Each bad input names the problem and its fix.
#[test]
fn bad_collective_input_is_refused_with_the_fix() {
    let one = "let s = scene(); s.box = [100e-6, 100e-6, 100e-6]; s.add(dumbbell());";
    for (src, says) in [
        ("let s = scene(); s.add(dumbbell()); s.add(dumbbell(#{ center: [2e-5, 0, 0] })); s.pair_correlation(10, 1e-5)", "put the scene in a box"),
        (&format!("{one} s.pair_correlation(10, 60e-6)"), "use r_max up to 5e-5 m"),
        (&format!("{one} s.pair_correlation(10, 40e-6)"), "at least two swimmers"),
        ("pair_polar(0, 1e-5)", "1 to 10000 shells"),
        ("pair_nematic(10, -1.0)", "positive r_max"),
        ("orientation_autocorrelation(3)", "order 1"),
        ("let s = scene(); s.observe(orientation_autocorrelation())", "add swimmers first"),
        ("translational_diffusion([0.0, 1.0], [0.0, 1.0])", "at least 3 rows"),
        ("translational_diffusion([0.0, 1.0, 2.0], [0.0, 1.0, 2.0], #{ dims: 4 })", "1, 2 or 3 dimensions"),
        ("translational_diffusion([0.0, 1.0, 2.0], [0.0, 1.0, 2.0], #{ window: 4 })", "unknown option \"window\""),
        ("rotational_diffusion([0.0, 1.0, 2.0], [1.0, 0.1, 0.0])", "end it earlier"),
        ("let s = scene(); s.add(dumbbell()); let r = s.record([R_H(0)], 1); translational_diffusion(r)", "no column \"msd\""),
    ] {
        let e = error(src);
        assert!(e.contains(says), "{src}\n{e}");
    }
}
