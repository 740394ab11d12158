//! Embed the engine directly: the paper's Fig-1 mirror pair (small spheres inwards, D = 10ℓ,
//! φ² − φ¹ = π/2), per-period collective drift with several integrators.
use nalgebra::Vector3;
use std::f64::consts::FRAC_PI_2;
use swimlab::engine::{Dumbbell, IntegratorSpec, Scene, Simulation};

fn pair(spec: Option<IntegratorSpec>) -> Scene {
    let ell = 5e-6;
    let big_l = 0.15 * ell;
    let d = Dumbbell {
        a1: 1.5 * big_l,
        a2: 0.75 * big_l,
        ..Dumbbell::default()
    };
    let mut s = Scene::new();
    s.add(d, Vector3::new(-5.0 * ell, 0.0, 0.0), Vector3::x())
        .unwrap();
    s.add(
        Dumbbell {
            phase: FRAC_PI_2,
            ..d
        },
        Vector3::new(5.0 * ell, 0.0, 0.0),
        -Vector3::x(),
    )
    .unwrap();
    s.set_integrator(spec);
    s
}

fn drift(spec: Option<IntegratorSpec>, periods: f64) -> (f64, f64, u64, f64) {
    let mut s = Simulation::new(pair(spec));
    let ell = 5e-6;
    s.run_periods(1.0).unwrap();
    let m0 = (s.displacement(0).unwrap().x + s.displacement(1).unwrap().x) / 2.0;
    let start = std::time::Instant::now();
    let e0 = s.stats().rhs_evals;
    s.run_periods(periods).unwrap();
    let el = start.elapsed().as_secs_f64();
    let m1 = (s.displacement(0).unwrap().x + s.displacement(1).unwrap().x) / 2.0;
    let sep = s.center(1).unwrap().x - s.center(0).unwrap().x;
    (
        (m1 - m0) / periods / ell,
        sep / ell,
        s.stats().rhs_evals - e0,
        el,
    )
}

fn main() {
    let t = 2.0 * std::f64::consts::PI / 500.0;
    let reference = drift(Some(IntegratorSpec::Dopri5 { rtol: 1e-11 }), 2.0);
    println!(
        "reference dopri5(1e-11): drift/period = {:.12e} ell",
        reference.0
    );
    let mut specs: Vec<IntegratorSpec> = vec![];
    for n in [700.0, 1000.0, 2000.0, 10000.0] {
        specs.push(IntegratorSpec::Rk4 { dt: t / n });
    }
    for n in [1000.0, 10000.0] {
        specs.push(IntegratorSpec::Euler { dt: t / n });
    }
    for r in [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9] {
        specs.push(IntegratorSpec::Dopri5 { rtol: r });
    }
    for spec in specs {
        let (d, _sep, evals, el) = drift(Some(spec), 2.0);
        println!(
            "{:>22}  drift/period = {:.10e}  rel.err = {:.2e}  rhs/period = {:>6}  {:.2} ms/period",
            spec.to_string(),
            d,
            ((d - reference.0) / reference.0).abs(),
            evals / 2,
            el * 500.0
        );
    }
}
