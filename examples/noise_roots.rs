//! The crossover of the two square roots of the mobility that thermal noise needs: one
//! Euler-Maruyama step of a lattice of spring dumbbells at 300 K with the dense Cholesky factor and
//! with the Lanczos iteration (tolerance 1e-6), side by side, for growing sphere counts:
//! `cargo run --release --example noise_roots [-- MAX_SPHERES]`. Each time is the fastest of three
//! steps (the step's deterministic part, the same for both, included). "auto" switches to Lanczos
//! above `engine::thermal::CHOLESKY_MAX_SPHERES`.
use std::time::Instant;
use swimlab::engine::build::lattice_scene;
use swimlab::engine::thermal::NoiseRoot;
use swimlab::engine::{IntegratorSpec, Model, Simulation};

fn step_time(swimmers: usize, root: NoiseRoot) -> f64 {
    let mut s = lattice_scene(swimmers, Model::Micro).expect("lattice");
    s.set_temperature(300.0).expect("temperature");
    s.set_noise_root(root);
    let dt = 0.1 / s.stiff_rate();
    s.set_integrator(Some(IntegratorSpec::Euler { dt }));
    let mut sim = Simulation::new(s);
    (0..3)
        .map(|_| {
            let t = Instant::now();
            sim.run(dt).expect("step");
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let max: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(1024);
    println!("spheres  cholesky [ms]  lanczos [ms]  cholesky/lanczos");
    let mut spheres = 8;
    let mut crossover = None;
    while spheres <= max {
        let c = step_time(spheres / 2, NoiseRoot::Cholesky);
        let l = step_time(spheres / 2, NoiseRoot::Lanczos);
        println!(
            "{spheres:7}  {:13.3}  {:12.3}  {:16.2}",
            c * 1e3,
            l * 1e3,
            c / l
        );
        match crossover {
            None if l < c => crossover = Some(spheres),
            Some(_) if l >= c => crossover = None,
            _ => {}
        }
        // Steps of about 1.25x, even (two spheres a dumbbell).
        spheres = (spheres * 5 / 4 + 1) & !1;
    }
    match crossover {
        Some(n) => println!(
            "Lanczos is faster from {n} spheres on; \"auto\" takes Cholesky up to {} spheres",
            swimlab::engine::thermal::CHOLESKY_MAX_SPHERES
        ),
        None => println!("Cholesky was faster up to {max} spheres"),
    }
}
