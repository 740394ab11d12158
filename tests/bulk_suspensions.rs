//! Bulk suspensions of the averaged model: neighbour lists against the all-pairs rows
//! while swimmers move, cross faces and are relisted; the suspension stepper's order, its
//! agreement with a tight Dormand-Prince reference, its contacts, guards, interrupts and
//! save/load mid-run.

use nalgebra::Vector3;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use swimlab::bench::suspension::{bulk_scene_apart, displacement_error};
use swimlab::engine::averaged::AveragedSystem;
use swimlab::engine::integrators::{IntegratorSpec, OdeSystem};
use swimlab::engine::{Coefficients, Dumbbell, EngineError, Model, Observable, Scene, Simulation};

fn asymmetric() -> Dumbbell {
    Dumbbell {
        a2: 0.5 * Dumbbell::default().a1,
        ..Dumbbell::default()
    }
}

/// The rates of `s`'s swimmers at state `y`, every pair found by the all-pairs rows.
fn all_pairs_rates(s: &Scene, y: &[f64]) -> Vec<f64> {
    let mut sys = system_of(s, y);
    sys.set_neighbour_lists(Some(false));
    let mut dy = vec![0.0; y.len()];
    sys.rhs(0.0, y, &mut dy);
    dy
}

fn system_of(s: &Scene, y: &[f64]) -> AveragedSystem {
    let (_, base) = s.raw_state();
    let mut sys = AveragedSystem::new(s.swimmers(), base, Coefficients::Paper, y);
    sys.set_periodic(s.periodic().copied());
    sys.set_cutoff(s.cutoff());
    sys.set_contacts(s.contacts(), s.mu());
    sys
}

/// Each 3-vector of `a` within `rel` of the largest of its kind in `b`.
fn assert_rates_close(a: &[f64], b: &[f64], rel: f64, what: &str) {
    let n = a.len() / 6;
    for kind in [0, 1] {
        let block = |v: &[f64], i: usize| {
            let k = 6 * i + 3 * kind;
            Vector3::new(v[k], v[k + 1], v[k + 2])
        };
        let scale = (0..n).map(|i| block(b, i).norm()).fold(0.0, f64::max);
        assert!(scale > 0.0, "{what}: no motion");
        for i in 0..n {
            let d = (block(a, i) - block(b, i)).norm();
            assert!(d <= rel * scale, "{what}, swimmer {i}: {d:e} of {scale:e}");
        }
    }
}

