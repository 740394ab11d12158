//! Swimmers above a no-slip wall: the Rotne-Prager-Blake mobility against the exact one-sphere
//! results, its symmetry and positive definiteness near the wall, its far field; the wall as a
//! body (repulsion, guard, observables); external forces; and the Boltzmann distribution of
//! Brownian dumbbells sedimenting onto the wall, with and without the drift kT ∇·M.

use crate::common;
use nalgebra::{DMatrix, DVector, Vector3};
use rayon::prelude::*;
use std::f64::consts::PI;
use swimlab::engine::mobility::{self_mobility, MobilityOperator};
use swimlab::engine::thermal::{lanczos, BOLTZMANN};
use swimlab::engine::wall::{Wall, WallMobility};
use swimlab::engine::{Dumbbell, IntegratorSpec, Mobility, Model, Scene, Simulation};

const MU: f64 = 1e-3;

/// A small deterministic generator (xorshift) so the configurations are reproducible.
struct Rng(u64);
impl Rng {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn wall_at(z: f64) -> WallMobility {
    WallMobility::new(MU, Mobility::Rpy, Wall::at(z).unwrap())
}

/// (μ_∥, μ_⊥) of one sphere of radius `a` at height `h` above the wall, over 1/(6πμa).
fn one_sphere(a: f64, h: f64) -> (f64, f64) {
    let op = wall_at(0.0);
    let x = Vector3::new(0.0, 0.0, h);
    let m = op.block(&x, &x, a, a, true) / self_mobility(MU, a);
    assert!(m[(0, 0)] == m[(1, 1)] && m[(0, 1)] == 0.0 && m[(0, 2)] == 0.0);
    (m[(0, 0)], m[(2, 2)])
}

/// Brenner's exact perpendicular mobility (1961) over 1/(6πμa): 1/λ with
/// λ = (4/3) sinh α Σ n(n+1)/((2n−1)(2n+3)) [(2 sinh(2n+1)α + (2n+1) sinh 2α) /
/// (4 sinh²(n+½)α − (2n+1)² sinh² α) − 1], cosh α = h/a.
fn brenner_perpendicular(h_over_a: f64) -> f64 {
    let alpha = h_over_a.acosh();
    let mut sum = 0.0;
    for n in 1..400 {
        let n = n as f64;
        let num = 2.0 * ((2.0 * n + 1.0) * alpha).sinh() + (2.0 * n + 1.0) * (2.0 * alpha).sinh();
        let den = 4.0 * ((n + 0.5) * alpha).sinh().powi(2)
            - (2.0 * n + 1.0).powi(2) * alpha.sinh().powi(2);
        let term = n * (n + 1.0) / ((2.0 * n - 1.0) * (2.0 * n + 3.0)) * (num / den - 1.0);
        sum += term;
        if term.abs() < 1e-17 * sum.abs() {
            break;
        }
    }
    1.0 / (4.0 / 3.0 * alpha.sinh() * sum)
}

/// Faxén's series for the parallel mobility over 1/(6πμa), x = a/h: the method of reflections
/// to (a/h)⁵, which Goldman, Cox & Brenner (1967) confirm within 1% down to h/a ≈ 1.5.
fn faxen_parallel(x: f64) -> f64 {
    1.0 - 9.0 / 16.0 * x + x.powi(3) / 8.0 - 45.0 / 256.0 * x.powi(4) - x.powi(5) / 16.0
}

/// One sphere: the Rotne-Prager-Blake self mobility is Swan & Brady's series
/// μ_∥ = 1 − 9/16 x + 1/8 x³ − 1/16 x⁵ and μ_⊥ = 1 − 9/8 x + 1/2 x³ − 1/8 x⁵ (x = a/h) to
/// round-off, and its own error against the exact results is what the series leaves out: the
/// x⁴ terms (45/256 x⁴ parallel; ≈ 0.57 x⁴ perpendicular, from Brenner's sum), so below
/// 0.6 x⁴ + 2 x⁶ at every height. The table is printed for the book (`cargo test --test walls
/// -- --nocapture one_sphere`).
#[test]
fn one_sphere_against_swan_brady_brenner_and_faxen() {
    let a = 1e-6;
    println!("h/a  mu_par(RPB)  Faxen  err  mu_perp(RPB)  Brenner  err");
    for h_over_a in [1.05, 1.2, 1.5, 2.0, 3.0, 5.0, 10.0] {
        let (par, perp) = one_sphere(a, h_over_a * a);
        let x = 1.0 / h_over_a;
        let sb_par = 1.0 - 9.0 / 16.0 * x + x.powi(3) / 8.0 - x.powi(5) / 16.0;
        let sb_perp = 1.0 - 9.0 / 8.0 * x + x.powi(3) / 2.0 - x.powi(5) / 8.0;
        assert!(
            (par - sb_par).abs() < 1e-14,
            "h/a {h_over_a}: {par} vs {sb_par}"
        );
        assert!(
            (perp - sb_perp).abs() < 1e-14,
            "h/a {h_over_a}: {perp} vs {sb_perp}"
        );
        let exact_perp = brenner_perpendicular(h_over_a);
        let fax = faxen_parallel(x);
        println!(
            "{h_over_a:5.2} {par:.6} {fax:.6} {:+.2e} {perp:.6} {exact_perp:.6} {:+.2e}",
            par - fax,
            perp - exact_perp
        );
        let bound = 0.6 * x.powi(4) + 2.0 * x.powi(6);
        assert!((perp - exact_perp).abs() < bound, "h/a {h_over_a}");
        if h_over_a >= 1.5 {
            assert!((par - fax).abs() < bound, "h/a {h_over_a}");
        }
    }
    // Far from the wall the corrections fall off as (9/16, 9/8) a/h.
    let (par, perp) = one_sphere(a, 1e4 * a);
    assert!(((1.0 - par) * 1e4 - 9.0 / 16.0).abs() < 1e-6);
    assert!(((1.0 - perp) * 1e4 - 9.0 / 8.0).abs() < 1e-6);
}

/// `n` spheres of radii in [0.5, 1.5] µm at heights from 1.05 radii up, in a region small
/// enough that many pairs overlap.
fn near_wall_spheres(rng: &mut Rng, n: usize, lift: f64) -> (Vec<Vector3<f64>>, Vec<f64>) {
    let mut pos = Vec::new();
    let mut radii = Vec::new();
    for _ in 0..n {
        let a = 0.5e-6 + 1e-6 * rng.uniform();
        let h = a * (lift + 3.0 * rng.uniform() * rng.uniform());
        pos.push(Vector3::new(
            4e-6 * rng.uniform(),
            4e-6 * rng.uniform(),
            h - 2e-6,
        ));
        radii.push(a);
    }
    (pos, radii)
}

/// Symmetric and positive definite for random unequal spheres from 1.05 radii above the wall,
/// overlapping pairs included (Zuk's form for them), and for spheres within one radius of it
/// (the damped form): the smallest eigenvalue stays positive, and the Lanczos square root
/// converges and agrees with the dense one. Symmetry is exact in the construction (each pair
/// block is computed once and transposed), so it holds to round-off of the largest entry.
#[test]
fn symmetric_positive_definite_near_the_wall_with_overlaps() {
    let mut rng = Rng(0x2545f4914f6cdd1d);
    let mut overlapping = 0;
    for trial in 0..60 {
        let n = 4 + trial % 12;
        let lift = if trial % 3 == 2 { 0.3 } else { 1.05 };
        let (pos, radii) = near_wall_spheres(&mut rng, n, lift);
        for a in 0..n {
            for b in a + 1..n {
                if (pos[a] - pos[b]).norm() < radii[a] + radii[b] {
                    overlapping += 1;
                }
            }
        }
        let mut op = WallMobility::new(MU, Mobility::Rpy, Wall::at(-2e-6).unwrap());
        let m = op.matrix(&pos, &radii);
        let scale = m.amax();
        assert!(
            (&m - m.transpose()).amax() <= 1e-15 * scale,
            "trial {trial}"
        );
        let eig = m.clone().symmetric_eigenvalues();
        assert!(
            eig.min() > 0.0,
            "trial {trial}: smallest eigenvalue {}",
            eig.min()
        );
        // Lanczos through the operator's product against the dense square root.
        let w = DVector::from_fn(3 * n, |_, _| rng.uniform() - 0.5);
        let mut apply = |v: &[f64], out: &mut [f64]| {
            let f: Vec<Vector3<f64>> = v.chunks(3).map(Vector3::from_column_slice).collect();
            let mut u = vec![Vector3::zeros(); n];
            op.interaction_velocities(&pos, &radii, &f, &mut u);
            for (k, (u, a)) in u.iter().zip(&radii).enumerate() {
                let v = u + f[k] * self_mobility(MU, *a);
                out[3 * k..3 * k + 3].copy_from_slice(v.as_slice());
            }
        };
        let mut root = vec![0.0; 3 * n];
        lanczos::sqrt_times(&mut apply, w.as_slice(), 1e-10, &mut root)
            .unwrap_or_else(|e| panic!("trial {trial}: Lanczos failed: {e:?}"));
        let se = m.symmetric_eigen();
        let sqrt = &se.eigenvectors
            * DMatrix::from_diagonal(&se.eigenvalues.map(f64::sqrt))
            * se.eigenvectors.transpose();
        let dense = sqrt * &w;
        let err = (DVector::from_column_slice(&root) - &dense).amax() / dense.amax();
        assert!(err < 1e-8, "trial {trial}: Lanczos against dense: {err:e}");
    }
    assert!(
        overlapping > 20,
        "only {overlapping} overlapping pairs were tried"
    );
}

/// The operator's product, blocks and matrix are one mobility, damped spheres included:
/// M F = D F + W F to round-off of the largest velocity, for a set that takes the serial pair
/// loop and one that takes the parallel one (from 64 spheres on).
#[test]
fn product_blocks_and_matrix_agree() {
    let mut rng = Rng(0x1234_5678_9abc_def1);
    for (n, lift) in [(12, 1.05), (12, 0.4), (80, 0.4)] {
        let (pos, radii) = near_wall_spheres(&mut rng, n, lift);
        let mut op = WallMobility::new(MU, Mobility::Rpy, Wall::at(-2e-6).unwrap());
        let forces: Vec<Vector3<f64>> = (0..n)
            .map(|_| Vector3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 1e-12)
            .collect();
        let mut u = vec![Vector3::zeros(); n];
        op.interaction_velocities(&pos, &radii, &forces, &mut u);
        let m = op.matrix(&pos, &radii);
        let f = DVector::from_iterator(3 * n, forces.iter().flat_map(|f| f.iter().copied()));
        let mf = &m * &f;
        for k in 0..n {
            let v = u[k] + forces[k] * self_mobility(MU, radii[k]);
            for c in 0..3 {
                assert!(
                    (v[c] - mf[3 * k + c]).abs() <= 1e-13 * mf.amax(),
                    "{n} spheres, lift {lift}"
                );
            }
        }
    }
}

/// Far from the wall the pair blocks tend to open space's as a/h: h/a ·|M − M_open| settles to
/// a constant as h grows (the image Stokeslet's 1/(2h) against the pair's own distance).
#[test]
fn far_from_the_wall_the_mobility_tends_to_open_space() {
    let (a1, a2) = (1e-6, 0.6e-6);
    let r = Vector3::new(3e-6, 1e-6, 0.5e-6);
    let mut scaled = Vec::new();
    for h_over_a in [1e2, 1e3, 1e4, 1e5] {
        let h = h_over_a * a1;
        let op = wall_at(0.0);
        let xa = Vector3::new(0.0, 0.0, h);
        let xb = xa + r;
        let open = Mobility::Rpy.pair_tensor(MU, &(xa - xb), a1, a2);
        let wall = op.block(&xa, &xb, a1, a2, false);
        scaled.push((wall - open).amax() * h_over_a / self_mobility(MU, a1));
    }
    for w in scaled.windows(2) {
        assert!((w[1] - w[0]).abs() < 0.02 * w[1], "{scaled:?}");
    }
}

/// The divergence of one sphere's mobility is the slope of its perpendicular mobility,
/// d μ_⊥/dh = (1/(6πμa)) (9/8 a/h² − 3/2 a³/h⁴ + 5/8 a⁵/h⁶) along z; the central differences
/// behind it are good to ~1e-9 relative.
#[test]
fn the_divergence_of_one_sphere_is_the_slope_of_its_perpendicular_mobility() {
    let a = 1e-6;
    let op = wall_at(0.0);
    for h_over_a in [1.1, 1.5, 3.0, 10.0] {
        let h = h_over_a * a;
        let mut div = [Vector3::zeros()];
        assert!(op.divergence(&[Vector3::new(1e-6, 0.0, h)], &[a], &mut div));
        let x = a / h;
        let slope =
            self_mobility(MU, a) / a * (9.0 / 8.0 * x * x - 1.5 * x.powi(4) + 0.625 * x.powi(6));
        assert!(div[0].x == 0.0 && div[0].y == 0.0);
        assert!(((div[0].z - slope) / slope).abs() < 1e-7, "h/a {h_over_a}");
    }
}

fn swimmer_at(s: &mut Scene, d: Dumbbell, center: [f64; 3], dir: [f64; 3]) -> usize {
    s.add(d, Vector3::from(center), Vector3::from(dir)).unwrap()
}

/// The wall as a body: the repulsion keeps a sinking dumbbell off it, the guard names a sphere
/// that touches it, and the wall refuses what it cannot go with (a box, the averaged model, the
/// GPU); the observables measure from it.
#[test]
fn the_wall_as_a_body() {
    let d = Dumbbell::default();
    let mut s = Scene::new();
    s.set_wall(Some(Wall::at(0.0).unwrap())).unwrap();
    // A swimmer reaching into the wall is refused, the scene unchanged.
    let e = s
        .add(d, Vector3::new(0.0, 0.0, 0.5e-6), Vector3::x())
        .unwrap_err();
    assert!(e.to_string().contains("above the wall"), "{e}");
    assert_eq!(s.count(), 0);
    swimmer_at(&mut s, d, [0.0, 0.0, 3e-6], [1.0, 0.0, 1.0]);
    let w = swimlab::engine::Observable::Height(0).evaluate(&s).unwrap()[0];
    assert!((w - 3e-6).abs() < 1e-18);
    let angle = swimlab::engine::Observable::WallAngle(0)
        .evaluate(&s)
        .unwrap()[0];
    assert!((angle - PI / 4.0).abs() < 1e-12);
    // A box with a wall is refused both ways.
    assert!(s.set_box(Some([1e-4; 3])).is_err());
    let mut boxed = Scene::new();
    boxed.set_box(Some([1e-4; 3])).unwrap();
    assert!(boxed.set_wall(Some(Wall::at(-4e-5).unwrap())).is_err());
    // Averaged model and GPU: refused with the reason.
    let mut avg = s.clone();
    avg.set_model(Model::Averaged);
    let e = avg
        .system()
        .err()
        .expect("averaged with a wall must be refused");
    assert!(e.to_string().contains("no wall equations"), "{e}");
    assert!(swimlab::engine::gpu::support::supports(&s)
        .unwrap_err()
        .contains("wall"));
    // Saved and loaded exactly.
    let back = Scene::from_json(&s.to_json().unwrap()).unwrap();
    assert_eq!(back.wall(), s.wall());
    // Sinking under a strong force with a soft, short repulsion: the guard names the sphere.
    let mut sink = Scene::new();
    let weak = Wall {
        range: 1e-8,
        stiffness: 1e-9,
        ..Wall::at(0.0).unwrap()
    };
    sink.set_wall(Some(weak)).unwrap();
    swimmer_at(&mut sink, d, [0.0, 0.0, 1.5e-6], [1.0, 0.0, 0.0]);
    sink.set_external_force([0.0, 0.0, -1e-9]).unwrap();
    let mut sim = Simulation::new(sink);
    let e = sim.run(0.05).unwrap_err();
    assert!(e.to_string().contains("touched the wall"), "{e}");
    // With the default repulsion the same force is held off the wall.
    let mut held = Scene::new();
    held.set_wall(Some(Wall::at(0.0).unwrap())).unwrap();
    swimmer_at(&mut held, d, [0.0, 0.0, 1.5e-6], [1.0, 0.0, 0.0]);
    held.set_external_force([0.0, 0.0, -1e-11]).unwrap();
    let mut sim = Simulation::new(held);
    sim.run(0.05).unwrap();
    let gap = swimlab::engine::Observable::WallGap
        .evaluate(sim.scene())
        .unwrap()[0];
    assert!(gap > 0.0 && gap < 1e-7, "gap {gap:e}");
}

/// Two equal spheres of a passive dumbbell under the same force F across their line of
/// centres move together at (1/(6πμa) + c_I(ℓ)) F, RPY's pair coefficient: the external force
/// enters the spring model and the rigid-stroke model alike. Gravity is the buoyant weight.
#[test]
fn an_external_force_moves_a_passive_dumbbell_at_the_two_sphere_mobility() {
    let d = Dumbbell {
        lambda: 0.0,
        ..Dumbbell::default()
    };
    let f = 1e-13;
    let (ci, _) = Mobility::Rpy.pair_coefficients(MU, d.ell, d.a1, d.a2);
    let expected = (self_mobility(MU, d.a1) + ci) * f;
    for model in [Model::Micro, Model::Rigid] {
        let mut s = Scene::new();
        s.set_model(model);
        swimmer_at(&mut s, d, [0.0; 3], [1.0, 0.0, 0.0]);
        s.set_external_force([0.0, 0.0, f]).unwrap();
        let (v, spin) = s.rates(0).unwrap();
        assert!(
            ((v.z - expected) / expected).abs() < 1e-12,
            "{model:?}: {v:?}"
        );
        assert!(
            v.x.abs() < 1e-12 * expected && spin.norm() < 1e-9,
            "{model:?}"
        );
    }
    let mut s = Scene::new();
    swimmer_at(&mut s, d, [0.0; 3], [1.0, 0.0, 0.0]);
    let (rho_s, rho_f, g) = (1050.0, 1000.0, 9.81);
    s.set_gravity(Some(swimlab::engine::forces::Gravity {
        g,
        density: rho_s,
        fluid_density: rho_f,
    }))
    .unwrap();
    let weight = 4.0 / 3.0 * PI * d.a1.powi(3) * (rho_s - rho_f) * g;
    let (v, _) = s.rates(0).unwrap();
    let expected = -(self_mobility(MU, d.a1) + ci) * weight;
    assert!(((v.z - expected) / expected).abs() < 1e-12);
}

/// The rigid-stroke model near the wall agrees with a stiff spring model: the wall's blocks
/// enter the constraint solve, and its repulsion and an external force the tensions' right-hand
/// side. With k0 = 1 N/m the spring follows L(t) to ~λω/rate ≈ 2e-5 λ, which moves the centre
/// by a like fraction of its drift: 1e-3 of a period's displacement holds with room.
#[test]
fn the_rigid_stroke_model_near_the_wall_agrees_with_a_stiff_spring() {
    let d = Dumbbell {
        k0: 1.0,
        ..Dumbbell::default()
    };
    let run = |model: Model| {
        let mut s = Scene::new();
        s.set_wall(Some(Wall::at(0.0).unwrap())).unwrap();
        s.set_model(model);
        swimmer_at(&mut s, d, [0.0, 0.0, 2.5e-6], [1.0, 0.0, 0.3]);
        s.set_external_force([0.0, 0.0, -2e-14]).unwrap();
        s.set_integrator(Some(IntegratorSpec::Dopri5 { rtol: 1e-9 }));
        let mut sim = Simulation::new(s);
        sim.run(d.period()).unwrap();
        sim.scene().center(0).unwrap()
    };
    let (micro, rigid) = (run(Model::Micro), run(Model::Rigid));
    let moved = (micro - Vector3::new(0.0, 0.0, 2.5e-6)).norm();
    assert!(moved > 1e-9, "the swimmer did not move ({moved:e} m)");
    assert!(
        (micro - rigid).norm() < 1e-3 * moved,
        "micro {micro:?} rigid {rigid:?} moved {moved:e}"
    );
}

/// The mean height above the wall of a dumbbell's geometric centre in the Boltzmann
/// distribution of U = F(z₁ + z₂) + k0(r − ℓ)²/2 + U_w(z₁) + U_w(z₂), by quadrature over the
/// centre's height, the length r (weight r²) and cos θ of the dumbbell vector (U_w: the wall's
/// harmonic repulsion; the region where a sphere would be in the wall carries e^{-40} or less).
fn boltzmann_mean_height(d: &Dumbbell, wall: &Wall, force: f64, kt: f64) -> f64 {
    let a = d.a1;
    let uw = |z: f64| {
        let gap = z - wall.z - a;
        if gap < wall.range {
            0.5 * wall.stiffness * (wall.range - gap).powi(2)
        } else {
            0.0
        }
    };
    let sigma = (kt / d.k0).sqrt();
    let (nz, nu, nr) = (3000, 200, 41);
    let z_top = wall.z + d.ell + 40.0 * kt / (2.0 * force);
    let (mut num, mut den) = (0.0, 0.0);
    for ir in 0..nr {
        let r = d.ell + sigma * (-5.0 + 10.0 * ir as f64 / (nr - 1) as f64);
        let wr = r * r * (-0.5 * d.k0 * (r - d.ell).powi(2) / kt).exp();
        for iu in 0..nu {
            let u = -1.0 + (iu as f64 + 0.5) * 2.0 / nu as f64;
            for iz in 0..nz {
                let z = wall.z + (iz as f64 + 0.5) * (z_top - wall.z) / nz as f64;
                let (z1, z2) = (z - 0.5 * r * u, z + 0.5 * r * u);
                if z1 - wall.z - a <= 0.0 || z2 - wall.z - a <= 0.0 {
                    continue;
                }
                let e = force * (z1 + z2) + uw(z1) + uw(z2);
                let w = wr * (-e / kt).exp();
                num += w * (z - wall.z);
                den += w;
            }
        }
    }
    num / den
}

/// Mean and standard error of the per-run means `m` (independent runs).
fn mean_and_error(m: &[f64]) -> (f64, f64) {
    let n = m.len() as f64;
    let mean = m.iter().sum::<f64>() / n;
    let var = m.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// The sedimentation runs: `runs` independent passive dumbbells (own seeds) under a downward
/// force on each sphere above the wall, Euler-Maruyama at `dt`; each run's mean height of R_H
/// over `samples` samples `every` steps apart after a burn-in.
fn sediment(drift: bool, runs: u64, samples: usize, every: usize, dt: f64) -> Vec<f64> {
    let (d, wall, force) = sedimentation_setup();
    (0..runs)
        .into_par_iter()
        .map(|seed| {
            let mut s = Scene::new();
            s.set_wall(Some(Wall { drift, ..wall })).unwrap();
            s.add(d, Vector3::new(0.0, 0.0, d.a1 + 1e-6), Vector3::x())
                .unwrap();
            s.set_external_force([0.0, 0.0, -force]).unwrap();
            s.set_temperature(300.0).unwrap();
            s.set_seed(1000 + seed);
            s.set_integrator(Some(IntegratorSpec::Euler { dt }));
            let mut sim = Simulation::new(s);
            sim.run(10.0).unwrap();
            let mut sum = 0.0;
            for _ in 0..samples {
                sim.run(every as f64 * dt).unwrap();
                sum += sim.scene().center(0).unwrap().z - wall.z;
            }
            sum / samples as f64
        })
        .collect()
}

/// Passive symmetric dumbbells (a = 0.5 µm, ℓ = 2.5 µm, a soft spring of k0 = 1e-7 N/m whose
/// thermal length fluctuation is 0.08 ℓ), a wall at z = 0 repelling within 0.25 µm with 20 kT
/// at contact, and a force kT/(1 µm) down on each sphere: a gravitational length of 0.5 µm for
/// the dumbbell, so it lives where the wall changes the mobility most.
fn sedimentation_setup() -> (Dumbbell, Wall, f64) {
    let kt = BOLTZMANN * 300.0;
    let d = Dumbbell {
        a1: 0.5e-6,
        a2: 0.5e-6,
        ell: 2.5e-6,
        lambda: 0.0,
        k0: 1e-7,
        ..Dumbbell::default()
    };
    let range = 0.25e-6;
    let wall = Wall {
        range,
        stiffness: 40.0 * kt / (range * range),
        ..Wall::at(0.0).unwrap()
    };
    (d, wall, kt / 1e-6)
}

/// PyStokes's `wallBounded` matrix for equal spheres of radius `a` at `pos` (wall at z = 0), or
/// `None` (test skipped) without a Python that has PyStokes.
fn pystokes_wall_matrix(pos: &[Vector3<f64>], a: f64) -> Option<DMatrix<f64>> {
    use std::io::Write;
    use std::process::{Command, Stdio};
    let py = common::python_with(
        "pystokes.wallBounded",
        "SWIMLAB_REQUIRE_PYSTOKES",
        "pip install pystokes into SWIMLAB_PYTHON's environment, or run .ci/run",
    )?;
    let script =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/peers/pystokes_wall.py");
    let mut child = Command::new(py)
        .arg(script)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("python starts");
    let mut input = format!("{MU:e} {a:e}");
    for x in pos {
        input += &format!(" {:e} {:e} {:e}", x.x, x.y, x.z);
    }
    child
        .stdin
        .take()
        .unwrap()
        .write_all(input.as_bytes())
        .unwrap();
    let out = child.wait_with_output().expect("python runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let values: Vec<f64> = String::from_utf8(out.stdout)
        .unwrap()
        .split_whitespace()
        .map(|v| v.parse().unwrap())
        .collect();
    let n = 3 * pos.len();
    assert_eq!(values.len(), n * n);
    Some(DMatrix::from_row_slice(n, n, &values))
}

/// Pairs of equal spheres against PyStokes's `wallBounded` (Singh & Adhikari), a real peer run
/// from Python. Its self blocks are Swan & Brady's series, as swimlab's are. Its pair blocks
/// are Blake's point-force tensor plus finite-size terms; in the point limit (PyStokes with a
/// vanishing radius) they are Blake's tensor, which swimlab's Oseen kind uses for pairs above a
/// wall. PyStokes's finite-size pair terms are not the Rotne-Prager-Blake tensor: its matrix is
/// not symmetric (M_ij ≠ M_ji^T by several per cent here), where swimlab's RPY wall mobility is
/// symmetric to round-off (the test above); the difference is printed for the docs.
#[test]
fn pairs_of_equal_spheres_against_pystokes() {
    let a = 1e-6;
    let mut rng = Rng(0x5eed_f00d);
    let pos: Vec<Vector3<f64>> = (0..6)
        .map(|_| {
            Vector3::new(
                8e-6 * rng.uniform(),
                8e-6 * rng.uniform(),
                a * (1.2 + 4.0 * rng.uniform()),
            )
        })
        .collect();
    let Some(theirs) = pystokes_wall_matrix(&pos, a) else {
        return;
    };
    let Some(point) = pystokes_wall_matrix(&pos, 1e-9 * a) else {
        return;
    };
    let radii = vec![a; pos.len()];
    let oseen = WallMobility::new(MU, Mobility::Oseen, Wall::at(0.0).unwrap()).matrix(&pos, &radii);
    let rpy = wall_at(0.0).matrix(&pos, &radii);
    let n = pos.len();
    let (mut pair_scale, mut pair_err, mut self_err, mut asym, mut rpy_vs_theirs) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for i in 0..n {
        for j in 0..n {
            let block = |m: &DMatrix<f64>| m.fixed_view::<3, 3>(3 * i, 3 * j).clone_owned();
            if i == j {
                // Self blocks: the same series on both sides, compared relative to μ0.
                self_err =
                    self_err.max((block(&rpy) - block(&theirs)).abs().max() / self_mobility(MU, a));
            } else {
                pair_scale = pair_scale.max(block(&point).abs().max());
                pair_err = pair_err.max((block(&oseen) - block(&point)).abs().max());
                let transposed = theirs.fixed_view::<3, 3>(3 * j, 3 * i).transpose();
                asym = asym.max((block(&theirs) - transposed).abs().max());
                rpy_vs_theirs = rpy_vs_theirs.max((block(&rpy) - block(&theirs)).abs().max());
            }
        }
    }
    eprintln!(
        "PyStokes wallBounded, {n} spheres 1.2-5.2 radii above the wall: Blake pairs differ by {:.1e}, self blocks by {self_err:.1e} of μ0; PyStokes's finite-size pairs: asymmetry {:.1e}, difference from the Rotne-Prager-Blake pairs {:.1e} (relative to the largest pair block)",
        pair_err / pair_scale,
        asym / pair_scale,
        rpy_vs_theirs / pair_scale,
    );
    // Both sides are closed forms in f64, so round-off (~1e-14) is all that separates them; 1e-10
    // leaves a ten-thousandfold margin.
    assert!(pair_err < 1e-10 * pair_scale, "{}", pair_err / pair_scale);
    assert!(self_err < 1e-10, "{self_err}");
}

/// Sedimentation equilibrium: Brownian passive dumbbells under a constant downward force reach
/// the Boltzmann (barometric) distribution above the wall, with the wall's excluded region,
/// only with the drift kT ∇·M: without it they crowd where the mobility is small, near the wall.
/// Compared by the mean height of R_H against its quadrature: the drift run lands within 4
/// standard errors of independent runs plus 1 % for Euler-Maruyama's O(dt) bias (halving dt
/// moved the mean by 0.04 %, within its statistics), and the run without the drift misses by
/// more than twice that band (measured: 11 % low, 25 standard errors).
#[test]
fn sedimentation_reaches_the_boltzmann_distribution_only_with_the_divergence_drift() {
    let (d, wall, force) = sedimentation_setup();
    let kt = BOLTZMANN * 300.0;
    let exact = boltzmann_mean_height(&d, &wall, force, kt);
    let (runs, samples, every, dt) = (16, 10000, 40, 2.5e-3);
    let (with, with_err) = mean_and_error(&sediment(true, runs, samples, every, dt));
    let (without, without_err) = mean_and_error(&sediment(false, runs, samples, every, dt));
    eprintln!(
        "mean height of R_H: Boltzmann {exact:.4e} m; with the drift {with:.4e} ± {with_err:.1e}; without {without:.4e} ± {without_err:.1e}"
    );
    let band = |err: f64| 4.0 * err + 0.01 * exact;
    assert!(
        (with - exact).abs() < band(with_err),
        "with the drift: {with:e} vs {exact:e}"
    );
    assert!(
        (without - exact).abs() > 2.0 * band(without_err),
        "without the drift the distribution should be off: {without:e} vs {exact:e}"
    );
}

/// The wall's parallel pair terms add up in a fixed order: the same velocities, bit for bit, on
/// one thread and on several (thermal runs' reproducibility rests on it).
#[test]
fn the_parallel_wall_product_is_bitwise_independent_of_the_threads() {
    let mut rng = Rng(0xdead_beef_1234_5678);
    let n = 150;
    let (pos, radii) = near_wall_spheres(&mut rng, n, 0.6);
    let forces: Vec<Vector3<f64>> = (0..n)
        .map(|_| Vector3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 1e-12)
        .collect();
    let product = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut op = WallMobility::new(MU, Mobility::Rpy, Wall::at(-2e-6).unwrap());
            let mut u = vec![Vector3::zeros(); n];
            op.interaction_velocities(&pos, &radii, &forces, &mut u);
            u
        })
    };
    let one = product(1);
    for threads in [2, 3, 7] {
        assert!(product(threads) == one, "{threads} threads differ from one");
    }
}

