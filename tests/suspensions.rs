//! Suspensions: large random scenes stay finite under the guards, the averaged model's rows are
//! independent of the thread count, its cutoff keeps its stated bound, contacts (overlaps,
//! steric repulsion) behave, and the collective observables count what they say.

use nalgebra::Vector3;
use rhai::Scope;
use swimlab::engine::averaged::AveragedSystem;
use swimlab::engine::build::{box_side, random_suspension, Orientations, Phases};
use swimlab::engine::integrators::OdeSystem;
use swimlab::engine::{Coefficients, Dumbbell, Model, Observable, Scene, Simulation, Steric};
use swimlab::script::run_source;

fn suspension(model: Model, n: usize, phi: f64, d: Dumbbell, seed: u64) -> Scene {
    let mut s = Scene::new();
    s.set_model(model);
    let side = box_side(n, &d, phi).unwrap();
    random_suspension(
        &mut s,
        n,
        d,
        [side; 3],
        Orientations::Random,
        Phases::Random,
        seed,
    )
    .unwrap();
    s
}

fn asymmetric() -> Dumbbell {
    Dumbbell {
        a1: 1.125e-6,
        a2: 0.5625e-6,
        ..Dumbbell::default()
    }
}

fn all_finite(s: &Scene) -> bool {
    let (y, _) = s.raw_state();
    y.iter().all(|v| v.is_finite())
}

// A 1,000-swimmer averaged run for a few periods stays finite with the guards on (the
// default contact guard stops a run cleanly instead; here the steric repulsion keeps swimmers
// apart, so the run must complete).
#[test]
fn thousand_swimmer_averaged_run_stays_finite() {
    let mut s = suspension(Model::Averaged, 1000, 0.001, asymmetric(), 11);
    s.set_steric(Some(Steric::new(0.2e-6, 1e-6).unwrap()));
    let mut s = Simulation::new(s);
    s.run_periods(3.0).unwrap();
    assert!(all_finite(&s));
    let p = Observable::Polarization.evaluate(&s).unwrap()[0];
    assert!(
        p.is_finite() && p < 0.2,
        "random orientations: polarization {p}"
    );
}

// A 200-swimmer microscopic run (400 spheres, the fast kernel in parallel) for a few
// periods with the default integrator and every guard.
#[test]
fn two_hundred_swimmer_micro_run_stays_finite() {
    let mut s = Simulation::new(suspension(Model::Micro, 200, 0.01, Dumbbell::default(), 5));
    s.run_periods(2.0).unwrap();
    assert!(all_finite(&s));
    let gap = Observable::MinGap.evaluate(&s).unwrap()[0];
    assert!(gap > 0.0, "min gap {gap:e}");
}

fn averaged_rates(s: &Scene, cutoff: Option<f64>) -> Vec<f64> {
    let (y, base) = s.raw_state();
    let mut sys = AveragedSystem::new(s.swimmers(), base, Coefficients::Paper, y);
    sys.set_cutoff(cutoff);
    let mut dy = vec![0.0; y.len()];
    sys.rhs(0.0, y, &mut dy);
    dy
}