// One list system carried along a sequence of states (as a run carries it): swimmers drift by
// a fraction of the skin (no relisting), a few jump by more than half the skin (relisted alone),
// one swimmer walks across the box in steps of a tenth of its side (crossing faces, relisted at
// each), and finally every swimmer moves (a rebuild). At every state the rates equal the
// all-pairs rows' to 1e-13 of the largest of their kind: the same terms (the same switch, the
// same minimum images), summed in another order (≤ 60 partners, rounding ~1e-16 each).
#[test]
fn neighbour_lists_follow_moving_swimmers_and_equal_all_pairs_rows() {
    let d = asymmetric();
    for (with_box, with_steric) in [(true, true), (true, false), (false, true)] {
        let mut s = bulk_scene_apart(400, d, 2e-3, 32, Some(0.5 * d.ell)).unwrap();
        if !with_box {
            s.set_box(None).unwrap();
        }
        if !with_steric {
            s.set_steric(None);
        }
        let what = format!("box {with_box}, steric {with_steric}");
        let (y0, _) = s.raw_state();
        let mut y = y0.to_vec();
        let mut listed = system_of(&s, &y);
        listed.set_neighbour_lists(Some(true));
        let skin = 0.05 * s.cutoff().unwrap();
        listed.set_skin(Some(skin));
        let side = s.periodic().map_or(50.0 * d.ell, |b| b.shortest());
        let mut dy = vec![0.0; y.len()];
        let mut check = |y: &[f64], listed: &mut AveragedSystem, step: &str| {
            listed.rhs(0.0, y, &mut dy);
            assert_rates_close(
                &dy,
                &all_pairs_rates(&s, y),
                1e-13,
                &format!("{what}, {step}"),
            );
        };
        check(&y, &mut listed, "start");
        let builds = listed.list_builds();
        // A drift of a fifth of the skin, all swimmers: the lists stay.
        for i in 0..400 {
            y[6 * i] += 0.2 * skin * ((i % 7) as f64 / 7.0 - 0.5);
        }
        check(&y, &mut listed, "drift");
        assert_eq!(
            listed.list_builds(),
            builds,
            "{what}: a drift rebuilt the lists"
        );
        // Five swimmers jump by 0.8 skin: relisted alone.
        for i in [3, 77, 150, 222, 399] {
            y[6 * i + 1] += 0.8 * skin;
        }
        check(&y, &mut listed, "jumps");
        assert_eq!(
            listed.list_builds(),
            builds,
            "{what}: five jumps rebuilt the lists"
        );
        let relists = listed.list_relists();
        assert!(relists >= 5, "{what}: {relists} relists");
        // Swimmer 10 walks 1.2 sides along x and z: it crosses faces of the box.
        for k in 0..12 {
            y[60] += 0.1 * side;
            y[62] -= 0.1 * side;
            check(&y, &mut listed, &format!("walk {k}"));
        }
        assert!(listed.list_relists() >= relists + 12);
        // Every swimmer moves by a skin: rebuilt.
        for i in 0..400 {
            y[6 * i + 2] += skin * if i % 2 == 0 { 1.0 } else { -1.0 };
        }
        check(&y, &mut listed, "all moved");
        assert!(listed.list_builds() > builds, "{what}: not rebuilt");
    }
}

/// 300 swimmers at φ = 0.3% placed ℓ/2 apart (above the list threshold; the box holds the 6ℓ
/// cutoff), steric rods (smooth), and one more pair side by side and parallel, 0.2 µm apart
/// (within the 0.5 µm range): the contact is there from the start, so the implicit clusters and
/// the refinement of fast swimmers act, and the rods' force acts at the blended points of
/// parallel rods (closest points would jump from end to end with rounding and stall the step).
fn contact_scene() -> Scene {
    let d = Dumbbell::default();
    let base = bulk_scene_apart(300, d, 3e-3, 7, Some(0.5 * d.ell)).unwrap();
    let side = base.periodic().unwrap().shortest();
    let y = 2.0 * d.a1 + 0.2e-6;
    // The first spot of a coarse grid where the pair fits among the others.
    for k in 0..1000 {
        let c =
            Vector3::new((k % 10) as f64, ((k / 10) % 10) as f64, (k / 100) as f64) * (0.1 * side);
        let mut s = base.clone();
        if s.add(d, c, Vector3::x()).is_ok()
            && s.add(d, c + Vector3::new(0.0, y, 0.0), Vector3::x())
                .is_ok()
        {
            return s;
        }
    }
    panic!("no room for the pair");
}

fn run(mut s: Scene, spec: IntegratorSpec, periods: f64) -> Simulation {
    s.set_integrator(Some(spec));
    let mut sim = Simulation::new(s);
    sim.run_periods(periods).unwrap();
    sim
}

