//! The periodic box: the Ewald-summed RPY mobility (Hasimoto's limit, open space's limit,
//! independence of the splitting, the tolerance kept, positive definiteness) and the scene in a box
//! (minimum images, wrapping, filling, saving, the averaged model's cutoff, the GPU's refusal).

use nalgebra::{DVector, Vector3};
use swimlab::engine::build::Rng;
use swimlab::engine::ewald::{hasimoto, Ewald, EwaldMethod};
use swimlab::engine::periodic::PeriodicBox;
use swimlab::engine::{Backend, Dumbbell, Mobility, Model, Scene};

const MU: f64 = 1e-3;

/// `n` spheres of radii 0.5-1.5 µm anywhere in box `b` (not overlapping by minimum image), and a
/// random force on each.
fn random_spheres(
    rng: &mut Rng,
    n: usize,
    b: &PeriodicBox,
) -> (Vec<Vector3<f64>>, Vec<f64>, Vec<Vector3<f64>>) {
    let l = b.sides();
    let (mut pos, mut radii) = (Vec::new(), Vec::new());
    while pos.len() < n {
        let a = 0.5e-6 + 1e-6 * rng.uniform();
        let x = Vector3::new(
            (rng.uniform() - 0.5) * l[0],
            (rng.uniform() - 0.5) * l[1],
            (rng.uniform() - 0.5) * l[2],
        );
        if pos
            .iter()
            .zip(&radii)
            .all(|(p, r): (&Vector3<f64>, &f64)| b.min_image(p - x).norm() > a + r)
        {
            pos.push(x);
            radii.push(a);
        }
    }
    let forces = (0..n)
        .map(|_| Vector3::new(rng.uniform(), rng.uniform(), rng.uniform()).add_scalar(-0.5) * 1e-12)
        .collect();
    (pos, radii, forces)
}

fn velocities(
    e: &Ewald,
    pos: &[Vector3<f64>],
    radii: &[f64],
    f: &[Vector3<f64>],
) -> Vec<Vector3<f64>> {
    let mut u = vec![Vector3::zeros(); pos.len()];
    e.interaction_velocities(pos, radii, f, &mut u);
    u
}

fn max_norm(v: &[Vector3<f64>]) -> f64 {
    v.iter().map(|x| x.norm()).fold(0.0, f64::max)
}

fn max_diff(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).norm())
        .fold(0.0, f64::max)
}

/// Hasimoto: a sphere's self-mobility in a cubic box is (1 − 2.837297 a/L + (4π/3)(a/L)³) of
/// Stokes', here through the scene: one swimmer, a force on its a1 sphere only. The tolerance,
/// 1e-6 a/L, is the six digits of the quoted constant (2.8372974794…); beyond them the sum agrees
/// to 1e-10 (the unit test in src/engine/ewald.rs uses the ten-digit constant).
#[test]
fn a_sphere_in_a_cubic_box_has_hasimotos_mobility() {
    for l in [20e-6, 50e-6, 200e-6] {
        let mut s = Scene::new();
        s.set_box(Some([l; 3])).unwrap();
        // The sums to 1e-12, below the 1e-10 the comparison with `hasimoto` asks.
        s.set_ewald_tol(Some(1e-12)).unwrap();
        let d = Dumbbell::default();
        s.add(d, Vector3::zeros(), Vector3::x()).unwrap();
        let f = Vector3::new(0.0, 0.0, 1e-12);
        let v = s.sphere_velocities(&[f, Vector3::zeros()]).unwrap();
        // The a1 sphere's own velocity; its partner carries no force.
        let got = v[0].z / f.z;
        let x = d.a1 / l;
        let quoted = (1.0 - 2.837297 * x + 4.0 * std::f64::consts::PI / 3.0 * x.powi(3))
            / (6.0 * std::f64::consts::PI * MU * d.a1);
        assert!(
            (got / quoted - 1.0).abs() < 1e-6 * x + 1e-10,
            "L = {l:e}: {got:e} against Hasimoto's {quoted:e}"
        );
        assert!((got / hasimoto(MU, d.a1, l) - 1.0).abs() < 1e-10);
        // And it moves along the force only.
        assert!(v[0].x.abs() < 1e-12 * v[0].z.abs() && v[0].y.abs() < 1e-12 * v[0].z.abs());
    }
}

/// Deep inside a growing box a force-free swimmer pair's velocities tend to open space's: the
/// images of a force-free group are force dipoles, so the difference falls as L⁻³ (measured
/// ratios 7.9-8.0 per doubling; required > 6).
#[test]
fn a_pair_deep_inside_a_growing_box_tends_to_open_space() {
    let d = Dumbbell::default();
    let build = |l: Option<f64>| {
        let mut s = Scene::new();
        if let Some(l) = l {
            s.set_box(Some([l; 3])).unwrap();
        }
        s.add(d, Vector3::zeros(), Vector3::x()).unwrap();
        s.add(
            d,
            Vector3::new(0.0, 3.0 * d.ell, 0.0),
            Vector3::new(1.0, 1.0, 0.0),
        )
        .unwrap();
        s
    };
    let f = [
        Vector3::new(1.0, 0.2, 0.0) * 1e-12,
        Vector3::new(-1.0, -0.2, 0.0) * 1e-12,
        Vector3::new(0.0, 0.5, 0.3) * 1e-12,
        Vector3::new(0.0, -0.5, -0.3) * 1e-12,
    ];
    let open = build(None).sphere_velocities(&f).unwrap();
    let mut last = f64::INFINITY;
    for k in 0..4 {
        let l = 20.0 * d.ell * 2f64.powi(k);
        let v = build(Some(l)).sphere_velocities(&f).unwrap();
        let diff = max_diff(&v, &open) / max_norm(&open);
        if k > 0 {
            assert!(
                last / diff > 6.0,
                "L = {l:e}: difference {diff:e}, before {last:e}"
            );
        }
        last = diff;
    }
    assert!(
        last < 1e-5,
        "at L = 160 ell the box still changes the velocities by {last:e}"
    );
}

