//! The rigid-stroke limit (k0 → ∞): the spring model converges to it as k0 grows, it obeys the
//! scallop theorem, and its default integrator meets the drift accuracy budget in far fewer steps.

use crate::common::*;
use nalgebra::Vector3;
use std::f64::consts::FRAC_PI_2;
use swimlab::engine::{Dumbbell, IntegratorSpec, Model, Scene, Simulation, Steric};

fn pair_with_k0(k0: f64) -> Scene {
    let mut s = Scene::new();
    let d = Dumbbell {
        k0,
        ..swimmer(0.15, true, 0.0)
    };
    s.add(d, Vector3::new(-5.0 * ELL, 0.0, 0.0), Vector3::x())
        .unwrap();
    s.add(
        Dumbbell {
            phase: FRAC_PI_2,
            ..d
        },
        Vector3::new(5.0 * ELL, 0.0, 0.0),
        -Vector3::x(),
    )
    .unwrap();
    s
}

#[test]
fn spring_model_converges_to_the_rigid_stroke_limit() {
    let mut rigid = pair_with_k0(1e-3);
    rigid.set_model(Model::Rigid);
    rigid.set_integrator(Some(IntegratorSpec::Dopri5 { rtol: 1e-10 }));
    let (limit, _) = drift_per_period(&mut rigid, 2.0);
    let mut previous = f64::INFINITY;
    for k0 in [1e-3, 4e-3, 1.6e-2] {
        let (d, _) = drift_per_period(&mut pair_with_k0(k0), 2.0);
        let err = rel(d, limit);
        // Measured: 2.1e-5, 1.3e-6, 7.8e-8: the lag of the spring costs O(1/k0²) of the drift.
        // Requiring a factor 8 per factor 4 in k0 checks convergence of at least order 1.5.
        assert!(
            err < previous / 8.0,
            "k0 = {k0}: {err:e} after {previous:e}"
        );
        previous = err;
    }
    assert!(previous < 1e-7);
}

#[test]
fn isolated_rigid_dumbbell_returns_each_period() {
    // R_H is a function of the length alone, so it returns exactly; what is left is the adaptive
    // integrator's error, controlled by its tolerance. Default (1e-7): measured 2e-12 ℓ per period,
    // 2e-6 of the Fig-1 drift; bound 1e-11 ℓ (1e-5 of it). At 1e-10 the bound is the spring
    // model's 1e-12 ℓ.
    for (spec, bound) in [
        (None, 1e-11),
        (Some(IntegratorSpec::Dopri5 { rtol: 1e-10 }), 1e-12),
    ] {
        let mut s = Scene::new();
        s.add(
            swimmer(0.15, true, 0.3),
            Vector3::zeros(),
            Vector3::new(1.0, 2.0, -0.5),
        )
        .unwrap();
        s.set_model(Model::Rigid);
        s.set_integrator(spec);
        let mut s = Simulation::new(s);
        s.run_periods(1.0).unwrap();
        let start = s.center(0).unwrap();
        s.run_periods(3.0).unwrap();
        let moved = (s.center(0).unwrap() - start).norm() / ELL / 3.0;
        assert!(moved < bound, "{spec:?}: {moved:e} ell per period");
    }
}