// The suspension stepper against Dormand-Prince at rtol 1e-11 over 20 periods. The reference's
// own error is bounded by its difference from rtol 1e-10 (measured 2.5e-11; the error falls with
// the tolerance: both lie within 5e-10 of RK4 at T/256, which is itself within RK4's 6.3e-9
// difference from T/128 there), below 1e-9, well under a tenth of the smallest error compared
// below (8e-7 at tol 1e-4). At the default tolerance the stepper is within 1e-3 of the RMS
// displacement (the accuracy a suspension study asks), and the error falls with tol.
#[test]
fn the_suspension_stepper_converges_to_a_tight_reference() {
    let state = |sim: &Simulation| sim.scene().raw_state().0.to_vec();
    let coarser = state(&run(
        contact_scene(),
        IntegratorSpec::dopri5(1e-10).unwrap(),
        20.0,
    ));
    let reference = state(&run(
        contact_scene(),
        IntegratorSpec::dopri5(1e-11).unwrap(),
        20.0,
    ));
    let reference_error = displacement_error(&reference, &coarser);
    assert!(reference_error < 1e-9, "dopri5 1e-11: {reference_error:e}");
    let mut rows = Vec::new();
    for tol in [1e-2, 1e-3, 1e-4] {
        let sim = run(
            contact_scene(),
            IntegratorSpec::suspension(tol).unwrap(),
            20.0,
        );
        let err = displacement_error(&state(&sim), &reference);
        rows.push((tol, err, sim.stats().steps as f64));
    }
    assert!(rows[1].1 < 1e-3, "{rows:?}");
    // Each error within twice its tolerance (the contract bounds each step's error against each
    // swimmer's own motion in that step; over 20 periods the contact pair's errors add up over
    // its substeps, and at the loosest tolerance the RMS over swimmers reaches 1.1 tol), and
    // falling at least 3× per decade of tol (the refined contact pair's substeps answer to tol,
    // not to the coarse step count, so an order against coarse steps is measured in `swimlab
    // bench suspension`, on a scene without a pair in contact from the start).
    assert!(
        rows.iter().all(|r| r.1 <= 2.0 * r.0) && rows.windows(2).all(|w| w[1].1 * 3.0 < w[0].1),
        "{rows:?}"
    );
}

// Over 300 periods from a contact the run never accepts an overlap (the guard would stop it) and
// the smallest sphere gap, read every 10 periods, stays positive; the pair in contact was pushed
// apart (its gap grew) and a few fast swimmers were refined.
#[test]
fn suspension_runs_keep_swimmers_apart() {
    let s = contact_scene();
    let pair = (s.count() - 2, s.count() - 1);
    let gap_of_pair =
        |sim: &Simulation| Observable::DistanceH(pair.0, pair.1).evaluate(sim).unwrap()[0];
    let mut sim = Simulation::new(s);
    let start = gap_of_pair(&sim);
    for _ in 0..30 {
        sim.run_periods(10.0).unwrap();
        let gap = Observable::MinGap.evaluate(&sim).unwrap()[0];
        assert!(gap > 0.0, "min gap {gap:e} at t = {:e}", sim.time());
    }
    assert!(
        gap_of_pair(&sim) > start,
        "the pair in contact did not separate"
    );
    assert!(sim.stats().refined_steps > 0, "{:?}", sim.stats());
}

// The default integrator of a suspension is the suspension stepper, and `auto` picks it; the
// spring model refuses it, naming the averaged model.
#[test]
fn suspensions_default_to_the_suspension_stepper() {
    let s = contact_scene();
    assert!(matches!(s.integrator(), IntegratorSpec::Suspension { .. }));
    assert!(s.integrator_info().unwrap().contains("suspension"));
    let mut auto = contact_scene();
    auto.set_integrator(Some(IntegratorSpec::auto(1e-4).unwrap()));
    let info = auto.integrator_info().unwrap();
    assert!(info.contains("runs suspension(1e-4)"), "{info}");
    let mut micro = contact_scene();
    micro.set_model(Model::Micro);
    micro.set_integrator(Some(IntegratorSpec::suspension(1e-3).unwrap()));
    let e = Simulation::new(micro).run_periods(0.01).unwrap_err();
    assert!(e.to_string().contains("averaged"), "{e}");
}

