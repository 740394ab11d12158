//! The fast pair kernel ([`crate::engine::pairs`]): RPY pair interactions per second at
//! N = 4,096 spheres, serial and on 1 … all cores, against the ~1e9 per core bound of evaluating
//! each pair from both ends (≈36 flops and one reciprocal square root per H_ij·F_j; evaluating it
//! once for both exceeds it); and the row kernel ([`row_velocities`]) serially in the same run, the
//! comparison of the each-pair-once form against the rows.

use super::table::Table;
use crate::engine::mobility::Mobility;
use crate::engine::pairs::{interaction_velocities, row_velocities, SoaSpheres};
use std::time::Instant;

/// Interactions per second per core that the arithmetic of a pair evaluated from both ends allows.
pub const BOUND_PER_CORE: f64 = 1e9;

/// N spheres on a jittered cubic lattice 3 µm apart, radii 0.5-1 µm (as in benches/kernels.rs).
pub fn lattice(n: usize) -> SoaSpheres {
    let mut s = SoaSpheres::default();
    s.resize(n);
    let side = (n as f64).cbrt().ceil() as usize;
    for k in 0..n {
        let (i, j, l) = (k % side, (k / side) % side, k / (side * side));
        let jitter = ((k * 7919) % 101) as f64 / 101.0 * 0.2e-6;
        s.x[k] = i as f64 * 3e-6 + jitter;
        s.y[k] = j as f64 * 3e-6 + jitter;
        s.z[k] = l as f64 * 3e-6 + jitter;
        let a = 0.5e-6 + 0.5e-6 * ((k * 31) % 17) as f64 / 17.0;
        s.set_radius(k, a);
        let f = 1e-12 * (1.0 + (k % 3) as f64);
        s.fx[k] = f;
        s.fy[k] = -0.5 * f;
        s.fz[k] = 0.25 * f;
    }
    s
}

/// Median over `repeats` of the seconds one product takes.
fn time_product(s: &SoaSpheres, parallel: bool, repeats: usize) -> f64 {
    time_kernel(interaction_velocities, s, parallel, repeats)
}

/// A pair kernel's signature.
type PairKernel = fn(Mobility, f64, &SoaSpheres, &mut [[f64; 3]], bool);

/// Median over `repeats` of the seconds one product of `kernel` takes.
fn time_kernel(kernel: PairKernel, s: &SoaSpheres, parallel: bool, repeats: usize) -> f64 {
    let mut u = vec![[0.0; 3]; s.len()];
    let mut times: Vec<f64> = (0..repeats)
        .map(|_| {
            let start = Instant::now();
            kernel(Mobility::Rpy, 1e-3, s, &mut u, parallel);
            std::hint::black_box(&u);
            start.elapsed().as_secs_f64()
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

/// The table: threads, seconds per product, ordered interactions per second, per core, fraction
/// of the bound, speed-up over one thread.
pub fn run(n: usize, repeats: usize) -> Table {
    let s = lattice(n);
    let pairs = (n * (n - 1)) as f64;
    let mut t = Table::new(&[
        "threads",
        "s_per_product",
        "interactions_per_s",
        "per_core",
        "fraction_of_bound",
        "speedup",
    ]);
    let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
    let serial = time_product(&s, false, repeats);
    let mut row = |label: String, secs: f64, threads: usize| {
        let rate = pairs / secs;
        t.rows.push(vec![
            label,
            format!("{secs:.4e}"),
            format!("{rate:.3e}"),
            format!("{:.3e}", rate / threads as f64),
            format!("{:.3}", rate / threads as f64 / BOUND_PER_CORE),
            format!("{:.2}", serial / secs),
        ]);
    };
    row("1 (serial)".into(), serial, 1);
    let by_rows = time_kernel(row_velocities, &s, false, repeats);
    row("1 (serial, by rows)".into(), by_rows, 1);
    for threads in 1..=cores {
        let pool = match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
            Ok(p) => p,
            Err(_) => continue,
        };
        let secs = pool.install(|| time_product(&s, true, repeats));
        row(format!("{threads} (rayon)"), secs, threads);
    }
    t
}