/// The result does not depend on the splitting parameter ξ: three splittings from ξL = 1 to 8 on
/// random configurations of unequal spheres (RPY and Oseen) agree to 1e-10 of the largest velocity
/// (measured ≤ 1.9e-12: the sums' tolerance is 1e-12, rounding over ~1e4 terms of both signs adds
/// a little).
#[test]
fn the_sum_does_not_depend_on_the_splitting() {
    let mut rng = Rng::new(0x2545f4914f6cdd1d);
    for (trial, mobility) in [Mobility::Rpy, Mobility::Oseen, Mobility::Rpy]
        .into_iter()
        .enumerate()
    {
        let b = PeriodicBox::new([30e-6, 40e-6, 35e-6]).unwrap();
        let (pos, radii, f) = random_spheres(&mut rng, 12, &b);
        let at = |xi: f64| {
            let e = Ewald::new(b, MU, mobility, pos.len(), 1e-12, Some(xi / 30e-6)).unwrap();
            velocities(&e, &pos, &radii, &f)
        };
        let reference = at(1.0);
        for xi in [3.0, 8.0] {
            let u = at(xi);
            let err = max_diff(&u, &reference) / max_norm(&reference);
            assert!(
                err < 1e-10,
                "trial {trial} ({mobility:?}), xi L = {xi}: {err:e}"
            );
        }
    }
}

/// The products (reciprocal part through structure factors in lanes; real part over cell lists
/// where r_c ≤ L/2, else over every pair's images) equal the blocks of Beenakker's sums applied
/// one by one (the matrix, a separate code path), for RPY and Oseen, unequal radii, pairs
/// overlapping across a face, a cube and an elongated box, at splittings on both sides of
/// r_c = L/2. The sums do not depend on the splitting, so the blocks are summed once per case at
/// ξL = 6, and once more at ξL = 25 for the cube with RPY (the matrix's pair-by-pair wave sums
/// there cost over a second each). To 1e-11 of the largest velocity: both sums are within 1e-13
/// of the exact one, and the matrix adds ~1e3 terms of rounding per entry.
#[test]
fn the_products_are_the_blocks_applied() {
    let mut rng = Rng::new(0x51ab_1e5e_ed00_0001);
    for sides in [[30e-6; 3], [30e-6, 30e-6, 48e-6]] {
        let b = PeriodicBox::new(sides).unwrap();
        let (mut pos, mut radii, f) = random_spheres(&mut rng, 24, &b);
        // Two pairs that overlap through the faces x = ±L/2 and z = ±L/2.
        pos[0] = Vector3::new(0.5 * sides[0] - 0.4e-6, 1e-6, 2e-6);
        pos[1] = Vector3::new(-0.5 * sides[0] + 0.5e-6, 1.3e-6, 2.2e-6);
        pos[2] = Vector3::new(-3e-6, 4e-6, 0.5 * sides[2] - 0.3e-6);
        pos[3] = Vector3::new(-3.4e-6, 4.1e-6, -0.5 * sides[2] + 0.2e-6);
        (radii[0], radii[1], radii[2], radii[3]) = (1.2e-6, 0.7e-6, 1.0e-6, 0.6e-6);
        let fv = DVector::from_iterator(3 * f.len(), f.iter().flat_map(|v| [v[0], v[1], v[2]]));
        for mobility in [Mobility::Rpy, Mobility::Oseen] {
            let ewald = |xi_l: f64| {
                Ewald::new(b, MU, mobility, pos.len(), 1e-13, Some(xi_l / sides[0])).unwrap()
            };
            // The interaction velocities M F − F/(6πμa) from the blocks at ξL = `xi_l`.
            let blocks_applied = |xi_l: f64| -> Vec<Vector3<f64>> {
                let mf = ewald(xi_l).matrix(&pos, &radii) * &fv;
                (0..pos.len())
                    .map(|i| {
                        Vector3::new(mf[3 * i], mf[3 * i + 1], mf[3 * i + 2])
                            - f[i] / (6.0 * std::f64::consts::PI * MU * radii[i])
                    })
                    .collect()
            };
            let want = blocks_applied(6.0);
            let mut got = Vec::new();
            for xi_l in [2.0, 6.0, 25.0] {
                got.push((
                    format!("product at xi L = {xi_l}"),
                    velocities(&ewald(xi_l), &pos, &radii, &f),
                ));
            }
            if sides[2] == sides[0] && mobility == Mobility::Rpy {
                got.push(("blocks at xi L = 25".into(), blocks_applied(25.0)));
            }
            for (what, u) in got {
                let err = max_diff(&u, &want) / max_norm(&want);
                assert!(
                    err < 1e-11,
                    "sides {sides:?}, {mobility:?}, {what}: {err:e}"
                );
            }
        }
    }
}

/// The tolerance is kept: at every tol from 1e-4 to 1e-12 (ξ chosen for speed) the velocities
/// lie within 10 tol of a 1e-15 sum, relative to the Stokes velocity F/(6πμa) of the largest
/// force (the scale the tolerance is set against). Measured: 2e-2 to 5e-2 of tol.
#[test]
fn the_ewald_tolerance_is_kept() {
    let mut rng = Rng::new(0x853c49e6748fea9b);
    let b = PeriodicBox::new([25e-6; 3]).unwrap();
    let (pos, radii, f) = random_spheres(&mut rng, 16, &b);
    let scale = max_norm(&f) / (6.0 * std::f64::consts::PI * MU * 0.5e-6);
    let exact = Ewald::new(b, MU, Mobility::Rpy, 16, 1e-15, None).unwrap();
    let reference = velocities(&exact, &pos, &radii, &f);
    for tol in [1e-4, 1e-6, 1e-8, 1e-10, 1e-12] {
        let e = Ewald::new(b, MU, Mobility::Rpy, 16, tol, None).unwrap();
        let err = max_diff(&velocities(&e, &pos, &radii, &f), &reference) / scale;
        assert!(err < 10.0 * tol, "tol {tol:e}: error {err:e}");
    }
}