// A run split by save and load (the stepper starts afresh) or by an interrupt ends where one run
// does to within the tolerance's reach: 1e-2 of the RMS displacement at tol 1e-4 (the two paths
// take different steps; each is within ~1e-4 of the exact one, see the convergence test).
#[test]
fn save_load_and_interrupts_mid_run_continue_the_run() {
    let spec = IntegratorSpec::suspension(1e-4).unwrap();
    let whole = run(contact_scene(), spec, 40.0);
    let first = run(contact_scene(), spec, 20.0);
    let json = first.scene().to_json().unwrap();
    let mut second = Simulation::new(Scene::from_json(&json).unwrap());
    assert_eq!(second.scene().integrator(), spec);
    second.run_periods(20.0).unwrap();
    let (a, b) = (second.scene().raw_state().0, whole.scene().raw_state().0);
    let err = displacement_error(a, b);
    assert!(err < 1e-2, "save/load: {err:e}");

    let mut s = contact_scene();
    s.set_integrator(Some(spec));
    let mut stopped = Simulation::new(s);
    let calls = Arc::new(AtomicU64::new(0));
    let c = calls.clone();
    stopped.set_interrupt(Some(Arc::new(move || {
        c.fetch_add(1, Ordering::Relaxed) >= 5
    })));
    let period = stopped.period().unwrap();
    let e = stopped.run(40.0 * period).unwrap_err();
    assert!(matches!(e, EngineError::Interrupted { .. }), "{e}");
    let at = stopped.time();
    assert!(at > 0.0 && at < 40.0 * period, "{}", at / period);
    assert!(stopped.scene().raw_state().0.iter().all(|v| v.is_finite()));
    stopped.set_interrupt(None);
    stopped.run(40.0 * period - at).unwrap();
    let err = displacement_error(stopped.scene().raw_state().0, b);
    assert!(err < 1e-2, "interrupted: {err:e}");
}

// The rates of a few swimmers that a refinement evaluates (from their list rows and the states
// alone: on this thread, `rhs_bodies`, or shared among threads, `rates_shared`) equal the whole
// right-hand side's, at the state the list was built for and at one where every swimmer moved
// (within half the skin, so nobody is relisted), the pair in contact included (steric forces).
// They differ only in summation order (scalar terms against the lanes): 1e-12 of the largest
// rate.
#[test]
fn a_few_swimmers_rates_equal_the_whole_right_hand_side() {
    let s = contact_scene();
    let n = s.count();
    let (y, _) = s.raw_state();
    let mut moved = y.to_vec();
    let ell = Dumbbell::default().ell;
    for (i, v) in moved.iter_mut().enumerate() {
        if i % 6 < 3 {
            *v += 1e-3 * ell * ((i as f64) * 0.7).sin();
        }
    }
    let mut sys = s.system().unwrap();
    let mut full = vec![0.0; y.len()];
    sys.rhs(0.0, y, &mut full);
    let bodies = vec![0, 5, 17, 120, n - 2, n - 1];
    for state in [y.to_vec(), moved] {
        sys.rhs(0.0, &state, &mut full);
        let p = sys.as_partitioned().unwrap();
        assert!(p.shares_rates());
        let mut partners = Vec::new();
        p.partners(&bodies, &mut partners);
        let mut changed: Vec<usize> = bodies.iter().chain(&partners).copied().collect();
        changed.sort_unstable();
        let (mut own, mut shared) = (vec![0.0; y.len()], vec![0.0; y.len()]);
        p.rhs_bodies(0.0, &state, &bodies, &changed, &mut own);
        assert!(p.rates_shared(&state, &bodies, &changed, &mut shared));
        let scale = full.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for &b in &bodies {
            for m in 6 * b..6 * b + 6 {
                assert!(
                    (own[m] - full[m]).abs() <= 1e-12 * scale,
                    "{m}: {} {}",
                    own[m],
                    full[m]
                );
                assert_eq!(own[m], shared[m]);
            }
        }
    }
    // A swimmer moved beyond half the skin: shared rates refuse (the list must change first).
    let p = sys.as_partitioned().unwrap();
    let mut far = y.to_vec();
    far[6 * 5] += ell;
    let mut out = vec![0.0; y.len()];
    assert!(!p.rates_shared(&far, &[5], &[5], &mut out));
}

