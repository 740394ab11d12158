//! One averaged right-hand side of a lattice of S swimmers (orientations turned out of line, so
//! the 3D rows run), scalar rows against vector-lane rows, per swimmer pair and core, on 1 and
//! all threads: `cargo run --release --example averaged_rows -- 4096` (the paper's symmetric
//! swimmer; `-- 4096 asymmetric`: a2 = a1/2, whose rows carry the I and K terms too). Then, side by side in 9
//! alternating rounds on one thread, a lane-row right-hand side against one product of the sphere
//! kernel on 4,096 spheres (`swimlab bench pairs`'s lattice): the median ratio of an averaged
//! swimmer pair to a sphere interaction, which the machine's load moves far less than either.
use std::time::Instant;
use swimlab::bench::pairs::lattice;
use swimlab::engine::averaged::AveragedSystem;
use swimlab::engine::build::lattice_scene_of;
use swimlab::engine::integrators::OdeSystem;
use swimlab::engine::pairs::interaction_velocities;
use swimlab::engine::{Coefficients, Dumbbell, Mobility, Model};

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(4096);
    let mut d = Dumbbell::default();
    if std::env::args().nth(2).as_deref() == Some("asymmetric") {
        d.a2 = d.a1 / 2.0;
    }
    let s = lattice_scene_of(n, Model::Averaged, d).unwrap();
    let (y, base) = s.raw_state();
    let mut y = y.to_vec();
    for i in 0..n {
        let a = i as f64 * 0.37;
        let v = [a.cos(), a.sin(), 0.3];
        let m = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        for k in 0..3 {
            y[6 * i + 3 + k] = v[k] / m;
        }
    }
    let mut dy = vec![0.0; y.len()];
    for threads in [1, rayon::current_num_threads()] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        for (name, lanes) in [("scalar rows", false), ("lane rows", true)] {
            let mut sys = AveragedSystem::new(s.swimmers(), base, Coefficients::Paper, &y);
            sys.set_vector_rows(Some(lanes));
            let t = pool.install(|| {
                sys.rhs(0.0, &y, &mut dy);
                let start = Instant::now();
                let reps = 3;
                for _ in 0..reps {
                    sys.rhs(0.0, &y, &mut dy);
                }
                start.elapsed().as_secs_f64() / reps as f64
            });
            let per_pair = t * threads as f64 / (n * (n - 1)) as f64;
            println!("{n} swimmers, {threads} threads, {name}: {t:.4} s per rhs, {:.2} ns per pair and core", per_pair * 1e9);
        }
    }
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let mut sys = AveragedSystem::new(s.swimmers(), base, Coefficients::Paper, &y);
    sys.set_vector_rows(Some(true));
    let spheres = lattice(4096);
    let mut u = vec![[0.0; 3]; spheres.len()];
    let time = |f: &mut dyn FnMut()| {
        let start = Instant::now();
        f();
        start.elapsed().as_secs_f64()
    };
    let interactions = |k: usize| (k * (k - 1)) as f64;
    let mut rounds: Vec<(f64, f64)> = (0..9)
        .map(|_| {
            one.install(|| {
                let a = time(&mut || sys.rhs(0.0, &y, &mut dy)) / interactions(n);
                let b = time(&mut || {
                    interaction_velocities(Mobility::Rpy, 1e-3, &spheres, &mut u, false)
                }) / interactions(spheres.len());
                (a, b)
            })
        })
        .collect();
    rounds.sort_by(|x, y| (x.0 / x.1).total_cmp(&(y.0 / y.1)));
    let (a, b) = rounds[rounds.len() / 2];
    let ratios: Vec<String> = rounds
        .iter()
        .map(|(a, b)| format!("{:.2}", a / b))
        .collect();
    println!(
        "side by side, 1 thread, 9 rounds: averaged pair / sphere interaction {:.2} (median round: {:.2} ns / {:.3} ns; all, sorted: {})",
        a / b,
        a * 1e9,
        b * 1e9,
        ratios.join(" ")
    );
}
