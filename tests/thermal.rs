//! Thermal noise: Brownian dumbbells with RPY hydrodynamics. The statistical tests are seeded
//! (so they are deterministic runs of the generator), and each states its false-failure
//! probability: the chance that a correct implementation, run with another seed, would fail it.

use crate::common;
use nalgebra::{DMatrix, Matrix2, Vector2, Vector3};
use rayon::prelude::*;
use swimlab::engine::integrators::{
    Euler, Noise, OdeSystem, Platen, Problem, Stats, StepDraws, Stepper,
};
use swimlab::engine::thermal::{lanczos, NoiseRoot, BOLTZMANN};
use swimlab::engine::{Dumbbell, IntegratorSpec, Mobility, Model, Scene, Simulation};

const KT: f64 = BOLTZMANN * 300.0;

/// A passive dumbbell (λ = 0) of the paper's size; `symmetric`: a1 = a2.
fn passive(symmetric: bool) -> Dumbbell {
    let ell = 5e-6;
    let (a1, a2) = if symmetric {
        (0.15 * ell, 0.15 * ell)
    } else {
        (0.225 * ell, 0.1125 * ell)
    };
    Dumbbell {
        a1,
        a2,
        ell,
        lambda: 0.0,
        ..Dumbbell::default()
    }
}

fn one(d: Dumbbell) -> Scene {
    let mut s = Scene::new();
    s.add(d, Vector3::zeros(), Vector3::x()).unwrap();
    s
}

/// The spring mode's relaxation rate with the dumbbell's own hydrodynamic interaction:
/// k0 (1/γ1 + 1/γ2 − 2 c_∥(ℓ)).
fn spring_rate(d: &Dumbbell, mobility: Mobility) -> f64 {
    let mu = 1e-3;
    let (ci, crr) = mobility.pair_coefficients(mu, d.ell, d.a1, d.a2);
    d.k0 * (1.0 / (6.0 * std::f64::consts::PI * mu) * (1.0 / d.a1 + 1.0 / d.a2) - 2.0 * (ci + crr))
}

#[test]
fn temperature_zero_changes_nothing() {
    let pair = || common::mirror_inwards(10.0, true);
    let mut plain = Simulation::new(pair());
    let mut touched = pair();
    touched.set_temperature(300.0).unwrap();
    touched.set_seed(9);
    touched.set_noise_root(NoiseRoot::Lanczos);
    touched.set_temperature(0.0).unwrap();
    let mut touched = Simulation::new(touched);
    for sim in [&mut plain, &mut touched] {
        sim.run_periods(2.0).unwrap();
        sim.scene_mut()
            .set_integrator(Some(IntegratorSpec::Euler { dt: 1e-7 }));
        sim.run_periods(0.5).unwrap();
    }
    assert_eq!(plain.scene().raw_state().0, touched.scene().raw_state().0);
    assert_eq!(plain.scene().stats(), touched.scene().stats());
    assert_eq!(plain.scene().stats().noisy_steps, 0);
    let json = pair().to_json().unwrap();
    assert!(
        !json.contains("thermal"),
        "a noise-free scene saves as before"
    );
    assert!(!json.contains("noisy_steps"));
}

/// ∇·M = 0: Σ_β Σ_k ∂M_{αi,βk}/∂x_{βk} by central differences at random positions, separated and
/// overlapping (Zuk et al.'s form), for RPY and Oseen. With steps δ = 1e-5 of the spread the
/// differences' truncation error, ~(δ/r)² of M/r, and their round-off stay below 1e-7 of the scale
/// 1/(8πμ spread²) that a non-zero divergence would have; the band is 1e-6 of it.
#[test]
fn the_mobilities_are_divergence_free() {
    let mu = 1e-3;
    let radii = [1.0e-6, 0.5e-6, 0.8e-6, 1.2e-6];
    let mut x = 0.37_f64;
    let mut rnd = || {
        x = (x * 97.13 + 0.41).fract();
        x - 0.5
    };
    for mobility in [Mobility::Rpy, Mobility::Oseen] {
        for spread in [20e-6, 2.0e-6] {
            let pos: Vec<Vector3<f64>> = (0..4)
                .map(|_| Vector3::new(rnd(), rnd(), rnd()) * spread)
                .collect();
            let n = pos.len();
            let scale = 1.0 / (8.0 * std::f64::consts::PI * mu * spread * spread);
            for a in 0..n {
                for i in 0..3 {
                    let mut div = 0.0;
                    for b in 0..n {
                        for k in 0..3 {
                            let delta = 1e-5 * spread;
                            let mut p = pos.clone();
                            p[b][k] += delta;
                            let plus = mobility.matrix(mu, &p, &radii)[(3 * a + i, 3 * b + k)];
                            p[b][k] -= 2.0 * delta;
                            let minus = mobility.matrix(mu, &p, &radii)[(3 * a + i, 3 * b + k)];
                            div += (plus - minus) / (2.0 * delta);
                        }
                    }
                    assert!(
                        div.abs() < 1e-6 * scale,
                        "{mobility:?}, spread {spread:e}: (div M)[{a}].{i} = {div:e} against {scale:e}"
                    );
                }
            }
        }
    }
}