// Refined groups are stepped on rayon's threads: the run is the same bit for bit on one thread
// and on two (1,000 swimmers placed ℓ/2 apart, contacts forming, many groups refined a step).
#[test]
fn refinement_does_not_depend_on_the_thread_count() {
    let run_on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let d = Dumbbell::default();
            let s = bulk_scene_apart(1000, d, 3e-3, 2026, Some(0.5 * d.ell)).unwrap();
            let sim = run(s, IntegratorSpec::suspension(1e-3).unwrap(), 30.0);
            (
                sim.scene().raw_state().0.to_vec(),
                sim.stats().refined_steps,
            )
        })
    };
    let (one, refined) = run_on(1);
    assert!(refined > 0, "nothing was refined");
    assert_eq!(run_on(2), (one, refined));
}

// A relisting that meets new partners across a face adds ghost slots; the slot arrays filled
// before it then get only those ghosts' entries appended (`extend_positions`,
// `extend_values`), which must equal arrays filled anew after it, bit for bit (the same
// additions of the same lattice vectors).
#[test]
fn slot_arrays_extended_after_a_relisting_equal_arrays_filled_anew() {
    use swimlab::engine::neighbours::{ListSpec, NeighbourList};
    use swimlab::engine::periodic::PeriodicBox;
    let side = 20.0;
    let b = PeriodicBox::new([side; 3]).unwrap();
    // 500 centres on a jittered lattice (the box spans −L/2..L/2 after wrapping), swimmer 0
    // near the middle of the box.
    let n = 500;
    let mut x: Vec<f64> = (0..n)
        .map(|i| (i % 8) as f64 * 2.5 + 0.1 * (i % 3) as f64)
        .collect();
    let mut y: Vec<f64> = (0..n)
        .map(|i| ((i / 8) % 8) as f64 * 2.5 + 0.07 * (i % 5) as f64)
        .collect();
    let mut z: Vec<f64> = (0..n)
        .map(|i| (i / 64) as f64 * 2.5 + 0.05 * (i % 7) as f64)
        .collect();
    (x[0], y[0], z[0]) = (1.2, 1.2, 1.2);
    let spec = ListSpec {
        cutoff: 3.0,
        contact_reach: 1.0,
        skin: 0.5,
    };
    let weight = |i: usize, j: usize| Some(((i * 31 + j * 17) % 11) as f64 / 11.0 - 0.5);
    let mut list = NeighbourList::build(&x, &y, &z, Some(&b), spec, &weight);
    let (mut px, mut py, mut pz) = (Vec::new(), Vec::new(), Vec::new());
    list.fill_positions([&x, &y, &z], [&mut px, &mut py, &mut pz]);
    let mut ids = Vec::new();
    list.fill_values(|s| s as f64, -1.0, &mut ids);
    let slots_before = list.slots();
    // Swimmer 0 jumps to a corner of the box: it meets its new partners across three faces.
    (x[0], y[0], z[0]) = (9.9, 9.9, 9.9);
    let grown = list.relist(0, [x[0], y[0], z[0]], &weight);
    assert!(grown && list.slots() > slots_before, "no ghost slot added");
    // The new ghosts appended, then the moved swimmer's entries set (its slot and ghosts), as
    // the averaged system does after a relisting.
    list.extend_positions([&mut px, &mut py, &mut pz]);
    list.extend_values(&mut ids);
    list.set_position(
        0,
        [x[0], y[0], z[0]],
        [&mut px[..], &mut py[..], &mut pz[..]],
    );
    let (mut qx, mut qy, mut qz) = (Vec::new(), Vec::new(), Vec::new());
    list.fill_positions([&x, &y, &z], [&mut qx, &mut qy, &mut qz]);
    let mut fresh = Vec::new();
    list.fill_values(|s| s as f64, -1.0, &mut fresh);
    assert_eq!(px.len(), list.slots());
    for (d, (a, b)) in [(&px, &qx), (&py, &qy), (&pz, &qz)].into_iter().enumerate() {
        for k in 0..a.len() {
            assert_eq!(a[k].to_bits(), b[k].to_bits(), "axis {d}, slot {k}");
        }
    }
    assert_eq!(ids, fresh);
}