/// The matrix and the matrix-free product agree, the matrix is symmetric and positive definite on
/// random configurations (one with an overlapping pair, Zuk et al.'s form at the nearest image).
#[test]
fn the_periodic_mobility_is_symmetric_positive_definite() {
    let mut rng = Rng::new(0xda942042e4dd58b5);
    for trial in 0..6 {
        let b = PeriodicBox::new([20e-6; 3]).unwrap();
        let (mut pos, mut radii, f) = random_spheres(&mut rng, 10, &b);
        if trial % 2 == 1 {
            // Overlap sphere 1 with sphere 0 across a face of the box.
            pos[1] = pos[0] + Vector3::new(20e-6 - 0.7 * (radii[0] + radii[1]), 0.0, 0.0);
            radii[1] = radii[1].max(0.6e-6);
        }
        let e = Ewald::new(b, MU, Mobility::Rpy, pos.len(), 1e-12, None).unwrap();
        let m = e.matrix(&pos, &radii);
        let asym = (&m - m.transpose()).abs().max() / m.abs().max();
        assert!(asym < 1e-12, "trial {trial}: asymmetry {asym:e}");
        let eig = m.clone().symmetric_eigen().eigenvalues;
        let (lo, hi) = (eig.min(), eig.max());
        assert!(
            lo > 1e-3 * hi,
            "trial {trial}: eigenvalues from {lo:e} to {hi:e}"
        );
        // M·F minus the drag is the matrix-free product.
        let flat = DVector::from_iterator(3 * f.len(), f.iter().flat_map(|v| [v.x, v.y, v.z]));
        let mf = &m * flat;
        let u = velocities(&e, &pos, &radii, &f);
        for (i, ui) in u.iter().enumerate() {
            let drag = f[i] / (6.0 * std::f64::consts::PI * MU * radii[i]);
            let dense = Vector3::new(mf[3 * i], mf[3 * i + 1], mf[3 * i + 2]) - drag;
            assert!(
                (dense - ui).norm() < 1e-11 * max_norm(&u),
                "trial {trial}, sphere {i}"
            );
        }
    }
}

/// Two averaged swimmers on either side of a face interact as the neighbours they are by minimum
/// image: the rates equal open space's for the pair moved together by one box length.
#[test]
fn pairs_across_a_face_meet_by_their_minimum_image() {
    let d = Dumbbell::default();
    let l = 40.0 * d.ell;
    let mut boxed = Scene::new();
    boxed.set_model(Model::Averaged);
    boxed.set_box(Some([l; 3])).unwrap();
    let mut open = Scene::new();
    open.set_model(Model::Averaged);
    let a = Vector3::new(0.48 * l, 0.1 * l, 0.0);
    let b = Vector3::new(-0.47 * l, 0.12 * l, 0.01 * l);
    let n = Vector3::new(1.0, 0.3, 0.1);
    boxed.add(d, a, n).unwrap();
    boxed
        .add(Dumbbell { phase: 1.0, ..d }, b, Vector3::y())
        .unwrap();
    open.add(d, a, n).unwrap();
    open.add(
        Dumbbell { phase: 1.0, ..d },
        b + Vector3::new(l, 0.0, 0.0),
        Vector3::y(),
    )
    .unwrap();
    for i in 0..2 {
        let (vb, wb) = boxed.rates(i).unwrap();
        let (vo, wo) = open.rates(i).unwrap();
        assert!(vo.norm() > 0.0);
        assert!(
            (vb - vo).norm() <= 1e-12 * vo.norm(),
            "swimmer {i}: {vb} vs {vo}"
        );
        assert!(
            (wb - wo).norm() <= 1e-12 * wo.norm(),
            "swimmer {i}: {wb} vs {wo}"
        );
    }
}

/// The averaged model in a box: the cutoff defaults to the longest that leaves the neighbour
/// lists their skin within L/2, a longer one than L/2 is refused with the fix; the GPU refuses a
/// box and names the CPU.
#[test]
fn a_box_limits_the_cutoff_and_stays_on_the_cpu() {
    let d = Dumbbell::default();
    let l = 40.0 * d.ell;
    let mut s = Scene::new();
    s.set_model(Model::Averaged);
    s.set_box(Some([l; 3])).unwrap();
    s.add(d, Vector3::zeros(), Vector3::x()).unwrap();
    let skin = swimlab::engine::averaged::DEFAULT_SKIN_OF_CUTOFF;
    assert_eq!(s.averaged_cutoff().unwrap(), Some(0.5 * l / (1.0 + skin)));
    s.set_cutoff(Some(0.6 * l)).unwrap();
    let e = s.averaged_cutoff().unwrap_err().to_string();
    assert!(e.contains("half the box") && e.contains("cutoff to"), "{e}");
    s.set_cutoff(None).unwrap();
    s.set_backend(Backend::Gpu);
    let e = swimlab::engine::plan::plan(&s).unwrap_err().to_string();
    assert!(e.contains("periodic box") && e.contains("cpu"), "{e}");
}

