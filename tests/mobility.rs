//! The Rotne-Prager-Yamakawa-Mazur mobility (e:Mazur): symmetric and positive definite for
//! non-overlapping spheres, Stokes drag for one sphere, and the Oseen tensor plus the finite-size
//! r⁻³ term.

use nalgebra::{DVector, Matrix3, Vector3};
use std::f64::consts::PI;
use swimlab::engine::Mobility;

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

/// `n` spheres with radii in [0.5, 1.5] µm, no two overlapping, some nearly touching.
fn random_spheres(rng: &mut Rng, n: usize, box_size: f64) -> (Vec<Vector3<f64>>, Vec<f64>) {
    let mut pos: Vec<Vector3<f64>> = Vec::new();
    let mut radii = Vec::new();
    while pos.len() < n {
        let a = 0.5e-6 + 1e-6 * rng.uniform();
        let x = Vector3::new(rng.uniform(), rng.uniform(), rng.uniform()) * box_size;
        if pos.iter().zip(&radii).all(|(p, r)| (p - x).norm() > a + r) {
            pos.push(x);
            radii.push(a);
        }
    }
    (pos, radii)
}

#[test]
fn symmetric_and_positive_definite_for_random_configurations() {
    let mut rng = Rng(0x9e3779b97f4a7c15);
    for trial in 0..40 {
        let n = 2 + trial % 12;
        // Dense boxes make near contacts, where positive definiteness is tightest.
        let (pos, radii) = random_spheres(&mut rng, n, 4e-6 * (n as f64).cbrt());
        for mob in [Mobility::Rpy, Mobility::Oseen] {
            let m = mob.matrix(MU, &pos, &radii);
            let asym = (&m - m.transpose()).amax() / m.amax();
            assert!(asym < 1e-15, "{mob:?}: asymmetry {asym:e}");
            if mob == Mobility::Rpy {
                // RPY is positive definite for non-overlapping spheres (the Oseen tensor is not
                // guaranteed to be, so only RPY is checked).
                let eig = m.symmetric_eigenvalues();
                let min = eig.min() / eig.max();
                assert!(
                    min > 0.0,
                    "trial {trial}: smallest eigenvalue ratio {min:e}"
                );
            }
        }
    }
}

#[test]
fn one_sphere_is_stokes_drag() {
    let a = 1.3e-6;
    let m = Mobility::Rpy.matrix(MU, &[Vector3::zeros()], &[a]);
    let f = DVector::from_vec(vec![1e-12, -2e-12, 3e-12]);
    let v = &m * &f;
    let expected = &f / (6.0 * PI * MU * a);
    assert!((&v - &expected).amax() < 1e-15 * expected.amax());
}

#[test]
fn oseen_and_rpy_differ_only_by_the_inverse_cube_term() {
    let r: Vector3<f64> = Vector3::new(3e-6, -1e-6, 2e-6);
    let (ai, aj) = (0.7e-6, 1.1e-6);
    let d: f64 = r.norm();
    let rr = r * r.transpose() / (d * d);
    let expected = (ai * ai + aj * aj) / (24.0 * PI * MU * d.powi(3))
        * (Matrix3::<f64>::identity() - 3.0 * rr);
    let diff =
        Mobility::Rpy.pair_tensor(MU, &r, ai, aj) - Mobility::Oseen.pair_tensor(MU, &r, ai, aj);
    assert!((diff - expected).amax() < 1e-14 * expected.amax());
    // And the Oseen tensor itself: (I + r̂r̂)/(8πμr).
    let oseen = (Matrix3::<f64>::identity() + rr) / (8.0 * PI * MU * d);
    let o = Mobility::Oseen.pair_tensor(MU, &r, ai, aj);
    assert!((o - oseen).amax() < 1e-14 * oseen.amax());
}

#[test]
fn interaction_kernel_equals_matrix_product_without_self_terms() {
    let mut rng = Rng(42);
    let (pos, radii) = random_spheres(&mut rng, 9, 8e-6);
    let forces: Vec<Vector3<f64>> = (0..9)
        .map(|_| {
            Vector3::new(
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
            ) * 1e-12
        })
        .collect();
    for mob in [Mobility::Rpy, Mobility::Oseen] {
        let mut u = vec![Vector3::zeros(); 9];
        mob.interaction_velocities(MU, &pos, &radii, &forces, &mut u);
        let m = mob.matrix(MU, &pos, &radii);
        let f = DVector::from_iterator(27, forces.iter().flat_map(|v| v.iter().copied()));
        let v = &m * &f;
        for a in 0..9 {
            let self_part = forces[a] / (6.0 * PI * MU * radii[a]);
            let expect = Vector3::new(v[3 * a], v[3 * a + 1], v[3 * a + 2]) - self_part;
            // Round-off of a 9-term sum against the self term it was separated from.
            assert!((u[a] - expect).norm() < 1e-12 * self_part.norm().max(expect.norm()));
        }
    }
}

/// `n` spheres with radii in [0.5, 1.5] µm placed anywhere in the box: many overlap, some lie
/// inside others.
fn overlapping_spheres(rng: &mut Rng, n: usize, box_size: f64) -> (Vec<Vector3<f64>>, Vec<f64>) {
    let radii = (0..n).map(|_| 0.5e-6 + 1e-6 * rng.uniform()).collect();
    let pos = (0..n)
        .map(|_| Vector3::new(rng.uniform(), rng.uniform(), rng.uniform()) * box_size)
        .collect();
    (pos, radii)
}

