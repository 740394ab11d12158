//! One averaged right-hand side of a lattice of S swimmers (orientations turned out of line, so
//! the 3D rows run), scalar rows against vector-lane rows, per swimmer pair and core, on 1 and
//! all threads: `cargo run --release --example averaged_rows -- 4096`. Compare with the sphere
//! kernel's interactions per second from `swimlab bench pairs` in the same session.
use std::time::Instant;
use swimlab::engine::averaged::AveragedSystem;
use swimlab::engine::build::lattice_scene;
use swimlab::engine::integrators::OdeSystem;
use swimlab::engine::{Coefficients, Model};

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(4096);
    let s = lattice_scene(n, Model::Averaged).unwrap();
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
}