// Cell lists find a cutoff's pairs among the 27 cells around each swimmer; they sum them cell by
// cell, so the rates equal the all-pairs loop's to the rounding of another order: each 3-vector
// within 1e-12 of the largest of its kind (≤ 700 terms of both signs, ~1e-16 each).
#[test]
fn cell_lists_give_the_all_pairs_rates() {
    let s = suspension(Model::Averaged, 700, 0.002, asymmetric(), 13);
    let (y, base) = s.raw_state();
    let ell = s.swimmers()[0].ell;
    for cutoff in [3.0 * ell, 8.0 * ell, 1e3 * ell] {
        for steric in [
            None,
            Some(swimlab::engine::Steric::new(1e-7, 1e-3).unwrap()),
        ] {
            let rates = |cells: bool| {
                let mut sys = AveragedSystem::new(s.swimmers(), base, Coefficients::Paper, y);
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
            let (a, b) = (rates(true), rates(false));
            for kind in [0, 1] {
                let block = |v: &[f64], i: usize| {
                    let k = 6 * i + 3 * kind;
                    Vector3::new(v[k], v[k + 1], v[k + 2])
                };
                let n = a.len() / 6;
                let scale = (0..n).map(|i| block(&b, i).norm()).fold(0.0, f64::max);
                for i in 0..n {
                    let d = (block(&a, i) - block(&b, i)).norm();
                    assert!(
                        d <= 1e-12 * scale,
                        "cutoff {cutoff:e}, steric {steric:?}, swimmer {i}: {d:e} of {scale:e}"
                    );
                }
            }
        }
    }
}

// Each swimmer sums its partners in one order whatever thread runs it: 1, 2 or 3 threads give
// the same bits (300 and 700 swimmers, above the parallel threshold, in vector lanes).
#[test]
fn averaged_rows_do_not_depend_on_the_thread_count() {
    for n in [300, 700] {
        let s = suspension(Model::Averaged, n, 0.001, asymmetric(), 3);
        let reference = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| averaged_rates(&s, None));
        for threads in [2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            assert_eq!(
                pool.install(|| averaged_rates(&s, None)),
                reference,
                "{n} swimmers, {threads} threads"
            );
        }
    }
}

// The cutoff's error is bounded per pair beyond the switch's inner edge by `far_pair_bound` there;
// a swimmer's error is at most its number of such pairs times that. The test also requires the cutoff to change
// something (a bound that is never approached would be untested).
#[test]
fn averaged_cutoff_error_stays_within_its_bound() {
    let s = suspension(Model::Averaged, 300, 0.001, asymmetric(), 9);
    let (y, base) = s.raw_state();
    let sys = AveragedSystem::new(s.swimmers(), base, Coefficients::Paper, y);
    let cutoff = 8.0 * s.swimmers()[0].ell;
    let full = averaged_rates(&s, None);
    let cut = averaged_rates(&s, Some(cutoff));
    let centres: Vec<Vector3<f64>> = (0..s.count()).map(|i| s.center(i).unwrap()).collect();
    // Pairs beyond the switch's inner edge lose part or all of their terms.
    let inner = (1.0 - swimlab::engine::averaged::CUTOFF_SWITCH_WIDTH) * cutoff;
    let (bv, bw) = sys.far_pair_bound(0, inner);
    let mut largest_ratio: f64 = 0.0;
    for i in 0..s.count() {
        let left_out = centres
            .iter()
            .filter(|c| (*c - centres[i]).norm() > inner)
            .count() as f64;
        let dv = Vector3::from_fn(|k, _| full[6 * i + k] - cut[6 * i + k]).norm();
        let dw = Vector3::from_fn(|k, _| full[6 * i + 3 + k] - cut[6 * i + 3 + k]).norm();
        assert!(dv <= left_out * bv && dw <= left_out * bw, "swimmer {i}");
        largest_ratio = largest_ratio.max(dv / (left_out * bv).max(f64::MIN_POSITIVE));
    }
    assert!(largest_ratio > 0.0, "the cutoff changed nothing");
}

fn side_by_side(gap: f64) -> Scene {
    // Two Fig-1 swimmers along x, side by side in y with a surface gap `gap`, in phase.
    let d = Dumbbell::default();
    let mut s = Scene::new();
    s.add(d, Vector3::zeros(), Vector3::x()).unwrap();
    s.add(d, Vector3::new(0.0, 2.0 * d.a1 + gap, 0.0), Vector3::x())
        .unwrap();
    s
}