/// Sample the spring length of a passive dumbbell every `every` steps after a burn-in: its
/// variance and the number of samples.
fn length_variance(mobility: Mobility, spec: IntegratorSpec, steps: usize, every: usize) -> f64 {
    let d = passive(false);
    let mut s = one(d);
    s.set_mobility(mobility);
    s.set_temperature(300.0).unwrap();
    s.set_seed(11);
    s.set_integrator(Some(spec));
    let dt = spec.parameter();
    let mut sim = Simulation::new(s);
    sim.run(200.0 * dt).unwrap();
    let mut lengths = Vec::new();
    for _ in 0..steps / every {
        sim.run(every as f64 * dt).unwrap();
        lengths.push(sim.scene().length(0).unwrap());
    }
    let n = lengths.len() as f64;
    let mean = lengths.iter().sum::<f64>() / n;
    lengths.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / n
}

/// Equipartition: the spring length of a passive dumbbell has variance kT/k0 whatever the
/// mobility. Euler-Maruyama at rate·dt = z overestimates it by 1/(1 − z/2) (the spring mode is an
/// Ornstein-Uhlenbeck process; the 3D length adds (σ/ℓ)² ~ 1e-7): with z = 0.05 that bias is
/// predicted and divided out. Samples every 3/rate are 5% correlated; 40,000 of them give the
/// variance to 0.75% (one standard error), so a 4% band is over 5 standard errors
/// (false-failure probability < 1e-6).
#[test]
fn a_passive_spring_has_variance_kt_over_k0_whatever_the_mobility() {
    let d = passive(false);
    for mobility in [Mobility::Rpy, Mobility::Oseen] {
        let rate = spring_rate(&d, mobility);
        let z = 0.05;
        let every = 60;
        let var = length_variance(
            mobility,
            IntegratorSpec::Euler { dt: z / rate },
            40_000 * every,
            every,
        );
        let ratio = var / (KT / d.k0) * (1.0 - z / 2.0);
        assert!(
            (ratio - 1.0).abs() < 0.04,
            "{mobility:?}: variance {var:e} is {ratio} of kT/k0 after the Euler-Maruyama factor"
        );
    }
}

/// The centre of a passive symmetric dumbbell diffuses with kT/(12πμ)(1/a + 1/ℓ): per step, its
/// squared displacement has mean 2 kT tr(M_RR) h = 6 D h exactly (no drift: the dumbbell is
/// symmetric and force-free; M_RR depends on the length only, which stays at ℓ to 4e-4). 2e5
/// steps give the mean to 0.18% (its relative standard error is √(2/3)/√n); the band of 1% is
/// 5.5 standard errors (false-failure probability 4e-8). Both square roots: the Lanczos one
/// through the pair kernel, Cholesky from the dense matrix.
#[test]
fn a_passive_symmetric_centre_diffuses_at_the_rpy_trace() {
    let d = passive(true);
    let expected = KT / (12.0 * std::f64::consts::PI * 1e-3) * (1.0 / d.a1 + 1.0 / d.ell);
    for root in [NoiseRoot::Cholesky, NoiseRoot::Lanczos] {
        let mut s = one(d);
        s.set_temperature(300.0).unwrap();
        s.set_noise_root(root);
        let h = 0.5 / spring_rate(&d, Mobility::Rpy);
        s.set_integrator(Some(IntegratorSpec::Euler { dt: h }));
        let mut sim = Simulation::new(s);
        let steps = 200_000;
        let mut sum = 0.0;
        let mut last = sim.scene().displacement(0).unwrap();
        for _ in 0..steps {
            sim.run(h).unwrap();
            let now = sim.scene().displacement(0).unwrap();
            sum += (now - last).norm_squared();
            last = now;
        }
        let measured = sum / steps as f64 / (6.0 * h);
        assert!(
            (measured / expected - 1.0).abs() < 0.01,
            "{root:?}: D = {measured:e}, expected kT/(12 pi mu)(1/a + 1/ell) = {expected:e}"
        );
        let rigid = sim.scene().rigid_diffusion(0).unwrap().translation();
        assert!(
            (rigid / expected - 1.0).abs() < 1e-12,
            "the rigid dumbbell's D_t {rigid:e} is the Kirkwood value {expected:e} for a1 = a2"
        );
    }
}

