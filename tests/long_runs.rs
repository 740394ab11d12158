//! Long runs stay sane: 1e4 periods of the microscopic mirror pair (spring and rigid-stroke) keep
//! the pair's separation constant relative to its drift and the state physical; 1e6 periods of the
//! averaged mirror pair keep |N| = 1 to 1e-12 and the separation exactly.

use crate::common::*;
use swimlab::engine::{IntegratorSpec, Model, Simulation};

fn run_long(model: Model, spec: Option<IntegratorSpec>, periods: f64) -> (f64, f64) {
    let mut s = mirror_inwards(10.0, true);
    s.set_model(model);
    s.set_integrator(spec);
    let (drift, _) = drift_per_period(&mut s, 1.0); // settles, then one period
    let sep0 = s.center(1).unwrap().x - s.center(0).unwrap().x;
    let mut s = Simulation::new(s);
    s.run_periods(periods).unwrap();
    let sep1 = s.center(1).unwrap().x - s.center(0).unwrap().x;
    for i in 0..2 {
        let n = s.dir(i).unwrap();
        assert!((n.norm() - 1.0).abs() < 1e-12);
        let len = s.length(i).unwrap();
        let rest = s.swimmer(i).unwrap().rest_length(s.time());
        // The spring follows L(t) within its lag (~λω/rate ≈ 2e-4 ℓ); exactly in the rigid model.
        assert!(
            (len - rest).abs() < 1e-3 * ELL,
            "length {len:e} vs rest {rest:e}"
        );
    }
    ((sep1 - sep0) / ELL, drift * periods)
}

#[test]
fn ten_thousand_periods_of_the_spring_pair() {
    // RK4 at T/1000, the cheapest spring integrator within 1e-4 of the drift (bench work-precision).
    let t = swimmer(0.15, true, 0.0).period();
    let (dsep, total) = run_long(
        Model::Micro,
        Some(IntegratorSpec::Rk4 { dt: t / 1000.0 }),
        1e4,
    );
    // Measured per period: ~7.6e-12 ℓ of separation change, 6e-6 of the drift: 1e-4 of the total
    // drift bounds it with room and catches any secular separation.
    assert!(
        dsep.abs() < 1e-4 * total.abs(),
        "separation changed {dsep:e} ell while drifting {total:e} ell"
    );
}

#[test]
fn ten_thousand_periods_of_the_rigid_pair() {
    let (dsep, total) = run_long(Model::Rigid, None, 1e4);
    assert!(
        dsep.abs() < 1e-4 * total.abs(),
        "separation changed {dsep:e} ell while drifting {total:e} ell"
    );
}

#[test]
fn a_million_periods_of_the_averaged_pair() {
    let (dsep, total) = run_long(Model::Averaged, None, 1e6);
    // Aligned mirror pair: both swimmers move with the same velocity, exactly.
    assert!(dsep.abs() <= 1e-15 * total.abs(), "{dsep:e} vs {total:e}");
    assert!(total > 0.1, "the pair moved {total} ell in 1e6 periods");
}