// Steric repulsion pushes close swimmers apart, by far more than the same pair moves without it
// (an in-phase pair has no drift of its own beyond the spring's small lag).
#[test]
fn steric_repulsion_separates_close_swimmers() {
    let gap = 0.05e-6;
    let plain = side_by_side(gap);
    let d0 = Observable::DistanceH(0, 1).evaluate(&plain).unwrap()[0];
    let mut plain = Simulation::new(plain);
    plain.run_periods(1.0).unwrap();
    let d_plain = Observable::DistanceH(0, 1).evaluate(&plain).unwrap()[0];
    let mut pushed = side_by_side(gap);
    pushed.set_steric(Some(Steric::new(0.1e-6, 1e-4).unwrap()));
    let mut pushed = Simulation::new(pushed);
    pushed.run_periods(1.0).unwrap();
    let d_pushed = Observable::DistanceH(0, 1).evaluate(&pushed).unwrap()[0];
    assert!(
        d_pushed - d0 > 0.1 * gap && d_pushed - d0 > 100.0 * (d_plain - d0).abs(),
        "with repulsion {:e}, without {:e}",
        d_pushed - d0,
        d_plain - d0
    );
    // Repulsion is a pair force: the pair's mean y does not move (the swimmers are mirror images
    // in y, so each moves by the same amount in opposite directions).
    let mean_y = (pushed.center(0).unwrap().y + pushed.center(1).unwrap().y) / 2.0;
    assert!(
        (mean_y - (2.0 * Dumbbell::default().a1 + gap) / 2.0).abs() < 1e-9 * gap,
        "mean y moved by {mean_y:e}"
    );
}

// Spheres of different swimmers overlapping stop a run by default and run on, finite, with
// s.overlaps = "allow" (the overlapping-sphere RPY form keeps the mobility positive definite).
#[test]
fn overlaps_stop_by_default_and_run_on_when_allowed() {
    let d = Dumbbell::default();
    let build = || {
        let mut s = Scene::new();
        s.add(d, Vector3::zeros(), Vector3::x()).unwrap();
        // At right angles, swimmer 1's first sphere 0.02 µm above swimmer 0's second one at
        // t = 0; the strokes (±λ/2 per sphere) then push the two spheres into each other.
        let y = 2.0 * d.a1 + 0.02e-6 + d.ell / 2.0;
        s.add(d, Vector3::new(d.ell / 2.0, y, 0.0), Vector3::y())
            .unwrap();
        s
    };
    let mut stop = Simulation::new(build());
    let e = stop.run_periods(1.0);
    assert!(e.is_err(), "expected a contact");
    let mut allow = build();
    allow.set_allow_overlap(true);
    let mut allow = Simulation::new(allow);
    allow.run_periods(1.0).unwrap();
    assert!(all_finite(&allow));
}

// Counts of all pairs add up to S(S−1)/2 when r_max covers the scene; on a line of spacing h,
// bin k of width h holds the S − k pairs k apart... shifted by a half bin to avoid edges.
#[test]
fn pair_distance_histogram_counts_pairs() {
    let mut s = Scene::new();
    let d = Dumbbell::default();
    let h = 3.0 * d.ell;
    for i in 0..6 {
        s.add(d, Vector3::new(i as f64 * h, 0.0, 0.0), Vector3::x())
            .unwrap();
    }
    let bins = 8;
    let o = Observable::PairDistances {
        bins,
        r_max: (bins as f64 - 0.5) * h,
    };
    let hist = o.evaluate(&s).unwrap();
    // Bin width is (bins − 0.5)h/bins < h, so distance k·h falls in bin floor(k·bins/(bins − 0.5)).
    let mut expected = vec![0.0; bins];
    for k in 1..6 {
        expected[(k as f64 * bins as f64 / (bins as f64 - 0.5)) as usize] += (6 - k) as f64;
    }
    assert_eq!(hist, expected);
    assert_eq!(hist.iter().sum::<f64>(), 15.0);
    assert!(Observable::PairDistances {
        bins: 0,
        r_max: 1.0
    }
    .check(&s)
    .is_err());
}

// In the averaged model the mean speed is ⟨|dR_H/dt|⟩ of the model's own rates.
#[test]
fn mean_speed_is_the_mean_of_the_rates() {
    let s = suspension(Model::Averaged, 40, 0.001, asymmetric(), 4);
    let dy = averaged_rates(&s, None);
    let expected = (0..40)
        .map(|i| Vector3::new(dy[6 * i], dy[6 * i + 1], dy[6 * i + 2]).norm())
        .sum::<f64>()
        / 40.0;
    let got = Observable::MeanSpeed.evaluate(&s).unwrap()[0];
    assert!(
        (got - expected).abs() <= 1e-14 * expected,
        "{got:e} vs {expected:e}"
    );
}

