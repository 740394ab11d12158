//! The scallop theorem: a reciprocal stroke does not swim. An isolated dumbbell's hydrodynamic centre
//! is a function of its length alone (dR_H/dt ∝ dd/dt along the fixed axis), so it returns to itself
//! whenever the length does, once per period after the springs settle. Two swimmers in phase (or in
//! antiphase) are, together, a reciprocal swimmer too: no collective drift.

use crate::common::*;
use nalgebra::Vector3;
use std::f64::consts::PI;
use swimlab::engine::{Scene, Simulation};

#[test]
fn isolated_asymmetric_dumbbell_returns_each_period() {
    let mut s = Scene::new();
    s.add(
        swimmer(0.15, true, 0.3),
        Vector3::new(1e-6, -2e-6, 3e-6),
        Vector3::new(1.0, 2.0, -0.5),
    )
    .unwrap();
    let mut s = Simulation::new(s);
    s.run_periods(1.0).unwrap();
    let mut previous = s.center(0).unwrap();
    for _ in 0..5 {
        s.run_periods(1.0).unwrap();
        let now = s.center(0).unwrap();
        // 1e-12 ℓ per period, a billionth of the ~1e-3 ℓ the stroke moves R_H within a period.
        let moved = (now - previous).norm() / ELL;
        assert!(moved < 1e-12, "R_H moved {moved:e} ell over one period");
        previous = now;
    }
}

#[test]
fn in_phase_and_antiphase_pairs_do_not_drift_collectively() {
    for dphi in [0.0, PI] {
        for asym in [false, true] {
            let mut s = mirror_inwards(10.0, asym);
            s.set_phase(1, dphi).unwrap();
            let (mean, _) = drift_per_period(&mut s, 3.0);
            // The phase-shifted pair drifts ~1e-6 ℓ per period; 1e-12 ℓ is a millionth of that.
            assert!(
                mean.abs() < 1e-12,
                "dphi = {dphi}, asym = {asym}: drift {mean:e} ell/period"
            );
        }
    }
}