/// Lanczos and Cholesky give the same covariance: the Lanczos square root S of the RPY matrix of
/// 24 spheres (some overlapping), taken column by column, satisfies S Sᵀ = M = L Lᵀ to 1e-8 at a
/// tolerance of 1e-11 (the stopping test bounds the last change; the error is a small multiple).
#[test]
fn lanczos_and_cholesky_give_the_same_covariance() {
    let mu = 1e-3;
    let mut x = 0.61_f64;
    let mut rnd = || {
        x = (x * 89.7 + 0.29).fract();
        x - 0.5
    };
    let n = 24;
    let pos: Vec<Vector3<f64>> = (0..n)
        .map(|_| Vector3::new(rnd(), rnd(), rnd()) * 8e-6)
        .collect();
    let radii: Vec<f64> = (0..n)
        .map(|i| if i % 2 == 0 { 1e-6 } else { 0.5e-6 })
        .collect();
    let m = Mobility::Rpy.matrix(mu, &pos, &radii);
    let l = m
        .clone()
        .cholesky()
        .expect("RPY is positive definite")
        .unpack();
    let dim = 3 * n;
    let mut s = DMatrix::zeros(dim, dim);
    for c in 0..dim {
        let mut e = vec![0.0; dim];
        e[c] = 1.0;
        let mut out = vec![0.0; dim];
        let mut apply = |v: &[f64], w: &mut [f64]| {
            let r = &m * nalgebra::DVector::from_column_slice(v);
            w.copy_from_slice(r.as_slice());
        };
        lanczos::sqrt_times(&mut apply, &e, 1e-11, &mut out).unwrap();
        s.column_mut(c).copy_from_slice(&out);
    }
    let scale = m.norm();
    let err_l = (&l * l.transpose() - &m).norm() / scale;
    let err_s = (&s * s.transpose() - &m).norm() / scale;
    assert!(err_l < 1e-13, "Cholesky: {err_l:e}");
    assert!(err_s < 1e-8, "Lanczos: {err_s:e}");
    assert!(
        (&s - s.transpose()).norm() / s.norm() < 1e-8,
        "Lanczos gives the symmetric root"
    );
}

/// Through the engine, the two square roots give Brownian steps of the same covariance in a
/// scene of 40 dumbbells (80 spheres: the Lanczos products take the vectorised pair kernel).
/// The squared noise increment of all centres, summed, has mean 2kT h Σσ tr(M_RR^σσ) (rows of
/// w1, w2 on each dumbbell's spheres). Over 400 seeded steps from one state each root's sample
/// mean must lie within 5 of its standard errors (false-failure probability 6e-7), and the
/// standard error must be below 1% (so that the test can tell a wrong covariance).
#[test]
fn both_square_roots_give_the_same_step_covariance_through_the_pair_kernel() {
    let mut s = Scene::new();
    let d = Dumbbell {
        lambda: 0.0,
        ..Dumbbell::default()
    };
    for k in 0..40 {
        let c = Vector3::new((k % 4) as f64, ((k / 4) % 4) as f64, (k / 16) as f64) * 9e-6;
        let dir = Vector3::new(1.0, 0.3 * (k as f64).sin(), 0.2 * (k as f64).cos());
        s.add(d, c, dir).unwrap();
    }
    let h = 1e-7;
    s.set_integrator(Some(IntegratorSpec::Euler { dt: h }));
    // The deterministic step, to subtract.
    let mut quiet = Simulation::new(s.clone());
    quiet.run(h).unwrap();
    let det: Vec<Vector3<f64>> = (0..40)
        .map(|i| quiet.scene().displacement(i).unwrap())
        .collect();
    // Expected: Σσ tr(T M Tᵀ) on the R_H rows.
    let (pos, radii): (Vec<Vector3<f64>>, Vec<f64>) = (0..40)
        .flat_map(|i| {
            let (a, b) = s.spheres(i);
            [(a, d.a1), (b, d.a2)]
        })
        .unzip();
    let m = Mobility::Rpy.matrix(1e-3, &pos, &radii);
    let (w1, w2) = (d.w1(), d.w2());
    let mut trace = 0.0;
    for sw in 0..40 {
        for k in 0..3 {
            let (p, q) = (6 * sw + k, 6 * sw + 3 + k);
            trace += w1 * w1 * m[(p, p)] + 2.0 * w1 * w2 * m[(p, q)] + w2 * w2 * m[(q, q)];
        }
    }
    let expected = 2.0 * KT * h * trace;
    for root in [NoiseRoot::Cholesky, NoiseRoot::Lanczos] {
        let samples: Vec<f64> = (0..400u64)
            .into_par_iter()
            .map(|seed| {
                let mut noisy = s.clone();
                noisy.set_temperature(300.0).unwrap();
                noisy.set_noise_root(root);
                noisy.set_seed(seed);
                let mut sim = Simulation::new(noisy);
                sim.run(h).unwrap();
                (0..40)
                    .map(|i| (sim.scene().displacement(i).unwrap() - det[i]).norm_squared())
                    .sum::<f64>()
            })
            .collect();
        let (mean, se) = mean_and_error(samples.iter().copied());
        assert!(
            se < 0.01 * expected,
            "{root:?}: standard error {se:e} of {expected:e}"
        );
        assert!(
            (mean - expected).abs() < 5.0 * se,
            "{root:?}: mean squared kick {mean:e} ± {se:e} against 2kT h tr = {expected:e}"
        );
    }
}