// Zuk et al. (2014) built the overlapping form so that the RPY mobility stays positive definite for
// any configuration; Mazur's form alone loses that once spheres overlap. Eigenvalues are compared
// with the largest: a negative one at −1e-3 of it would be a wrong formula, round-off is ~1e-16.
#[test]
fn rpy_stays_positive_definite_when_spheres_overlap() {
    let mut rng = Rng(0x2545f4914f6cdd1d);
    let mut overlapping_configs = 0;
    for trial in 0..60 {
        let n = 2 + trial % 15;
        let (pos, radii) = overlapping_spheres(&mut rng, n, 2e-6 * (n as f64).cbrt());
        let overlaps = (0..n)
            .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
            .any(|(i, j)| (pos[i] - pos[j]).norm() < radii[i] + radii[j]);
        overlapping_configs += overlaps as usize;
        let m = Mobility::Rpy.matrix(MU, &pos, &radii);
        let asym = (&m - m.transpose()).amax() / m.amax();
        assert!(asym < 1e-15, "asymmetry {asym:e}");
        let eig = m.symmetric_eigenvalues();
        let min = eig.min() / eig.max();
        assert!(
            min > 0.0,
            "trial {trial}: smallest eigenvalue ratio {min:e}"
        );
    }
    assert!(overlapping_configs > 50, "the configurations must overlap");
}

// At contact d = a_i + a_j the overlapping form meets Mazur's; at d = |a_i − a_j| (one sphere just
// inside the other) it meets the larger sphere's drag. Both sides are evaluated 1e-9 of a radius
// apart: the tensor's slope is ~1/(μ a²), so the jump allowed is ~1e-9 of the value (2e-9 taken).
#[test]
fn overlapping_form_is_continuous_with_mazur_at_contact_and_with_drag_inside() {
    let r_hat = Vector3::new(2.0, -1.0, 2.0) / 3.0;
    for (ai, aj) in [(1e-6f64, 1e-6f64), (0.7e-6, 1.3e-6), (1.5e-6, 0.4e-6)] {
        let eps = 1e-9 * ai.min(aj);
        for (d, inner) in [(ai + aj, false), ((ai - aj).abs(), true)] {
            if d == 0.0 {
                continue;
            }
            let out = Mobility::Rpy.pair_tensor(MU, &(r_hat * (d + eps)), ai, aj);
            let inn = Mobility::Rpy.pair_tensor(MU, &(r_hat * (d - eps)), ai, aj);
            let jump = (out - inn).amax() / out.amax();
            assert!(
                jump < 2e-9,
                "a = ({ai:e}, {aj:e}), d = {d:e}: jump {jump:e}"
            );
            if inner {
                let drag = Matrix3::identity() / (6.0 * PI * MU * ai.max(aj));
                assert!((inn - drag).amax() < 1e-12 * drag.amax());
            }
        }
    }
    // Equal spheres on top of each other move as one: the block is the single-sphere drag.
    let h = Mobility::Rpy.pair_tensor(MU, &Vector3::new(1e-15, 0.0, 0.0), 1e-6, 1e-6);
    let drag = 1.0 / (6.0 * PI * MU * 1e-6);
    assert!((h[(0, 0)] - drag).abs() < 1e-8 * drag && (h[(1, 1)] - drag).abs() < 1e-8 * drag);
}

/// `Scene::sphere_velocities` against the RPY formula written out for one dumbbell along x
/// (unequal radii, spheres apart): a force on the a1 sphere moves it by Stokes drag and the a2
/// sphere by (1/(4πμd))(1 − (a1² + a2²)/(3d²)) along the line, and (1/(8πμd))(1 + (a1² +
/// a2²)/(3d²)) across it; a wrong count or a non-finite force is refused.
#[test]
fn sphere_velocities_follow_the_rpy_formula() {
    use swimlab::engine::{Dumbbell, Scene};
    let mut s = Scene::default();
    let d = Dumbbell {
        a1: 1.125e-6,
        a2: 0.5625e-6,
        ..Dumbbell::default()
    };
    s.add(d, Vector3::zeros(), Vector3::x()).unwrap();
    let (x1, x2) = s.spheres(0);
    let r = (x2 - x1).norm();
    let sum = d.a1 * d.a1 + d.a2 * d.a2;
    let f = 1e-12;
    let v = s
        .sphere_velocities(&[Vector3::new(f, f, 0.0), Vector3::zeros()])
        .unwrap();
    let along = f / (4.0 * PI * MU * r) * (1.0 - sum / (3.0 * r * r));
    let across = f / (8.0 * PI * MU * r) * (1.0 + sum / (3.0 * r * r));
    let drag = f / (6.0 * PI * MU * d.a1);
    // Each is a handful of flops from the same inputs: round-off only.
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-13 * b.abs();
    assert!(close(v[0].x, drag) && close(v[0].y, drag), "{:?}", v[0]);
    assert!(close(v[1].x, along) && close(v[1].y, across), "{:?}", v[1]);
    assert_eq!(v[1].z, 0.0);
    assert!(s.sphere_velocities(&[Vector3::zeros()]).is_err());
    let bad = s.sphere_velocities(&[Vector3::new(f64::NAN, 0.0, 0.0), Vector3::zeros()]);
    assert!(bad.unwrap_err().to_string().contains("not finite"));
}