fn script(src: &str) -> Result<(), String> {
    run_source("test", src, &mut Scope::new())
}

// sweep: results in the order of the parameters, on any thread count; a failing call is named.
#[test]
fn sweep_returns_results_in_order_and_names_a_failing_parameter() {
    script(
        r#"
        let f = |p| {
            let s = scene();
            s.model = "averaged";
            s.add(dumbbell());
            s.add(dumbbell(#{ center: [p * 1e-6, 0, 0], phase: 1.0 }));
            s.run_periods(2);
            s.observe(R_H(1))[0]
        };
        let ps = [20, 30, 40, 50, 60];
        let a = sweep(ps, f);
        let b = sweep(ps, f, 1);
        let c = ps.map(f);
        if a != c || b != c { throw `sweep ${a} / ${b} differ from map ${c}`; }
        "#,
    )
    .unwrap();
    let err = script("sweep([1, 2, 3], |p| if p == 2 { throw \"bad\" } else { p });").unwrap_err();
    assert!(
        err.contains("parameter 1 (2)") && err.contains("bad"),
        "{err}"
    );
    let err = script("sweep([1], |p| p, 0);").unwrap_err();
    assert!(err.contains("threads must be at least 1"), "{err}");
}

// Lattices from the stdlib go in with add_at, all or nothing.
#[test]
fn lattices_are_added_all_or_nothing() {
    script(
        r#"
        import "lattice" as lattice;
        let s = scene();
        s.add_at(dumbbell(), lattice::cubic(3, 2, 2, 20e-6));
        if s.count != 12 { throw `count ${s.count}`; }
        let h = lattice::hexagonal(4, 3, 20e-6);
        if h.len() != 12 { throw "hexagonal"; }
        let t = scene();
        let ok = false;
        // 1 µm apart overlaps from the second swimmer on: nothing is added.
        try { t.add_at(dumbbell(), lattice::line(5, 1e-6)); } catch (e) { ok = t.count == 0 && `${e}`.contains("centre 1"); }
        if !ok { throw "not all-or-nothing"; }
        "#,
    )
    .unwrap();
}

// Bad contact settings are refused with the fix in the message.
#[test]
fn contact_settings_are_checked() {
    let e = script("let s = scene(); s.steric = #{ range: -1.0, stiffness: 1e-3 };").unwrap_err();
    assert!(e.contains("range must be a positive number"), "{e}");
    let e = script("let s = scene(); s.steric = #{ range: 1e-7 };").unwrap_err();
    assert!(e.contains("needs both range and stiffness"), "{e}");
    let e = script("let s = scene(); s.steric = #{ range: 1e-7, stiffness: 1e-3, body: \"rod\" };")
        .unwrap_err();
    assert!(e.contains("rods") && e.contains("spheres"), "{e}");
    script(
        "let s = scene(); s.steric = #{ range: 1e-7, stiffness: 1e-3, body: \"rods\" }; \
         if s.steric.body != \"rods\" { throw \"body not kept\" }",
    )
    .unwrap();
    let e = script("let s = scene(); s.overlaps = \"sometimes\";").unwrap_err();
    assert!(e.contains("stop") && e.contains("allow"), "{e}");
    let e = script("let s = scene(); s.cutoff = 0;").unwrap_err();
    assert!(e.contains("cutoff must be a positive distance"), "{e}");
    // The rigid-stroke model takes steric repulsion as a body force (tests/rigid_stroke.rs).
    script(
        "let s = scene(); s.add(dumbbell()); s.model = \"rigid\"; s.steric = #{ range: 1e-7, stiffness: 1e-3 }; s.run_periods(1);",
    )
    .unwrap();
}

// From 512 swimmers the averaged guard groups equal centres instead of comparing all pairs: it
// names the same first pair, and a large scene's contact guard goes through cell lists.
#[test]
fn large_averaged_guards_name_the_same_swimmers() {
    let base = suspension(Model::Averaged, 600, 0.001, asymmetric(), 21);
    let (y, b) = base.raw_state();
    let check = |y: &[f64], b: &[Vector3<f64>]| {
        let mut sys = AveragedSystem::new(base.swimmers(), b, Coefficients::Paper, y);
        swimlab::engine::integrators::OdeSystem::check(&mut sys, 0.0, y).map_err(|p| p.cause)
    };
    assert_eq!(check(y, b), Ok(()));
    // Swimmer 400's centre onto swimmer 123's, then swimmer 300's spheres onto 50's.
    let mut moved = b.to_vec();
    let mut y2 = y.to_vec();
    moved[400] = b[123];
    y2[6 * 400..6 * 400 + 3].copy_from_slice(&y[6 * 123..6 * 123 + 3]);
    let e = check(&y2, &moved).unwrap_err();
    assert!(
        e.contains("swimmers 123 and 400 have the same centre"),
        "{e}"
    );
    let mut moved = b.to_vec();
    moved[300] = b[50] + Vector3::new(0.3e-6, 0.0, 0.0);
    let mut y3 = y.to_vec();
    y3[6 * 300..6 * 300 + 3].copy_from_slice(&y[6 * 50..6 * 50 + 3]);
    y3[6 * 300 + 3..6 * 300 + 6].copy_from_slice(&y[6 * 50 + 3..6 * 50 + 6]);
    let e = check(&y3, &moved).unwrap_err();
    assert!(e.contains("swimmer 50") && e.contains("swimmer 300"), "{e}");
}

// The vector-lane rows against the scalar rows: every term in play (asymmetric and symmetric
// swimmers, both coefficient sets, every shortcut on and off, a cutoff, steric repulsion), each
// 3-vector within 1e-13 of the largest of its kind (≤ 700 terms summed in another order, the
// lanes' brackets with fused multiply-adds).
#[test]
fn vector_lane_rows_equal_the_scalar_rows() {
    use swimlab::engine::averaged::Shortcuts;
    let mut mixed = suspension(Model::Averaged, 350, 0.002, asymmetric(), 17);
    let sym = Dumbbell::default();
    let side = box_side(350, &sym, 0.002).unwrap();
    random_suspension(
        &mut mixed,
        350,
        sym,
        [2.0 * side; 3],
        Orientations::Random,
        Phases::Random,
        18,
    )
    .unwrap();
    let (y, base) = mixed.raw_state();
    let ell = mixed.swimmers()[0].ell;
    for set in [Coefficients::Paper, Coefficients::LeadingOrder] {
        for shortcuts in [Shortcuts::default(), Shortcuts::none()] {
            for cutoff in [None, Some(6.0 * ell)] {
                for steric in [
                    None,
                    Some(swimlab::engine::Steric::new(1e-7, 1e-3).unwrap()),
                ] {
                    let rates = |lanes: bool| {
                        let mut sys = AveragedSystem::with_shortcuts(
                            mixed.swimmers(),
                            base,
                            set,
                            y,
                            shortcuts,
                        );
                        sys.set_cutoff(cutoff);
                        sys.set_neighbour_lists(Some(false));
                        sys.set_contacts(
                            swimlab::engine::Contacts {
                                allow_overlap: false,
                                steric,
                            },
                            1e-3,
                        );
                        sys.set_vector_rows(Some(lanes));
                        let mut dy = vec![0.0; y.len()];
                        sys.rhs(0.0, y, &mut dy);
                        dy
                    };
                    let (a, b) = (rates(true), rates(false));
                    let n = a.len() / 6;
                    for kind in [0, 1] {
                        let block = |v: &[f64], i: usize| {
                            let k = 6 * i + 3 * kind;
                            Vector3::new(v[k], v[k + 1], v[k + 2])
                        };
                        let scale = (0..n).map(|i| block(&b, i).norm()).fold(0.0, f64::max);
                        assert!(scale > 0.0);
                        for i in 0..n {
                            let d = (block(&a, i) - block(&b, i)).norm();
                            assert!(
                            d <= 1e-13 * scale,
                            "{set:?} {shortcuts:?} cutoff {cutoff:?} steric {steric:?}, swimmer {i}: {d:e} of {scale:e}"
                        );
                        }
                    }
                }
            }
        }
    }
}