/// dX = A X dt + Σⱼ Bⱼ X dWⱼ in the plane, with B₁, B₂ that do not commute: E[X Xᵀ] = P solves
/// P' = AP + PAᵀ + Σⱼ BⱼPBⱼᵀ exactly, so E|X_T|² is known.
#[derive(Clone)]
struct Linear {
    a: Matrix2<f64>,
    b: [Matrix2<f64>; 2],
    seed: u64,
}

impl OdeSystem for Linear {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) {
        let v = self.a * Vector2::new(y[0], y[1]);
        dy.copy_from_slice(v.as_slice());
    }
    fn error_scale(&self, _y: &[f64], scale: &mut [f64]) {
        scale.fill(1.0);
    }
    fn noise(&self) -> Option<Noise> {
        Some(Noise {
            seed: self.seed,
            dim: 2,
        })
    }
    fn add_noise(
        &mut self,
        _t: f64,
        y: &[f64],
        dw: &[f64],
        y_new: &mut [f64],
    ) -> Result<(), Problem> {
        let x = Vector2::new(y[0], y[1]);
        let v = self.b[0] * x * dw[0] + self.b[1] * x * dw[1];
        y_new[0] += v.x;
        y_new[1] += v.y;
        Ok(())
    }
    fn diffusion(&mut self, _t: f64, y: &[f64], out: &mut DMatrix<f64>) -> Result<(), Problem> {
        let x = Vector2::new(y[0], y[1]);
        for j in 0..2 {
            let c = self.b[j] * x;
            out[(0, j)] = c.x;
            out[(1, j)] = c.y;
        }
        Ok(())
    }
}

/// |X_T|² of Euler-Maruyama and of Platen on the same path (both draw the same Wiener increments
/// from the same seed and step counter), for `paths` seeds and steps T/n.
fn coupled_paths(sys: &Linear, n: usize, paths: u64) -> Vec<(f64, f64)> {
    let t_end = 1.0;
    (0..paths)
        .into_par_iter()
        .map(|p| {
            let run = |mut st: Box<dyn Stepper>| {
                let mut s = sys.clone();
                s.seed = p;
                let mut y = [1.0, 0.0];
                let (mut t, mut stats) = (0.0, Stats::default());
                while t < t_end {
                    t = st.step(&mut s, t, &mut y, t_end, &mut stats).unwrap();
                }
                y[0] * y[0] + y[1] * y[1]
            };
            let h = t_end / n as f64;
            (run(Box::new(Euler::new(h))), run(Box::new(Platen::new(h))))
        })
        .collect()
}

fn mean_and_error(v: impl Iterator<Item = f64> + Clone) -> (f64, f64) {
    let k = v.clone().count() as f64;
    let mean = v.clone().sum::<f64>() / k;
    let var = v.map(|x| (x - mean).powi(2)).sum::<f64>() / (k - 1.0);
    (mean, (var / k).sqrt())
}

/// Platen's step for the linear system: y ← R y with R = 1 + Ah + ½A²h² + Σⱼ wⱼ(Bⱼ + ½h(ABⱼ +
/// BⱼA)) + ½ Σⱼ BⱼBⱼ(wⱼ² − h) + ½ Σ_{j≠r} BⱼB_r(wⱼw_r + V_{rj}): for linear coefficients its
/// differences are exact, so it is the weak Taylor scheme of order 2 (Kloeden & Platen 14.2.1).
fn platen_matrix(sys: &Linear, h: f64, w: [f64; 2], v: f64) -> Matrix2<f64> {
    let (a, b) = (sys.a, sys.b);
    let mut r = Matrix2::identity() + a * h + a * a * (h * h / 2.0);
    for j in 0..2 {
        r += (b[j] + (a * b[j] + b[j] * a) * (h / 2.0)) * w[j];
        r += b[j] * b[j] * ((w[j] * w[j] - h) / 2.0);
    }
    r += b[0] * b[1] * ((w[0] * w[1] - v) / 2.0) + b[1] * b[0] * ((w[0] * w[1] + v) / 2.0);
    r
}