#[test]
fn rigid_default_integrator_meets_the_drift_accuracy_budget() {
    for (n1, n2) in [(1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
        for asym in [false, true] {
            let mut fast = aligned_pair(10.0, asym, n1, n2);
            fast.set_model(Model::Rigid);
            let mut fine = fast.clone();
            fine.set_integrator(Some(IntegratorSpec::Dopri5 { rtol: 1e-10 }));
            let (m, _) = drift_per_period(&mut fast, 2.0);
            let (r, _) = drift_per_period(&mut fine, 2.0);
            assert!(
                rel(m, r) < 1e-4,
                "n = ({n1}, {n2}), asym = {asym}: {m:e} vs {r:e}"
            );
            // The point of the model: ~100 right-hand sides per period instead of ~9,000.
            assert!(fast.stats().rhs_evals < 3 * 300, "{:?}", fast.stats());
        }
    }
}

#[test]
fn rigid_tension_matches_the_stiff_spring() {
    let mut spring = Simulation::new(pair_with_k0(6.4e-2));
    spring.run_periods(1.1).unwrap();
    let mut rigid = spring.clone();
    rigid.set_model(Model::Rigid);
    for i in 0..2 {
        let (ts, tr) = (spring.tension(i).unwrap(), rigid.tension(i).unwrap());
        // The spring lags L(t) by O(1/k0): at k0 = 64× the paper's the tensions agree to ~1%.
        assert!(
            rel(ts, tr) < 0.02,
            "swimmer {i}: spring {ts:e} N, rigid {tr:e} N"
        );
    }
}

#[test]
fn rosenbrock_is_not_held_by_the_spring_stability_limit() {
    // k0 = 100× the paper's: the explicit RK4 limit is ~2,200 × 100 steps per period. ROS34PW2,
    // implicit in each dumbbell's own spring, takes a few thousand (measured ~5,900) and stays
    // within 1e-4 of the drift (measured 7e-5 against the rigid limit, which the spring at this
    // k0 matches to 2e-9).
    let mut stiff = pair_with_k0(0.1);
    stiff.set_integrator(Some(IntegratorSpec::Rosw { rtol: 1e-6 }));
    let (d, _) = drift_per_period(&mut stiff, 1.0);
    let mut rigid = pair_with_k0(0.1);
    rigid.set_model(Model::Rigid);
    rigid.set_integrator(Some(IntegratorSpec::Dopri5 { rtol: 1e-10 }));
    let (r, _) = drift_per_period(&mut rigid, 1.0);
    assert!(rel(d, r) < 2e-4, "{d:e} vs {r:e}");
    let rate_steps = stiff.stiff_rate() * stiff.period().unwrap() / 2.785;
    let steps = stiff.stats().steps as f64 / 2.0;
    assert!(
        steps < rate_steps / 10.0,
        "{steps} steps per period, explicit limit {rate_steps}"
    );
}

/// In a periodic box the rigid-stroke tension is the one the run's constraint solve uses, with
/// the box's (Ewald-summed) mobility: for one swimmer, T = L̇ / c with c the rate at which a unit
/// tension (+N on the a1 sphere, −N on the a2 sphere) pulls the spheres apart along N, read from
/// the scene's sphere velocities in the box. A box of side 4ℓ changes the tension by 0.7%, so
/// open space's tension fails this; the two agree to 1e-8, the Ewald sums' tolerance with room.
#[test]
fn the_rigid_tension_in_a_box_uses_the_box_mobility() {
    let d = swimmer(0.15, true, 0.3);
    let build = |side: Option<f64>| {
        let mut s = Scene::new();
        s.set_model(Model::Rigid);
        if let Some(l) = side {
            s.set_box(Some([l; 3])).unwrap();
        }
        s.add(d, Vector3::zeros(), Vector3::new(1.0, 0.4, -0.2))
            .unwrap();
        s
    };
    let s = build(Some(4.0 * d.ell));
    let n = s.dir(0).unwrap();
    let unit = 1e-12;
    let u = s.sphere_velocities(&[n * unit, -n * unit]).unwrap();
    let c = (u[1] - u[0]).dot(&n) / unit;
    let l_dot = d.lambda * d.omega * d.phase.cos();
    let expected = l_dot / c;
    let t = s.tension(0).unwrap();
    assert!(
        ((t - expected) / expected).abs() < 1e-8,
        "tension {t:e} N, constraint with the box's mobility {expected:e} N"
    );
    let open = build(None).tension(0).unwrap();
    assert!(
        ((open - expected) / expected).abs() > 1e-3,
        "the box does not change the tension ({open:e} against {expected:e}): the test cannot tell"
    );
}

/// Two side-by-side swimmers (parallel, phases 0 and π/2) whose big spheres start 0.3 µm apart,
/// inside a steric range of 0.5 µm: their y-separation after one period, the steric repulsion
/// on or off, by `model` at spring constant `k0`.
fn side_by_side_separation(model: Model, k0: f64, steric: bool) -> f64 {
    let mut s = Scene::new();
    let d = Dumbbell {
        k0,
        ..swimmer(0.15, true, 0.0)
    };
    let h = 2.0 * d.a1 + 0.3e-6;
    s.add(d, Vector3::new(0.0, -0.5 * h, 0.0), Vector3::x())
        .unwrap();
    s.add(
        Dumbbell {
            phase: FRAC_PI_2,
            ..d
        },
        Vector3::new(0.0, 0.5 * h, 0.0),
        Vector3::x(),
    )
    .unwrap();
    if steric {
        s.set_steric(Some(Steric::new(0.5e-6, 1e-3).unwrap()));
    }
    s.set_model(model);
    s.set_integrator(Some(IntegratorSpec::Dopri5 { rtol: 1e-10 }));
    let mut sim = Simulation::new(s);
    sim.run_periods(1.0).unwrap();
    sim.center(1).unwrap().y - sim.center(0).unwrap().y
}

/// Steric repulsion is a body force in the rigid-stroke model as in the spring model (its
/// velocities leave the constraint tensions less of each stroke to make up), so the spring
/// model's separation of a pair pushed apart by it converges to the rigid model's as k0 grows.
#[test]
fn spring_model_with_steric_repulsion_converges_to_the_rigid_stroke_limit() {
    let limit = side_by_side_separation(Model::Rigid, 1e-3, true);
    let free = side_by_side_separation(Model::Rigid, 1e-3, false);
    let push = (limit - free).abs();
    let mut errors = Vec::new();
    for k0 in [1e-3, 4e-3, 1.6e-2] {
        let d = side_by_side_separation(Model::Micro, k0, true);
        errors.push((d - limit).abs() / push);
    }
    // Measured: a push of 1.33e-7 m (0.027ℓ) in the period; the spring model 8.2e-5, 1.3e-5 and
    // 2.6e-6 of it away from the limit. A steric force across a dumbbell stretches or squeezes
    // its spring by F/k0, so the difference falls at first order in 1/k0 and faster as the
    // stroke's own lag (second order) takes over: a factor 3 per factor 4 in k0 (order 0.8)
    // checks convergence, and the last within 1e-5 of the push that the rigid model moves the
    // pair as the limit does (a rigid model deaf to the steric force would be off by all of it).
    assert!(
        push > 1e-7,
        "the steric force pushed the pair only {push:e} m"
    );
    for w in errors.windows(2) {
        assert!(w[1] < w[0] / 3.0, "{errors:?}");
    }
    assert!(errors[2] < 1e-5, "{errors:?}");
}