/// A box too short for a swimmer, or one in which spheres would overlap an image, is refused and
/// the scene kept; the box is saved and loaded with the scene.
#[test]
fn box_settings_are_checked_and_saved() {
    let d = Dumbbell::default();
    let mut s = Scene::new();
    s.add(d, Vector3::new(0.0, 0.0, 0.0), Vector3::x()).unwrap();
    s.add(d, Vector3::new(0.0, 6.0 * d.ell, 0.0), Vector3::x())
        .unwrap();
    let e = s.set_box(Some([2.0 * d.ell; 3])).unwrap_err().to_string();
    assert!(e.contains("too short") && e.contains("longer than"), "{e}");
    let e = s
        .set_box(Some([6.0 * d.ell + 1e-7; 3]))
        .unwrap_err()
        .to_string();
    assert!(e.contains("overlap the image"), "{e}");
    assert!(s.periodic().is_none());
    s.set_box(Some([20.0 * d.ell, 30.0 * d.ell, 25.0 * d.ell]))
        .unwrap();
    s.set_ewald_tol(Some(1e-9)).unwrap();
    let back = Scene::from_json(&s.to_json().unwrap()).unwrap();
    assert_eq!(back.periodic(), s.periodic());
    assert_eq!(back.ewald_tol(), 1e-9);
    assert!(s.set_ewald_tol(Some(0.5)).is_err());
}

/// Unless set, the Ewald tolerance follows the run's integrator: a tenth of its drift tolerance
/// (the default auto(1.1e-5): 1.1e-6), 1e-10 for fixed steps and for the noisy defaults; the
/// products use it (velocities equal to those at the same tolerance set by hand, unequal to
/// 1e-10's); a set one is kept whatever the integrator and saved, and `None` follows again (saved
/// following).
#[test]
fn the_ewald_tolerance_follows_the_run_unless_set() {
    use swimlab::engine::IntegratorSpec;
    let d = Dumbbell::default();
    let mut s = Scene::new();
    s.set_box(Some([8.0 * d.ell; 3])).unwrap();
    s.add(d, Vector3::zeros(), Vector3::x()).unwrap();
    s.add(
        Dumbbell { phase: 1.0, ..d },
        Vector3::new(0.3, 2.1, -1.2) * d.ell,
        Vector3::new(0.0, 1.0, 1.0).normalize(),
    )
    .unwrap();
    // A tenth of a decimal tolerance, to the rounding of the product.
    let near = |a: f64, b: f64| (a - b).abs() <= 1e-15 * b;
    assert!(near(s.ewald_tol(), 1.1e-6), "{}", s.ewald_tol());
    assert_eq!(s.ewald_tol_setting(), None);
    let forces: Vec<_> = (0..4)
        .map(|k| Vector3::new(1.0, -0.5 * k as f64, 0.25) * 1e-12)
        .collect();
    let by_default = s.sphere_velocities(&forces).unwrap();
    let mut set = s.clone();
    set.set_ewald_tol(Some(s.ewald_tol())).unwrap();
    assert_eq!(set.sphere_velocities(&forces).unwrap(), by_default);
    set.set_ewald_tol(Some(1e-10)).unwrap();
    assert_ne!(set.sphere_velocities(&forces).unwrap(), by_default);
    for (spec, tol) in [
        (IntegratorSpec::rk4(1e-4).unwrap(), 1e-10),
        (IntegratorSpec::dopri5(1e-9).unwrap(), 1e-10),
        (IntegratorSpec::auto(1e-3).unwrap(), 1e-4),
        (IntegratorSpec::stroboscopic(1e-6).unwrap(), 1e-7),
    ] {
        s.set_integrator(Some(spec));
        assert!(near(s.ewald_tol(), tol), "{spec:?}: {}", s.ewald_tol());
    }
    s.set_integrator(None);
    s.set_temperature(300.0).unwrap();
    assert_eq!(s.ewald_tol(), 1e-10, "the noisy default steps fixed");
    s.set_temperature(0.0).unwrap();
    s.set_ewald_tol(Some(1e-7)).unwrap();
    s.set_integrator(Some(IntegratorSpec::rk4(1e-4).unwrap()));
    assert_eq!(s.ewald_tol(), 1e-7);
    let back = Scene::from_json(&s.to_json().unwrap()).unwrap();
    assert_eq!(back.ewald_tol_setting(), Some(1e-7));
    s.set_ewald_tol(None).unwrap();
    assert_eq!(s.ewald_tol(), 1e-10);
    let json = s.to_json().unwrap();
    assert!(!json.contains("ewald_tol"), "{json}");
    assert_eq!(Scene::from_json(&json).unwrap().ewald_tol_setting(), None);
}

/// A microscopic pair in a box runs, and its velocities are the periodic mobility's: one step of
/// the spring model moves the spheres as sphere_velocities says for the spring forces.
#[test]
fn a_microscopic_pair_runs_in_a_box() {
    let d = Dumbbell::default();
    let mut s = Scene::new();
    s.set_box(Some([10.0 * d.ell; 3])).unwrap();
    s.add(d, Vector3::new(-0.25 * d.ell, 0.0, 0.0), Vector3::x())
        .unwrap();
    s.add(
        Dumbbell { phase: 0.8, ..d },
        Vector3::new(0.0, 2.5 * d.ell, 0.0),
        Vector3::x(),
    )
    .unwrap();
    // Rates: dR_H/dt = w1 v1 + w2 v2 for the spring forces ±f.
    let (rate, _) = s.rates(0).unwrap();
    let mut f = Vec::new();
    for i in 0..2 {
        let (x1, x2) = s.spheres(i);
        let dd = s.swimmer(i).unwrap();
        let b = x2 - x1;
        let fs = dd.k0 * (b.norm() - dd.rest_length(s.time())) / b.norm() * b;
        f.extend([fs, -fs]);
    }
    let v = s.sphere_velocities(&f).unwrap();
    let want = d.w1() * v[0] + d.w2() * v[1];
    assert!(
        (rate - want).norm() < 1e-9 * want.norm().max(1e-30),
        "{rate} vs {want}"
    );
    let mut sim = swimlab::engine::Simulation::new(s);
    sim.run_periods(1.0).unwrap();
    assert!(sim.scene().displacement(0).unwrap().norm() > 0.0);
}