/// E|X_T|² of Platen's scheme with n steps, exactly: E[R P Rᵀ] summed over the 3-point
/// Gauss-Hermite rule in each w (exact for R P Rᵀ, of degree 4 in w) and v = ±h.
fn platen_exact(sys: &Linear, n: usize) -> f64 {
    let h = 1.0 / n as f64;
    let nodes = [
        (0.0, 2.0 / 3.0),
        ((3.0 * h).sqrt(), 1.0 / 6.0),
        (-(3.0 * h).sqrt(), 1.0 / 6.0),
    ];
    let mut p = Matrix2::new(1.0, 0.0, 0.0, 0.0);
    for _ in 0..n {
        let mut next = Matrix2::zeros();
        for (w0, c0) in nodes {
            for (w1, c1) in nodes {
                for v in [h, -h] {
                    let r = platen_matrix(sys, h, [w0, w1], v);
                    next += r * p * r.transpose() * (c0 * c1 * 0.5);
                }
            }
        }
        p = next;
    }
    p.trace()
}

/// Weak orders on a linear system in the plane with non-commuting multiplicative noise, whose
/// E|X_T|² is exact: Euler-Maruyama's error falls as h, Platen's as h².
/// - Platen: the stepper's one-step matrix, rebuilt from the same draws (the counter-based
///   generator is public), is the weak Taylor scheme's to 1e-12; that scheme's exact moments
///   converge at order 2 (1.94, 1.97, 1.99 from 8 to 64 steps; 1.85 from 4 to 8).
/// - Euler-Maruyama: on a linear system its moments are exact too, P ← (1 + hA)P(1 + hA)ᵀ +
///   h Σ BPBᵀ; they converge at order 1 (1.04, 1.02, 1.01 from 16 to 128 steps; 1.07 from 8 to 16).
/// - Both steppers' samples (400,000 paths at 4, 8 and 16 steps) agree with their scheme's exact
///   moment within 5 standard errors (false-failure probability 6e-7 per check, 6 checks).
#[test]
fn weak_orders_of_euler_maruyama_and_platen() {
    let sigma = 0.6;
    let sys = Linear {
        a: Matrix2::new(-0.5, 1.0, -1.0, -0.5),
        b: [
            Matrix2::new(sigma, 0.0, 0.0, -sigma),
            Matrix2::new(0.0, sigma, sigma, 0.0),
        ],
        seed: 0,
    };
    let noise = |p: &Matrix2<f64>| {
        sys.b
            .iter()
            .map(|b| b * p * b.transpose())
            .sum::<Matrix2<f64>>()
    };
    // Exact: P' = AP + PAᵀ + Σ BPBᵀ by RK4 with 2e4 steps (error ~1e-16).
    let f = |p: &Matrix2<f64>| sys.a * p + p * sys.a.transpose() + noise(p);
    let p0 = Matrix2::new(1.0, 0.0, 0.0, 0.0);
    let mut p = p0;
    let dt = 1.0 / 20_000.0;
    for _ in 0..20_000 {
        let k1 = f(&p);
        let k2 = f(&(p + k1 * (dt / 2.0)));
        let k3 = f(&(p + k2 * (dt / 2.0)));
        let k4 = f(&(p + k3 * dt));
        p += (k1 + 2.0 * k2 + 2.0 * k3 + k4) * (dt / 6.0);
    }
    let exact = p.trace();

    // The stepper's matrix is the formula's, draw for draw.
    let h: f64 = 0.25;
    for (seed, step) in [(3u64, 0u64), (17, 5), (123_456_789, 1 << 33)] {
        let draws = StepDraws::new(seed, step);
        let mut w = [0.0; 2];
        draws.normals(&mut w);
        let w = [w[0] * h.sqrt(), w[1] * h.sqrt()];
        let expected = platen_matrix(&sys, h, w, h * draws.sign(1));
        for col in 0..2 {
            let mut y = [0.0; 2];
            y[col] = 1.0;
            let mut s = sys.clone();
            s.seed = seed;
            let mut stats = Stats {
                noisy_steps: step,
                ..Stats::default()
            };
            Platen::new(h)
                .step(&mut s, 0.0, &mut y, h, &mut stats)
                .unwrap();
            for row in 0..2 {
                assert!(
                    (y[row] - expected[(row, col)]).abs() < 1e-12,
                    "Platen's step matrix ({row}, {col}): {} against {}",
                    y[row],
                    expected[(row, col)]
                );
            }
        }
    }
    // Its exact moments converge at order 2.
    let errs: Vec<f64> = [8, 16, 32, 64]
        .iter()
        .map(|&n| (platen_exact(&sys, n) - exact).abs())
        .collect();
    for w in errs.windows(2) {
        let o = (w[0] / w[1]).log2();
        assert!((1.9..2.1).contains(&o), "Platen: order {o} from {errs:?}");
    }

    let euler_exact = |n: usize| {
        let h = 1.0 / n as f64;
        let g = Matrix2::identity() + sys.a * h;
        let mut p = p0;
        for _ in 0..n {
            p = g * p * g.transpose() + noise(&p) * h;
        }
        p.trace()
    };
    let em: Vec<f64> = [16, 32, 64, 128]
        .iter()
        .map(|&n| (euler_exact(n) - exact).abs())
        .collect();
    for w in em.windows(2) {
        let o = (w[0] / w[1]).log2();
        assert!(
            (0.95..1.05).contains(&o),
            "Euler-Maruyama: order {o} from {em:?}"
        );
    }
    let mut sampled = Vec::new();
    for n in [4, 8, 16] {
        let v = coupled_paths(&sys, n, 400_000);
        let (m_em, se_em) = mean_and_error(v.iter().map(|x| x.0));
        let ee = euler_exact(n);
        assert!(
            (m_em - ee).abs() < 5.0 * se_em,
            "Euler-Maruyama's samples {m_em} ± {se_em} against its exact moment {ee}"
        );
        let (m_pl, se_pl) = mean_and_error(v.iter().map(|x| x.1));
        let pe = platen_exact(&sys, n);
        assert!(
            (m_pl - pe).abs() < 5.0 * se_pl,
            "Platen's samples {m_pl} ± {se_pl} against its exact moment {pe}"
        );
        sampled.push((m_em - exact).abs());
    }
    println!(
        "exact {exact}; Euler-Maruyama's exact errors {em:?}, sampled {sampled:?}; Platen's exact errors {errs:?}"
    );
}

