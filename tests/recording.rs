//! Recorders take rows exactly at their trigger times and nowhere else; rows survive errors; CSV
//! carries names and units; a saved scene loads back exactly.

use crate::common::*;
use swimlab::engine::{Observable, Recorder, Scene, Simulation, Trigger};

#[test]
fn periodic_recorder_samples_on_the_period_grid() {
    let s = mirror_inwards(10.0, true);
    let t = s.period().unwrap();
    let mut s = Simulation::new(s);
    let id = s.add_recorder(
        Recorder::new(&s, vec![Observable::Q(0, 1)], Trigger::EveryPeriods(2.0)).unwrap(),
    );
    s.run_periods(5.0).unwrap();
    let times: Vec<f64> = s.recorder(id).unwrap().rows.iter().map(|r| r[0]).collect();
    // Rows at 0, 2T, 4T; the run stopped exactly there, so the times are exact multiples.
    assert_eq!(times.len(), 3, "{times:?}");
    for (k, tk) in times.iter().enumerate() {
        assert!(
            (tk - 2.0 * k as f64 * t).abs() <= 1e-15 * t * 4.0,
            "{times:?}"
        );
    }
    s.run_periods(1.0).unwrap();
    assert_eq!(
        s.recorder(id).unwrap().rows.len(),
        4,
        "6T is the next sample"
    );
}

#[test]
fn recording_does_not_change_the_dynamics() {
    // Splitting runs at trigger times must not change the result beyond round-off of the
    // step sizes (fixed-step: one step is shortened at each split).
    let a = mirror_inwards(10.0, true);
    let mut b = Simulation::new(mirror_inwards(10.0, true));
    b.add_recorder(
        Recorder::new(
            &b,
            vec![Observable::CenterH(0)],
            Trigger::EverySeconds(1e-3),
        )
        .unwrap(),
    );
    let mut a = Simulation::new(a);
    a.run_periods(3.0).unwrap();
    b.run_periods(3.0).unwrap();
    let diff = (a.center(0).unwrap() - b.center(0).unwrap()).norm();
    // The drift over 3 periods is ~3.6e-6 ℓ; the split shortens ~10 steps of ~2,200 per period.
    assert!(diff < 1e-9 * ELL, "{diff:e} m");
}

#[test]
fn at_times_and_at_end_triggers() {
    let mut s = Simulation::new(mirror_inwards(10.0, false));
    let a = s.add_recorder(
        Recorder::new(
            &s,
            vec![Observable::Polarization],
            Trigger::AtTimes(vec![1e-3, 5e-3, 1.0]),
        )
        .unwrap(),
    );
    let e = s.add_recorder(Recorder::new(&s, vec![Observable::Nematic], Trigger::AtEnd).unwrap());
    s.run(0.01).unwrap();
    s.run(0.002).unwrap();
    let ta: Vec<f64> = s.recorder(a).unwrap().rows.iter().map(|r| r[0]).collect();
    assert_eq!(ta, vec![1e-3, 5e-3]);
    let te: Vec<f64> = s.recorder(e).unwrap().rows.iter().map(|r| r[0]).collect();
    assert_eq!(te.len(), 2);
    assert!((te[1] - 0.012).abs() < 1e-15);
    // Polarization of an antiparallel pair is 0, nematic order 1.
    assert!(s.recorder(a).unwrap().rows[0][1].abs() < 1e-15);
    assert!((s.recorder(e).unwrap().rows[0][1] - 1.0).abs() < 1e-12);
}

#[test]
fn rows_taken_before_a_failure_are_kept() {
    let mut s = Simulation::new(mirror_inwards(10.0, false));
    let id = s.add_recorder(
        Recorder::new(&s, vec![Observable::Length(0)], Trigger::EveryPeriods(0.1)).unwrap(),
    );
    s.run_periods(0.35).unwrap();
    let dt = 20.0 / s.stiff_rate();
    s.scene_mut()
        .set_integrator(Some(swimlab::engine::IntegratorSpec::Euler { dt }));
    assert!(s.run_periods(1.0).is_err());
    assert!(s.recorder(id).unwrap().rows.len() >= 4);
}

#[test]
fn csv_header_carries_names_and_units() {
    let mut s = Simulation::new(mirror_inwards(10.0, false));
    let id = s.add_recorder(
        Recorder::new(
            &s,
            vec![Observable::CenterH(1), Observable::Tension(0)],
            Trigger::EveryPeriods(1.0),
        )
        .unwrap(),
    );
    s.run_periods(2.0).unwrap();
    let path = std::env::temp_dir().join(format!("swimlab-rec-{}.csv", std::process::id()));
    s.recorder(id).unwrap().write_csv(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "time [s],R_H[1].x [m],R_H[1].y [m],R_H[1].z [m],tension[0] [N]"
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 3);
    // Values read back exactly (shortest round-trip formatting).
    assert_eq!(rows[2], s.recorder(id).unwrap().rows[2]);
}

#[test]
fn a_saved_scene_loads_back_exactly() {
    let mut s = mirror_inwards(10.0, true);
    s.set_integrator(Some(swimlab::engine::IntegratorSpec::Dopri5 { rtol: 1e-7 }));
    let mut s = Simulation::new(s);
    s.run_periods(1.37).unwrap();
    let json = s.to_json().unwrap();
    let mut t = Scene::from_json(&json).unwrap();
    assert_eq!(t.to_json().unwrap(), json);
    assert_eq!(t.raw_state().0, s.raw_state().0);
    assert_eq!(t.time(), s.time());
    assert_eq!(t.integrator(), s.integrator());
    // A fixed-step integrator then continues identically (an adaptive one restarts its step-size
    // control after loading, so it continues to within its tolerance only).
    s.scene_mut().set_integrator(None);
    t.set_integrator(None);
    s.run_periods(1.0).unwrap();
    let mut t = Simulation::new(t);
    t.run_periods(1.0).unwrap();
    assert_eq!(t.raw_state().0, s.raw_state().0);
    assert!(Scene::from_json("{\"format\": 9, \"scene\": {}}").is_err());
}

/// A probe observable (one period on a copy) stops at a step boundary when interrupted, as a run
/// does, and reports the scene's own time: the scene did not move.
#[test]
fn an_interrupt_stops_a_probe_mid_period() {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;
    let mut s = Simulation::new(mirror_inwards(10.0, true));
    s.run_periods(0.25).unwrap();
    let t0 = s.time();
    // 1e9 steps per period: far longer than the test waits, so only the interrupt ends it.
    let dt = s.period().unwrap() * 1e-9;
    s.scene_mut()
        .set_integrator(Some(swimlab::engine::IntegratorSpec::rk4(dt).unwrap()));
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    s.set_interrupt(Some(Arc::new(move || flag.load(Ordering::Relaxed))));
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let r = s.measure(&Observable::DeltaQ(0, 1));
        let _ = tx.send((r, s.time()));
    });
    std::thread::sleep(std::time::Duration::from_millis(300));
    stop.store(true, Ordering::Relaxed);
    let (r, t) = rx
        .recv_timeout(std::time::Duration::from_secs(20))
        .expect("the probe stops once interrupted");
    assert_eq!(
        r,
        Err(swimlab::engine::EngineError::Interrupted { time: t0 }),
        "interrupted at the scene's own time"
    );
    assert_eq!(t, t0, "the scene is unchanged");
}