/// In a box the cell lists wrap around the faces: the averaged rates through them equal the
/// all-pairs minimum-image loop's to the rounding of the sums' order (1e-12 of the largest rate),
/// for cutoffs from a few ℓ to L/2, with and without steric repulsion; the sphere passes (steric
/// forces, the closest overlap) through periodic cells agree with their all-pairs forms too.
#[test]
fn periodic_cell_lists_give_the_all_pairs_rates() {
    use swimlab::engine::averaged::AveragedSystem;
    use swimlab::engine::build::{random_suspension, Orientations, Phases};
    use swimlab::engine::integrators::OdeSystem;
    use swimlab::engine::Coefficients;
    let d = Dumbbell {
        a2: 0.075 * 5e-6,
        ..Dumbbell::default()
    };
    let l = 160e-6;
    let mut s = Scene::new();
    s.set_model(Model::Averaged);
    s.set_box(Some([l, 1.1 * l, 0.9 * l])).unwrap();
    random_suspension(
        &mut s,
        700,
        d,
        [l, 1.1 * l, 0.9 * l],
        Orientations::Random,
        Phases::Random,
        21,
    )
    .unwrap();
    let (y, base) = s.raw_state();
    let b = *s.periodic().unwrap();
    for cutoff in [3.0 * d.ell, 8.0 * d.ell, 0.45 * l] {
        for steric in [
            None,
            Some(swimlab::engine::Steric::new(2e-6, 1e-3).unwrap()),
        ] {
            let rates = |cells: bool| {
                let mut sys = AveragedSystem::new(s.swimmers(), base, Coefficients::Paper, y);
                sys.set_periodic(Some(b));
                sys.set_cutoff(Some(cutoff));
                sys.set_contacts(
                    swimlab::engine::Contacts {
                        allow_overlap: false,
                        steric,
                    },
                    1e-3,
                );
                sys.set_neighbour_lists(Some(cells));
                let mut dy = vec![0.0; y.len()];
                sys.rhs(0.0, y, &mut dy);
                dy
            };
            let (a, c) = (rates(true), rates(false));
            let scale = c.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!(scale > 0.0);
            for (k, (x, z)) in a.iter().zip(&c).enumerate() {
                assert!(
                    (x - z).abs() <= 1e-12 * scale,
                    "cutoff {cutoff:e}, steric {}, component {k}: {x:e} vs {z:e}",
                    steric.is_some()
                );
            }
        }
    }
}

/// The contact guard through periodic cell lists (2,000 spheres, above the threshold) names the
/// pair a brute-force minimum-image loop finds, an overlap across a face included; `min_gap`
/// (cells of twice the mean spacing) gives the brute-force smallest gap.
#[test]
fn the_overlap_guard_sees_across_the_faces() {
    use swimlab::engine::gaps::{closest_overlap, min_gap};
    use swimlab::engine::pairs::SoaSpheres;
    let b = PeriodicBox::new([60e-6, 50e-6, 55e-6]).unwrap();
    let mut rng = Rng::new(0x6a09e667f3bcc909);
    let n = 2000;
    let mut s = SoaSpheres::default();
    s.resize(n);
    s.periodic = Some(b);
    let radii: Vec<f64> = (0..n)
        .map(|i| if i % 2 == 0 { 0.3e-6 } else { 0.2e-6 })
        .collect();
    let l = b.sides();
    for i in 0..n {
        s.x[i] = (rng.uniform() - 0.5) * l[0];
        s.y[i] = (rng.uniform() - 0.5) * l[1];
        s.z[i] = (rng.uniform() - 0.5) * l[2];
    }
    // Sphere 4 one box length from sphere 2 along x: on it by minimum image, the deepest overlap
    // two spheres of the largest radius can have (no random pair reaches it).
    s.x[4] = s.x[2] + l[0];
    (s.y[4], s.z[4]) = (s.y[2], s.z[2]);
    let brute = || {
        let mut best = (f64::INFINITY, 0, 0);
        for i in 0..n {
            for j in i + 1..n {
                let r = Vector3::new(s.x[i] - s.x[j], s.y[i] - s.y[j], s.z[i] - s.z[j]);
                let gap = b.min_image(r).norm() - radii[i] - radii[j];
                if gap < best.0 {
                    best = (gap, i, j);
                }
            }
        }
        best
    };
    let want = brute();
    assert_eq!((want.1, want.2), (2, 4));
    let got = closest_overlap(&s, &radii, true).expect("the overlap across the face");
    assert_eq!((got.1, got.2), (2, 4));
    assert!((got.0 - want.0).abs() < 1e-18);
    let g = min_gap(&s, &radii, true).unwrap();
    assert_eq!((g.1, g.2), (want.1, want.2));
}