/// The paper's asymmetric swimmer (a2 = a1/2, Λ = 0.15ℓ).
fn paper_swimmer() -> Dumbbell {
    let ell = 5e-6;
    Dumbbell {
        a1: 0.225 * ell,
        a2: 0.1125 * ell,
        ..Dumbbell::default()
    }
}

/// The rigid dumbbell's coefficients, independently: the 5×5 resistance JᵀM⁻¹J of its rigid
/// motions (3 translations of the centre of mobility, 2 rotations across the axis) through the
/// 6×6 two-sphere RPY matrix is block diagonal there (no translation-rotation coupling, to
/// 1e-12 of the diagonal) and its inverse times kT gives D_∥, D_⊥, D_r to 1e-12.
#[test]
fn rigid_dumbbell_diffusion_from_the_two_sphere_resistance() {
    let d = paper_swimmer();
    let mut s = one(d);
    s.set_temperature(300.0).unwrap();
    let rd = s.rigid_diffusion(0).unwrap();
    // Axis along z, R_H at 0: spheres at −w2ℓ and w1ℓ; the centre of mobility at `offset`.
    let pos = [
        Vector3::new(0.0, 0.0, -d.w2() * d.ell),
        Vector3::new(0.0, 0.0, d.w1() * d.ell),
    ];
    let m = Mobility::Rpy.matrix(1e-3, &pos, &[d.a1, d.a2]);
    let minv = m.try_inverse().unwrap();
    // J: (U, Ωx, Ωy) → sphere velocities U + Ω × (x_α − C).
    let mut j = DMatrix::<f64>::zeros(6, 5);
    for (a, p) in pos.iter().enumerate() {
        let r = p - Vector3::new(0.0, 0.0, rd.offset);
        for k in 0..3 {
            j[(3 * a + k, k)] = 1.0;
        }
        for (c, axis) in [Vector3::x(), Vector3::y()].iter().enumerate() {
            let v = axis.cross(&r);
            for k in 0..3 {
                j[(3 * a + k, 3 + c)] = v[k];
            }
        }
    }
    let resistance = j.transpose() * minv * &j;
    let diff = resistance.try_inverse().unwrap() * KT;
    for (got, want) in [
        (diff[(0, 0)], rd.perpendicular),
        (diff[(1, 1)], rd.perpendicular),
        (diff[(2, 2)], rd.parallel),
        (diff[(3, 3)], rd.rotation),
        (diff[(4, 4)], rd.rotation),
    ] {
        assert!((got / want - 1.0).abs() < 1e-12, "{got:e} against {want:e}");
    }
    for r in 0..3 {
        for c in 3..5 {
            let coupling = diff[(r, c)] / (diff[(r, r)] * diff[(c, c)]).sqrt();
            assert!(coupling.abs() < 1e-12, "coupling ({r}, {c}): {coupling:e}");
        }
    }
    assert!(
        rd.offset.abs() > 1e-9,
        "the asymmetric dumbbell's centre of mobility is not R_H"
    );
}

