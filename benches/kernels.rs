//! Hot kernels: the all-pairs RPY mobility-vector product for N = 4 … 4096 spheres, one right-hand
//! side of the Fig-1 pair in each model, and one step of each integrator.
//!
//! cargo bench --bench kernels

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use nalgebra::Vector3;
use std::f64::consts::FRAC_PI_2;
use std::hint::black_box;
use swimlab::engine::averaged::AveragedSystem;
use swimlab::engine::integrators::{Dopri5, Euler, OdeSystem, Rk4, Stats, Stepper};
use swimlab::engine::micro::MicroSystem;
use swimlab::engine::rigid::RigidSystem;
use swimlab::engine::{Coefficients, Dumbbell, Mobility, Model, Scene};

/// N spheres on a jittered cubic lattice, 3 µm apart, radii 0.5-1 µm (no overlaps).
fn lattice(n: usize) -> (Vec<Vector3<f64>>, Vec<f64>, Vec<Vector3<f64>>) {
    let side = (n as f64).cbrt().ceil() as usize;
    let mut pos = Vec::with_capacity(n);
    let mut radii = Vec::with_capacity(n);
    let mut forces = Vec::with_capacity(n);
    for k in 0..n {
        let (i, j, l) = (k % side, (k / side) % side, k / (side * side));
        let jitter = ((k * 7919) % 101) as f64 / 101.0 * 0.2e-6;
        pos.push(Vector3::new(i as f64, j as f64, l as f64) * 3e-6 + Vector3::repeat(jitter));
        radii.push(0.5e-6 + 0.5e-6 * ((k * 31) % 17) as f64 / 17.0);
        forces.push(Vector3::new(1.0, -0.5, 0.25) * 1e-12 * (1.0 + (k % 3) as f64));
    }
    (pos, radii, forces)
}

fn rpy_product(c: &mut Criterion) {
    let mut g = c.benchmark_group("rpy_interaction_product");
    for n in [4usize, 16, 64, 256, 1024, 4096] {
        let (pos, radii, forces) = lattice(n);
        let mut out = vec![Vector3::zeros(); n];
        // Pair interactions evaluated: n(n-1)/2 pairs, each applied in both directions.
        g.throughput(Throughput::Elements((n * (n - 1) / 2) as u64));
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                Mobility::Rpy.interaction_velocities(
                    1e-3,
                    black_box(&pos),
                    &radii,
                    &forces,
                    &mut out,
                )
            })
        });
    }
    g.finish();
}

fn fig1_pair() -> Scene {
    let l = 0.15 * 5e-6;
    let d = Dumbbell {
        a1: 1.5 * l,
        a2: 0.75 * l,
        ..Dumbbell::default()
    };
    let mut s = Scene::new();
    let _ = s.add(d, Vector3::new(-25e-6, 0.0, 0.0), Vector3::x());
    let _ = s.add(
        Dumbbell {
            phase: FRAC_PI_2,
            ..d
        },
        Vector3::new(25e-6, 0.0, 0.0),
        -Vector3::x(),
    );
    s
}

fn systems(model: Model) -> (Box<dyn OdeSystem>, Vec<f64>) {
    let mut s = fig1_pair();
    s.set_model(model);
    let (y, base) = s.raw_state();
    let sys: Box<dyn OdeSystem> = match model {
        Model::Micro => Box::new(MicroSystem::new(
            s.swimmers(),
            base,
            1e-3,
            Mobility::Rpy,
            Default::default(),
        )),
        Model::Rigid => Box::new(RigidSystem::new(
            s.swimmers(),
            base,
            1e-3,
            Mobility::Rpy,
            Default::default(),
        )),
        Model::Averaged => Box::new(AveragedSystem::new(
            s.swimmers(),
            base,
            Coefficients::Paper,
            y,
        )),
    };
    (sys, y.to_vec())
}

fn pair_rhs(c: &mut Criterion) {
    let mut g = c.benchmark_group("pair_rhs");
    for model in [Model::Micro, Model::Rigid, Model::Averaged] {
        let (mut sys, y) = systems(model);
        let mut dy = vec![0.0; y.len()];
        g.bench_function(model.name(), |b| {
            b.iter(|| sys.rhs(black_box(1e-3), black_box(&y), &mut dy))
        });
    }
    g.finish();
}

fn one_step(c: &mut Criterion) {
    let mut g = c.benchmark_group("pair_step_micro");
    let (mut sys, y0) = systems(Model::Micro);
    let dt = 5.6e-6;
    let steppers: Vec<(&str, Box<dyn Stepper>)> = vec![
        ("euler", Box::new(Euler::new(dt))),
        ("rk4", Box::new(Rk4::new(dt))),
        ("dopri5", Box::new(Dopri5::fixed_step(dt))),
    ];
    for (name, mut st) in steppers {
        let mut y = y0.clone();
        let mut stats = Stats::default();
        g.bench_function(name, |b| {
            b.iter(|| {
                y.copy_from_slice(&y0);
                st.step(sys.as_mut(), 0.0, &mut y, dt, &mut stats).ok()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, rpy_product, pair_rhs, one_step);
criterion_main!(benches);