/// Spectral Ewald (`s.ewald_method = "spectral"`) with its products at every tolerance from 1e-4
/// to 1e-12 lies within the tolerance of Beenakker's sum at 1e-15, relative to the Stokes
/// velocity of the largest force on the smallest sphere: 40 unequal spheres, a cube and an
/// elongated box, RPY and Oseen. Measured: 0.02 to 0.35 of tol, so the bound (tol itself) is the
/// contract, with a margin of three.
#[test]
fn spectral_ewald_agrees_with_beenakker_to_the_tolerance() {
    let mut rng = Rng::new(0x853c49e6748fea9b);
    for sides in [[25e-6; 3], [30e-6, 40e-6, 35e-6]] {
        let b = PeriodicBox::new(sides).unwrap();
        let (pos, radii, f) = random_spheres(&mut rng, 40, &b);
        let scale = max_norm(&f) / (6.0 * std::f64::consts::PI * MU * 0.5e-6);
        for mobility in [Mobility::Rpy, Mobility::Oseen] {
            let exact = Ewald::new(b, MU, mobility, 40, 1e-15, None).unwrap();
            let reference = velocities(&exact, &pos, &radii, &f);
            for tol in [1e-4, 1e-6, 1e-8, 1e-10, 1e-12] {
                let e = Ewald::with_method(b, MU, mobility, 40, tol, EwaldMethod::Spectral, None)
                    .unwrap();
                assert_eq!(e.method(), EwaldMethod::Spectral);
                let err = max_diff(&velocities(&e, &pos, &radii, &f), &reference) / scale;
                assert!(
                    err < tol,
                    "{sides:?}, {mobility:?}, tol {tol:e}: error {err:e}"
                );
            }
        }
    }
}

/// Spectral Ewald does not depend on its splitting (which moves work between the real-space
/// pairs and the grid): three splittings agree to 1e-10 of the largest velocity at tol 1e-12,
/// with an overlapping pair across a face (Zuk et al.'s form at the nearest image).
#[test]
fn spectral_ewald_does_not_depend_on_the_splitting() {
    let mut rng = Rng::new(0x2545f4914f6cdd1d);
    let b = PeriodicBox::new([30e-6, 40e-6, 35e-6]).unwrap();
    let (mut pos, mut radii, mut f) = random_spheres(&mut rng, 20, &b);
    // Two spheres overlapping across the x faces.
    pos[0] = Vector3::new(14.6e-6, 0.0, 0.0);
    pos[1] = Vector3::new(-14.6e-6, 0.3e-6, 0.0);
    (radii[0], radii[1]) = (1e-6, 0.8e-6);
    f[1] = -f[0];
    let at = |xi: Option<f64>| {
        let e =
            Ewald::with_method(b, MU, Mobility::Rpy, 20, 1e-12, EwaldMethod::Spectral, xi).unwrap();
        let xi = e.spectral().unwrap().splitting();
        (velocities(&e, &pos, &radii, &f), xi)
    };
    let (reference, xi) = at(None);
    let beenakker = Ewald::new(b, MU, Mobility::Rpy, 20, 1e-13, None).unwrap();
    let err =
        max_diff(&velocities(&beenakker, &pos, &radii, &f), &reference) / max_norm(&reference);
    assert!(err < 1e-10, "against Beenakker: {err:e}");
    for factor in [1.3, 1.8] {
        let (u, _) = at(Some(factor * xi));
        let err = max_diff(&u, &reference) / max_norm(&reference);
        assert!(err < 1e-10, "splitting x{factor}: {err:e}");
    }
}

/// The spectral operator is the mobility: symmetric (to the tolerance) and positive definite,
/// its matrix built column by column from products (12 spheres, one overlapping pair across a
/// face).
#[test]
fn spectral_ewald_is_symmetric_positive_definite() {
    let mut rng = Rng::new(0xda942042e4dd58b5);
    let b = PeriodicBox::new([20e-6; 3]).unwrap();
    let (mut pos, mut radii, _) = random_spheres(&mut rng, 12, &b);
    pos[0] = Vector3::new(9.5e-6, 0.0, 0.0);
    pos[1] = Vector3::new(-9.7e-6, 0.2e-6, 0.0);
    (radii[0], radii[1]) = (0.9e-6, 0.7e-6);
    let n = pos.len();
    let e =
        Ewald::with_method(b, MU, Mobility::Rpy, n, 1e-12, EwaldMethod::Spectral, None).unwrap();
    let mut m = nalgebra::DMatrix::zeros(3 * n, 3 * n);
    for c in 0..3 * n {
        let mut f = vec![Vector3::zeros(); n];
        f[c / 3][c % 3] = 1e-12;
        let mut u = velocities(&e, &pos, &radii, &f);
        u[c / 3] += f[c / 3] / (6.0 * std::f64::consts::PI * MU * radii[c / 3]);
        for (k, v) in u.iter().enumerate() {
            for q in 0..3 {
                m[(3 * k + q, c)] = v[q] / 1e-12;
            }
        }
    }
    let asym = (&m - m.transpose()).abs().max() / m.abs().max();
    assert!(asym < 1e-11, "asymmetry {asym:e}");
    let eig = nalgebra::SymmetricEigen::new((&m + m.transpose()) / 2.0).eigenvalues;
    let (lo, hi) = (eig.min(), eig.max());
    assert!(lo > 1e-3 * hi, "eigenvalues {lo:e} .. {hi:e}");
    let dense = Ewald::new(b, MU, Mobility::Rpy, n, 1e-12, None)
        .unwrap()
        .matrix(&pos, &radii);
    let diff = (&m - &dense).abs().max() / dense.abs().max();
    assert!(diff < 1e-10, "against Beenakker's matrix: {diff:e}");
}

/// Spectral products do not depend on the thread count: the spread takes each plane's spheres in
/// a fixed order, so one and two threads give the same bits.
#[test]
fn spectral_ewald_is_independent_of_the_thread_count() {
    let mut rng = Rng::new(0x6a09e667f3bcc909);
    let b = PeriodicBox::new([60e-6; 3]).unwrap();
    let (pos, radii, f) = random_spheres(&mut rng, 300, &b);
    let e =
        Ewald::with_method(b, MU, Mobility::Rpy, 300, 1e-8, EwaldMethod::Spectral, None).unwrap();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| velocities(&e, &pos, &radii, &f))
    };
    assert_eq!(run(1), run(2));
}