/// The averaged model's swimmers diffuse as rigid dumbbells: 2,000 swimmers with one phase (pairs
/// in phase do not interact, so they are free, and a cutoff below the lattice's spacing leaves
/// out only pair terms that are zero), 300 steps of 0.05 s. Per step the centre of
/// mobility C = R_H + z_c N moves by a squared distance of mean 6 D_t h exactly, and N turns by
/// 1 − N·N' of mean 1 − e^(−2 D_r h) (the normalised scheme: to O((D_r h)²) ~ 1e-3 relative).
/// 6e5 samples give both means to 0.13% (one standard error); the 1% band is 7 standard errors
/// (false-failure probability < 1e-11).
#[test]
fn averaged_swimmers_diffuse_as_rigid_dumbbells() {
    let d = paper_swimmer();
    let mut s = Scene::new();
    let mut k = 0;
    for x in 0..20 {
        for y in 0..10 {
            for z in 0..10 {
                let c = Vector3::new(x as f64, y as f64, z as f64) * 30e-6;
                let a = k as f64 * 0.61;
                let dir = Vector3::new(a.cos(), a.sin(), (1.7 * a).sin());
                s.add(d, c, dir).unwrap();
                k += 1;
            }
        }
    }
    s.set_model(Model::Averaged);
    s.set_cutoff(Some(20e-6)).unwrap();
    s.set_temperature(300.0).unwrap();
    let h = 0.05;
    s.set_integrator(Some(IntegratorSpec::Euler { dt: h }));
    let rd = s.rigid_diffusion(0).unwrap();
    let mut sim = Simulation::new(s);
    let n = sim.scene().count();
    let centre =
        |sc: &Scene, i: usize| sc.displacement(i).unwrap() + rd.offset * sc.dir(i).unwrap();
    let (mut trans, mut rot, mut samples) = (0.0, 0.0, 0.0);
    for _ in 0..300 {
        let before: Vec<(Vector3<f64>, Vector3<f64>)> = (0..n)
            .map(|i| (centre(sim.scene(), i), sim.scene().dir(i).unwrap()))
            .collect();
        sim.run(h).unwrap();
        for (i, (c, nd)) in before.iter().enumerate() {
            trans += (centre(sim.scene(), i) - c).norm_squared();
            rot += 1.0 - nd.dot(&sim.scene().dir(i).unwrap());
            samples += 1.0;
        }
    }
    let d_t = trans / samples / (6.0 * h);
    let turn = rot / samples;
    let want_turn = 1.0 - (-2.0 * rd.rotation * h).exp();
    assert!(
        (d_t / rd.translation() - 1.0).abs() < 0.01,
        "D_t {d_t:e} against {:e}",
        rd.translation()
    );
    assert!(
        (turn / want_turn - 1.0).abs() < 0.01,
        "1 - N.N' {turn:e} against {want_turn:e}"
    );
}

/// The noise is a function of the seed and the step count: a run saved and loaded half way goes
/// on bitwise as the run that was not, and a run split in two follows the run in one go (to the
/// rounding of their step sizes); another seed gives another path; and the Lanczos noise of 600
/// spheres (parallel pair kernel) is bitwise the same on 1 and 2 threads.
#[test]
fn noisy_runs_are_reproducible() {
    let pair = || {
        let mut s = common::mirror_inwards(10.0, true);
        s.set_temperature(300.0).unwrap();
        s.set_seed(5);
        s
    };
    let mut whole = Simulation::new(pair());
    whole.run_periods(0.2).unwrap();
    let mut split = Simulation::new(pair());
    split.run_periods(0.1).unwrap();
    let json = split.scene().to_json().unwrap();
    assert!(json.contains("\"temperature\": 300") || json.contains("\"temperature\":300"));
    split.run_periods(0.1).unwrap();
    let mut loaded = Simulation::new(Scene::from_json(&json).unwrap());
    loaded.run_periods(0.1).unwrap();
    // Loaded and split take the same steps: bitwise. The run in one go takes steps that differ
    // from the split run's in the last bits (equal steps over 0.2 T, not 0.1 T twice), so its
    // state agrees to rounding, where another noise path would differ entirely.
    assert_eq!(split.scene().raw_state().0, loaded.scene().raw_state().0);
    let close = |a: &Scene, b: &Scene| {
        (0..2).all(|i| {
            let (x, y) = (a.displacement(i).unwrap(), b.displacement(i).unwrap());
            (x - y).norm() < 1e-9 * x.norm()
        })
    };
    assert!(close(whole.scene(), split.scene()));
    let mut other = pair();
    other.set_seed(6);
    let mut other = Simulation::new(other);
    other.run_periods(0.2).unwrap();
    assert!(!close(whole.scene(), other.scene()));

    let big = || {
        let mut s = swimlab::engine::build::lattice_scene(300, Model::Micro).unwrap();
        s.set_temperature(300.0).unwrap();
        s.set_noise_root(NoiseRoot::Lanczos);
        let dt = 0.1 / s.stiff_rate();
        s.set_integrator(Some(IntegratorSpec::Euler { dt }));
        (s, dt)
    };
    let states: Vec<Vec<f64>> = [1, 2]
        .iter()
        .map(|&threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let (s, dt) = big();
                let mut sim = Simulation::new(s);
                sim.run(2.0 * dt).unwrap();
                sim.scene().raw_state().0.to_vec()
            })
        })
        .collect();
    assert_eq!(states[0], states[1]);
}