/// Random placement above a wall takes only places clear of it, so the scene saves and loads.
#[test]
fn random_swimmers_are_placed_above_the_wall() {
    let src = r#"
        let s = scene();
        s.wall = #{ z: 0.0 };
        s.add_random(dumbbell(), 20, 0.01, 7);
        if s.count != 20 || s.observe(wall_gap()) <= 0.0 { throw `placed ${s.count}, gap ${s.observe(wall_gap())}`; }
        s.save("out/tests/walls_random.json");
        if load_scene("out/tests/walls_random.json").count != 20 { throw "not loaded back"; }
    "#;
    swimlab::script::run_source("random above the wall", src, &mut rhai::Scope::new())
        .unwrap_or_else(|e| panic!("{e}"));
}

/// Where the phase places the spheres (the rigid-stroke model), a phase that would put a sphere
/// into the wall is refused, and the scene keeps its phases.
#[test]
fn a_phase_that_would_put_a_sphere_into_the_wall_is_refused() {
    let src = r#"
        let s = scene();
        s.model = "rigid";
        s.wall = #{ z: 0.0 };
        // Sphere 1 sits 5e-8 m above the wall at phase 0; at phase pi/2 the stroke lengthens the
        // dumbbell by lambda and pushes it 2e-7 m into the wall.
        s.add(dumbbell(#{ center: [0.0, 0.0, 3.3e-6], dir: [0.0, 0.0, 1.0] }));
        let refused = false;
        try { s.set_phase(0, pi() / 2.0); } catch (e) { refused = true; }
        if !refused || s.phases[0] != 0.0 { throw "set_phase was not refused"; }
        refused = false;
        try { s.phases = [pi() / 2.0]; } catch (e) { refused = true; }
        if !refused || s.phases[0] != 0.0 { throw "s.phases was not refused"; }
        s.set_phase(0, -pi() / 2.0);                   // shorter: allowed
        if s.observe(wall_gap()) <= 0.0 { throw "gap"; }
    "#;
    swimlab::script::run_source("phase into the wall", src, &mut rhai::Scope::new())
        .unwrap_or_else(|e| panic!("{e}"));
}