/// The scene's Ewald method: "auto" takes the spectral sums from the threshold on, the choice is
/// checked, saved and read back, and a scene's sphere velocities agree between the methods.
#[test]
fn the_ewald_method_is_a_scene_setting() {
    use swimlab::engine::build::{random_suspension, Orientations, Phases};
    use swimlab::engine::ewald::SPECTRAL_FROM_SPHERES;
    assert_eq!(
        EwaldMethod::Auto.resolve(SPECTRAL_FROM_SPHERES - 1),
        EwaldMethod::Beenakker
    );
    assert_eq!(
        EwaldMethod::Auto.resolve(SPECTRAL_FROM_SPHERES),
        EwaldMethod::Spectral
    );
    assert!(EwaldMethod::parse("spectrl")
        .unwrap_err()
        .to_string()
        .contains("spectral"));
    let mut s = Scene::new();
    s.set_box(Some([120e-6; 3])).unwrap();
    let mut rng = Rng::new(11);
    random_suspension(
        &mut s,
        30,
        Dumbbell::default(),
        [120e-6; 3],
        Orientations::Random,
        Phases::Random,
        5,
    )
    .unwrap();
    // The sums to 1e-10 (not the default integrator's 1.1e-6): the methods are held to 1e-8.
    s.set_ewald_tol(Some(1e-10)).unwrap();
    let forces: Vec<Vector3<f64>> = (0..60)
        .map(|_| Vector3::new(rng.uniform(), rng.uniform(), rng.uniform()).add_scalar(-0.5) * 1e-12)
        .collect();
    s.set_ewald_method(EwaldMethod::Beenakker);
    let b = s.sphere_velocities(&forces).unwrap();
    s.set_ewald_method(EwaldMethod::Spectral);
    let sp = s.sphere_velocities(&forces).unwrap();
    let err = max_diff(&sp, &b) / max_norm(&b);
    assert!(err < 1e-8, "methods differ by {err:e}");
    let json = s.to_json().unwrap();
    assert!(json.contains("\"ewald_method\": \"spectral\""), "{json}");
    let back = Scene::from_json(&json).unwrap();
    assert_eq!(back.ewald_method(), EwaldMethod::Spectral);
    // A short microscopic run by each method: the displacements agree to 1e-9 of their size (the
    // sums' 1e-10 of the Stokes velocity on every velocity; measured 2.7e-11).
    let run = |m: EwaldMethod| {
        let mut sc = back.clone();
        sc.set_ewald_method(m);
        let mut sim = swimlab::engine::Simulation::new(sc);
        sim.run_periods(0.01).unwrap();
        (0..30)
            .map(|i| sim.scene().displacement(i).unwrap())
            .collect::<Vec<_>>()
    };
    let (by_b, by_s) = (run(EwaldMethod::Beenakker), run(EwaldMethod::Spectral));
    let err = max_diff(&by_s, &by_b) / max_norm(&by_b);
    assert!(err < 1e-9, "runs differ by {err:e}");
    // Thermal noise through the Lanczos root of the spectral products: the same noise (same seed)
    // by either method gives the same motion to 1e-9 (the sums' 1e-10 carried through the root;
    // measured 9.3e-13).
    let noisy = |m: EwaldMethod| {
        let mut sc = back.clone();
        sc.set_ewald_method(m);
        sc.set_temperature(300.0).unwrap();
        sc.set_noise_root(swimlab::engine::thermal::NoiseRoot::Lanczos);
        let mut sim = swimlab::engine::Simulation::new(sc);
        sim.run_periods(0.0005).unwrap();
        (0..30)
            .map(|i| sim.scene().displacement(i).unwrap())
            .collect::<Vec<_>>()
    };
    let (by_b, by_s) = (noisy(EwaldMethod::Beenakker), noisy(EwaldMethod::Spectral));
    let err = max_diff(&by_s, &by_b) / max_norm(&by_b);
    assert!(err < 1e-9, "noisy runs differ by {err:e}");
}

/// `swimlab bench ewald` measures what it says: both methods at each size, their difference
/// within the tolerance, and the crossover read off the table (from the first size after the
/// last one where Beenakker's sums were faster).
#[test]
fn bench_ewald_compares_the_methods() {
    use swimlab::bench::ewald::{crossover, run, table, Row};
    let rows = run(125, 125, 1e-8).unwrap();
    assert_eq!(
        rows.iter().map(|r| r.spheres).collect::<Vec<_>>(),
        [64, 125]
    );
    for r in &rows {
        assert!(r.difference.unwrap() < 1.0, "{r:?}");
        assert!(r.spectral > 0.0 && r.open > 0.0 && r.beenakker.unwrap() > 0.0);
    }
    assert_eq!(table(&rows).rows.len(), 2);
    let row = |n, b: Option<f64>, s| Row {
        spheres: n,
        beenakker: b,
        spectral: s,
        open: 1.0,
        grid: [8; 3],
        difference: None,
    };
    let synthetic = [
        row(10, Some(1.0), 2.0),
        row(20, Some(3.0), 2.0),
        row(40, Some(1.0), 2.0),
        row(80, Some(9.0), 2.0),
        row(160, None, 2.0),
    ];
    assert_eq!(crossover(&synthetic), Some(80));
    assert_eq!(crossover(&synthetic[..3]), None);
}