/// What noise refuses, each with the reason and the fix.
#[test]
fn noise_refuses_what_it_cannot_do() {
    let run = |s: Scene| {
        Simulation::new(s)
            .run_periods(0.01)
            .unwrap_err()
            .to_string()
    };
    let hot = || {
        let mut s = common::mirror_inwards(10.0, true);
        s.set_temperature(300.0).unwrap();
        s
    };
    let mut s = hot();
    s.set_model(Model::Rigid);
    assert!(run(s).contains("not available in the rigid-stroke model"));
    for spec in [
        IntegratorSpec::Rk4 { dt: 1e-6 },
        IntegratorSpec::Dopri5 { rtol: 1e-6 },
        IntegratorSpec::Rosw { rtol: 1e-6 },
        IntegratorSpec::stroboscopic(1e-3).unwrap(),
        IntegratorSpec::auto(1e-3).unwrap(),
    ] {
        let mut s = hot();
        s.set_integrator(Some(spec));
        let e = run(s);
        assert!(
            e.contains("deterministic method and cannot carry thermal noise"),
            "{e}"
        );
    }
    let mut s = hot();
    s.set_model(Model::Averaged);
    s.set_integrator(Some(IntegratorSpec::Platen { dt: 1e-4 }));
    assert!(run(s).contains("unit sphere"));
    let mut s = swimlab::engine::build::lattice_scene(17, Model::Micro).unwrap();
    s.set_temperature(300.0).unwrap();
    s.set_integrator(Some(IntegratorSpec::Platen { dt: 1e-7 }));
    assert!(run(s).contains("at most 16 swimmers"));
    let mut s = hot();
    s.set_backend(swimlab::engine::Backend::Auto);
    let info = Simulation::new(s).backend_info().unwrap();
    assert!(
        info.contains("thermal noise (temperature above 0) runs on the CPU only"),
        "{info}"
    );
    let mut s = hot();
    assert!(s.set_temperature(-1.0).is_err());
    assert!(s.set_temperature(f64::NAN).is_err());
    assert!(s.set_lanczos_tol(0.0).is_err());
    s.set_temperature(0.0).unwrap();
    let e = Simulation::new(s)
        .measure(&swimlab::engine::Observable::Peclet(0, 1))
        .unwrap_err()
        .to_string();
    assert!(e.contains("at temperature 0 nothing diffuses"), "{e}");
}

/// The Péclet number scales as size^(3/2) and frequency^(1/2): the drift grows with the size
/// and the frequency, the diffusion coefficient falls as 1/size (averaged model, where both are
/// exact in the scale; to 1e-9).
#[test]
fn the_peclet_number_scales_with_size_and_frequency() {
    let pe = |scale: f64, omega: f64| {
        let base = paper_swimmer();
        let d = Dumbbell {
            a1: base.a1 * scale,
            a2: base.a2 * scale,
            ell: base.ell * scale,
            lambda: base.lambda * scale,
            omega,
            ..base
        };
        let mut s = Scene::new();
        s.add(d, Vector3::zeros(), -Vector3::x()).unwrap();
        s.add(
            Dumbbell {
                phase: std::f64::consts::FRAC_PI_2,
                ..d
            },
            Vector3::new(10.0 * d.ell, 0.0, 0.0),
            Vector3::x(),
        )
        .unwrap();
        s.set_model(Model::Averaged);
        s.set_temperature(300.0).unwrap();
        Simulation::new(s)
            .measure(&swimlab::engine::Observable::Peclet(0, 1))
            .unwrap()[0]
    };
    let p0 = pe(1.0, 500.0);
    assert!(
        p0 > 0.0 && p0 < 1e-2,
        "the paper's pair is diffusion-dominated: Pe = {p0:e}"
    );
    assert!((pe(2.0, 500.0) / p0 / 2f64.powf(1.5) - 1.0).abs() < 1e-9);
    assert!((pe(1.0, 2000.0) / p0 / 2.0 - 1.0).abs() < 1e-9);
}