/// `swimlab bench boundaries` on small scenes: every boundary and both sphere models give a
/// finite, positive time, and the table has a row per model and size with the ratios the book
/// quotes (box over open and wall over open computed from the times, the rigid model's open
/// space over the spring model's); a tolerance out of range is refused.
#[test]
fn bench_boundaries_times_every_boundary() {
    use swimlab::bench::boundaries::{run, table};
    let rows = run(&[10], None).unwrap();
    assert_eq!(rows.len(), 2);
    for r in &rows {
        for t in [r.open, r.periodic, r.wall, r.wall_divergence] {
            assert!(t.is_finite() && t > 0.0, "{r:?}");
        }
    }
    let t = table(&rows);
    assert_eq!(t.rows.len(), 2);
    let ratio = |row: usize, col: &str| -> f64 {
        let k = t.header.iter().position(|h| h == col).unwrap();
        t.rows[row][k].parse().unwrap()
    };
    let want = rows[1].periodic / rows[1].open;
    assert!((ratio(1, "box_over_open") - want).abs() <= 0.01 * want.max(1.0));
    assert_eq!(ratio(0, "open_over_micro_open"), 1.0);
    let want = rows[1].wall_divergence / rows[0].open;
    assert!((ratio(1, "wall_div_over_micro_open") - want).abs() <= 0.01 * want.max(1.0));
    assert!(
        (rows[1].ewald_tol - 1.1e-6).abs() < 1e-20,
        "the default follows auto(1.1e-5)"
    );
    // `--ewald-tol` out of range is refused with the range, before anything is timed.
    let e = run(&[10], Some(0.5)).unwrap_err();
    assert!(e.contains("Ewald tolerance") && e.contains("1e-2"), "{e}");
}

/// `swimlab bench contacts --quick`: each of its runs (both accurate models, open space and the
/// box) reports finite, positive seconds, right-hand sides and steps a period, right-hand sides
/// at least the steps (an adaptive step takes at least one), and the table has a row a run.
#[test]
fn bench_contacts_runs_every_scene() {
    use swimlab::bench::contacts::{run, table};
    let rows = run(true).unwrap();
    assert_eq!(rows.len(), 4);
    for r in &rows {
        assert!(r.seconds.is_finite() && r.seconds > 0.0, "{r:?}");
        assert!(r.steps > 0.0 && r.rhs >= r.steps, "{r:?}");
    }
    assert_eq!(table(&rows).rows.len(), 4);
}

/// A box too elongated for the spectral grid: "spectral" says so and names the fixes, "auto"
/// sums by Beenakker's method instead.
#[test]
fn an_elongated_box_falls_back_to_beenakker() {
    let b = PeriodicBox::new([12e-6, 12e-6, 12e-3]).unwrap();
    let err = Ewald::with_method(
        b,
        MU,
        Mobility::Rpy,
        800,
        1e-10,
        EwaldMethod::Spectral,
        None,
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("beenakker") && err.contains("tolerance"),
        "{err}"
    );
    let e = Ewald::with_method(b, MU, Mobility::Rpy, 800, 1e-10, EwaldMethod::Auto, None).unwrap();
    assert_eq!(e.method(), EwaldMethod::Beenakker);
}

/// What the tolerance means for a run: every swimmer's drift over a period, with the products
/// summed at `tol`, lies within 10 tol (RMS over swimmers, relative to the RMS drift) of the
/// same fixed-step run at 1e-14; the error grows as the tolerance is loosened. Measured by
/// `scripts/validate/ewald_tolerance.rhai` (4 to 16 swimmers): 1 to 5 tol. Four asymmetric
/// Fig-1 swimmers with unlike phases in a box of side 3.5 ℓ, RK4 at T/1000 (within the stiff
/// limit), the steps the same at every tolerance so that the differences are the sums' alone.
#[test]
fn the_drift_error_follows_the_ewald_tolerance() {
    let d = Dumbbell {
        a1: 1.125e-6,
        a2: 0.5625e-6,
        ..Dumbbell::default()
    };
    let l = 3.5 * d.ell;
    let mut s = Scene::new();
    s.set_box(Some([l; 3])).unwrap();
    let placed = [
        ([-0.25, -0.25, -0.25], [1.0, 0.0, 0.0], 0.0),
        ([0.25, 0.25, -0.25], [0.0, 1.0, 0.0], 1.3),
        ([0.25, -0.25, 0.25], [0.0, 0.0, 1.0], 2.1),
        ([-0.25, 0.25, 0.25], [1.0, 1.0, 1.0], 4.0),
    ];
    for (c, n, phase) in placed {
        s.add(
            Dumbbell { phase, ..d },
            Vector3::from(c) * l,
            Vector3::from(n).normalize(),
        )
        .unwrap();
    }
    let period = 2.0 * std::f64::consts::PI / d.omega;
    s.set_integrator(Some(
        swimlab::engine::IntegratorSpec::rk4(period / 1000.0).unwrap(),
    ));
    // The start from L(0) is a one-off transient: settled for a period at the default tolerance.
    let mut settle = swimlab::engine::Simulation::new(s);
    settle.run_periods(1.0).unwrap();
    let settled = settle.scene().clone();
    let drift = |tol: f64| -> Vec<Vector3<f64>> {
        let mut s = settled.clone();
        s.set_ewald_tol(Some(tol)).unwrap();
        let start: Vec<_> = (0..4).map(|i| s.displacement(i).unwrap()).collect();
        let mut sim = swimlab::engine::Simulation::new(s);
        sim.run_periods(1.0).unwrap();
        (0..4)
            .map(|i| sim.scene().displacement(i).unwrap() - start[i])
            .collect()
    };
    let reference = drift(1e-14);
    let rms = |v: &[Vector3<f64>]| v.iter().map(|x| x.norm_squared()).sum::<f64>().sqrt();
    let mut errors = Vec::new();
    for tol in [1e-8, 1e-6, 1e-4] {
        let d = drift(tol);
        let diff: Vec<_> = d.iter().zip(&reference).map(|(a, b)| a - b).collect();
        errors.push((tol, rms(&diff) / rms(&reference)));
    }
    assert!(errors.iter().all(|&(tol, e)| e <= 10.0 * tol), "{errors:?}");
    assert!(
        errors.windows(2).all(|w| w[1].1 > 10.0 * w[0].1),
        "{errors:?}"
    );
}
