//! The continuum tried as a hostile new user would ("nothing lost, nothing hangs", round three):
//! every run-like call checks its horizon and tolerance before it starts, every option and length
//! is checked against what the grid and the box hold, a perturbation keeps the distribution a
//! distribution and the conserved numbers, modes are the ones the grid or f64 resolve, and a
//! continuum a sweep's calls share is refused in swimlab's words. Each case runs in its own
//! `swimlab` process under a time limit, so a hang fails the test instead of stalling it, and a
//! panic shows as the "internal error" the script boundary turns it into.

use crate::common::cli;

/// [`cli::case_without`] Rhai's own data-race text and a NaN or infinity shown as a value.
#[track_caller]
fn case(script: &str, fragments: &[&str], code: i32) -> String {
    cli::case_without(script, fragments, &["Data race", "NaN,", "inf,"], code)
}

/// A box scene of two swimmers at two phases (the fuzz's prologue) and its continuum.
/// Prints whether each count of continuum `d` is its one swimmer, to 1e-12: the deposit's and
/// the run's round-off on counts of 1 is some 1e-15.
const COUNTS_ONE: &str = "print(d.counts().map(|x| (x - 1.0).abs() < 1e-12));\n";

const C: &str = "let b = scene();\nb.box = [120e-6, 120e-6, 120e-6];\nb.add(dumbbell(#{ center: [-30e-6, 0, 0] }));\nb.add(dumbbell(#{ phase: 1.0 }));\nlet c = continuum(b, #{ grid: 4, orientations: 2 });\n";

/// `try` a call, print what it says, and print whether the continuum's state (its time, counts
/// and the density at the first mode) is what it was.
fn refused(call: &str) -> String {
    format!(
        "let before = [c.time, c.counts(), c.mode(\"density\", [1, 0, 0]).abs];\ntry {{ {call}; print(\"accepted\"); }} catch (e) {{ print(e); }}\nprint(\"unchanged: \" + ([c.time, c.counts(), c.mode(\"density\", [1, 0, 0]).abs] == before));\n"
    )
}

/// A run past 1e9 stroke periods is refused before it starts, with the scene's check and words;
/// so are a run of no length (NaN) and a tolerance below what f64 resolves.
#[test]
fn a_continuum_run_checks_its_horizon_and_tolerance_as_a_scene_does() {
    case(
        &format!("{C}{}", refused("c.run_periods(1e308)")),
        &[
            "this run would end at t = ",
            "past the latest time a continuum may hold",
            "1e9 stroke periods: beyond, f64 no longer resolves the stroke",
            "run at most 1.256637e7 s (1.000000e9 periods) more",
            "unchanged: true",
        ],
        0,
    );
    case(
        &format!("{C}{}", refused("c.run_periods(1e308 * 10.0)")),
        &[
            "past the latest time a continuum may hold",
            "unchanged: true",
        ],
        0,
    );
    case(
        &format!("{C}{}", refused("c.run(0.0 / 0.0)")),
        &[
            "would end at t = NaN s; give its length as a number",
            "unchanged: true",
        ],
        0,
    );
    case(
        &format!("{C}{}", refused("c.run(-1.0)")),
        &["a continuum runs for 0 s or more", "unchanged: true"],
        0,
    );
    for tol in ["1e-300", "0.0", "1.0", "0.0 / 0.0"] {
        case(
            &format!("{C}continuum(b, #{{ grid: 4, orientations: 2, tol: {tol} }});"),
            &["a continuum's tolerance must"],
            1,
        );
    }
    case(
        &format!("{C}continuum(b, #{{ grid: 4, orientations: 2, tol: 1e-300 }});"),
        &[
            "a continuum's tolerance must lie in [1e-10, 1) (below 1e-10",
            "got 1e-300",
        ],
        1,
    );
    // The least tolerance runs.
    case(
        &format!("{C}let d = continuum(b, #{{ grid: 4, orientations: 2, tol: 1e-10 }});\nd.run_periods(1);\nprint(d.time > 0.0);"),
        &["true"],
        0,
    );
}

/// A core the kernel cannot describe is refused with its range and why; the least core builds
/// and runs at once (the kernel's radial panels no longer follow the core down).
#[test]
fn the_core_is_refused_outside_its_range_and_cheap_within() {
    for core in [
        "1e-12",
        "1e-9",
        "1.2e-6",
        "60e-6",
        "1.0",
        "0.0 / 0.0",
        "-1e-6",
    ] {
        case(
            &format!("{C}continuum(b, #{{ grid: 4, orientations: 2, core: {core} }});"),
            &[
                "a continuum's core must lie from 0.25 swimmer lengths, 1.25e-6 m, up to the cutoff 5.71e-5 m",
                "leave it out for one length ℓ, 5e-6 m",
            ],
            1,
        );
    }
    case(
        &format!("{C}let d = continuum(b, #{{ grid: 8, orientations: 2, core: 1.25e-6 }});\nd.run_periods(1);\n{COUNTS_ONE}"),
        &["[true, true]"],
        0,
    );
}

/// A smoothing width the grid cannot hold (narrower than a quarter of a cell) or wider than the
/// box's half is refused with both ends, not turned into NaN counts.
#[test]
fn the_width_is_checked_against_the_grid_and_the_box() {
    for width in ["1e-30", "7e-6", "61e-6", "1e30", "0.0 / 0.0"] {
        case(
            &format!("{C}continuum(b, #{{ grid: 4, orientations: 2, width: {width} }});"),
            &[
                "a continuum's smoothing width must lie from a quarter of its largest cell side, 7.5e-6 m",
                "to half the box's longest side, 6e-5 m",
                "leave it out for one cell, 3e-5 m",
            ],
            1,
        );
    }
    case(
        &format!("{C}let d = continuum(b, #{{ grid: 4, orientations: 2, width: 7.5e-6 }});\n{COUNTS_ONE}"),
        &["[true, true]"],
        0,
    );
}

/// A perturbation keeps f ≥ 0 (its bound stated) and finite; a refused one leaves the state.
#[test]
fn a_perturbation_keeps_the_distribution_a_distribution() {
    for amplitude in ["1e308", "2.0", "-1.5"] {
        case(
            &format!(
                "{C}{}",
                refused(&format!("c.perturb(#{{ amplitude: {amplitude} }})"))
            ),
            &[
                "a density wave of relative amplitude",
                "would make the distribution negative",
                "within ±1.000000 so that f ≥ 0 everywhere",
                "unchanged: true",
            ],
            0,
        );
    }
    case(
        &format!(
            "{C}{}",
            refused("c.perturb(#{ shape: \"nematic\", axis: [0, 0, 1], amplitude: 0.21 })")
        ),
        &["a nematic wave", "within ±0.200000", "unchanged: true"],
        0,
    );
    case(
        &format!(
            "{C}{}",
            refused("c.perturb(#{ shape: \"polarization\", axis: [1, 0, 0], amplitude: 0.34 })")
        ),
        &["within ±0.333333", "unchanged: true"],
        0,
    );
    case(
        &format!(
            "{C}{}",
            refused("c.perturb(#{ state: \"polar\", polarization: [0, 0, 0.3], amplitude: 0.11 })")
        ),
        &["within ±0.100000", "unchanged: true"],
        0,
    );
    // At the bounds: accepted, the density stays positive and the counts conserved.
    case(
        &format!("{C}let d = c;\nd.perturb(#{{ shape: \"nematic\", axis: [0, 0, 1], amplitude: 0.2 }});\nd.perturb(#{{ shape: \"polarization\", amplitude: 1.0 / 3.0 }});\nd.perturb(#{{ amplitude: 1.0 }});\nprint(d.field(\"density\").stat(\"min\") >= 0.0);\n{COUNTS_ONE}"),
        &["true\n[true, true]"],
        0,
    );
}

/// Mode [0, 0, 0] is the mean, not a wave: a perturbation there would change the conserved
/// numbers (20 + 20 swimmers became 30 + 30), and is refused with the fix.
#[test]
fn a_perturbation_at_mode_zero_is_refused() {
    case(
        &format!(
            "{C}{}",
            refused("c.perturb(#{ mode: [0, 0, 0], amplitude: 0.5 })")
        ),
        &[
            "box mode [0, 0, 0] is no wave but the mean",
            "which the dynamics conserves",
            "e.g. [1, 0, 0]",
            "unchanged: true",
        ],
        0,
    );
}

/// A continuum's modes are those its grid keeps (at the cells, [4, 0, 0] on 4 cells is the mean's
/// alias); a scene's are those whose phase f64 resolves.
#[test]
fn modes_are_the_ones_the_grid_or_f64_resolve() {
    for mode in [
        "[4, 0, 0]",
        "[100, 0, 0]",
        "[0, -2, 0]",
        "[9223372036854775807, 0, 0]",
    ] {
        case(
            &format!("{C}c.mode(\"density\", {mode});"),
            &[
                "is beyond what this continuum's grid [4, 4, 4] holds",
                "keeps |n| up to [1, 1, 1] per axis",
            ],
            1,
        );
    }
    case(
        &format!(
            "{C}{}",
            refused("c.perturb(#{ mode: [100, 0, 0], amplitude: 0.5 })")
        ),
        &[
            "beyond what this continuum's grid [4, 4, 4] holds",
            "unchanged: true",
        ],
        0,
    );
    // The largest kept mode reads and perturbs.
    case(
        &format!("{C}c.perturb(#{{ mode: [1, -1, 1], amplitude: 0.5 }});\nprint(c.mode(\"density\", [1, -1, 1]).abs > 0.0);"),
        &["true"],
        0,
    );
    for mode in ["[9223372036854775807, 0, 0]", "[0, 0, -1000000001]"] {
        case(
            &format!("{C}b.mode(\"density\", {mode});"),
            &["is beyond what f64 resolves", "modes go up to 1e9 per axis"],
            1,
        );
    }
    case(
        &format!("{C}print(b.mode(\"density\", [1000000000, 0, 0]).abs <= 2.0);"),
        &["true"],
        0,
    );
}

/// A population that does not exist is refused, naming how many there are, before anything
/// changes.
#[test]
fn a_perturbation_of_a_population_that_does_not_exist_is_refused() {
    case(
        &format!(
            "{C}c.perturb(#{{ amplitude: 0.5 }});\n{}",
            refused("c.perturb(#{ amplitude: 0.1, population: 5 })")
        ),
        &[
            "population 5 does not exist: this continuum has 2 (0 to 1)",
            "unchanged: true",
        ],
        0,
    );
    case(
        &format!("{C}c.perturb(#{{ population: -1 }});"),
        &["a population index is a whole number from 0", "got -1"],
        1,
    );
}

/// A phase given to `s.mode` is a number one of the swimmers has; otherwise the phases present
/// are named.
#[test]
fn a_mode_over_one_phase_names_the_phases_present() {
    case(
        &format!("{C}b.mode(\"density\", [1, 0, 0], #{{ phase: 0.0 / 0.0 }});"),
        &["a phase must be a finite number in rad, got NaN"],
        1,
    );
    case(
        &format!("{C}b.mode(\"density\", [1, 0, 0], #{{ phase: 2.0 }});"),
        &[
            "no swimmer has phase 2 rad",
            "the phases present are 0, 1 rad",
        ],
        1,
    );
    // A phase one 2π turn away is the same phase.
    case(
        &format!("{C}print(b.mode(\"density\", [0, 0, 0], #{{ phase: 1.0 + 2.0 * pi() }}).abs);"),
        &["1.0"],
        0,
    );
}

/// Each option's message states the range it accepts and what was given.
#[test]
fn continuum_options_state_their_ranges() {
    let prefix = &C[..C.find("let c").unwrap()];
    for (opts, fragments) in [
        (
            "grid: -1",
            &[
                "continuum grid takes 4 or more cells per axis and at most 32768 cells in all",
                "got -1",
            ][..],
        ),
        (
            "grid: [4, 4, -3]",
            &["continuum grid[2] takes 4 or more cells", "got -3"],
        ),
        (
            "grid: [4, 4, 3]",
            &["a continuum's grid takes 4 or more cells", "got [4, 4, 3]"],
        ),
        (
            "grid: 9223372036854775807",
            &[
                "a continuum's grid takes 4 or more cells",
                "got [9223372036854775807",
            ],
        ),
        (
            "grid: 33",
            &["at most 32768 cells in all", "got [33, 33, 33]"],
        ),
        (
            "orientations: 2.5",
            &[
                "continuum orientations takes a harmonic degree from 2",
                "to 8",
                "got 2.5",
            ],
        ),
        (
            "orientations: 1",
            &["orientations take a harmonic degree from 2", "got 1"],
        ),
        ("orientations: 9", &["to 8 (e.g. 4), got 9"]),
        ("phases: 0", &["phases take 1 to 16 phase bins, got 0"]),
        (
            "phases: -2",
            &["continuum phases takes 1 to 16 phase bins, got -2"],
        ),
    ] {
        case(
            &format!("{prefix}continuum(b, #{{ {opts} }});"),
            fragments,
            1,
        );
    }
}

/// A continuum a sweep's calls share is read by them, not changed: a change is swimlab's refusal
/// naming the fix (a copy), never Rhai's "Data race detected"; a copy runs in each call.
#[test]
fn a_continuum_shared_by_a_sweep_is_read_not_changed() {
    for change in ["c.run_periods(0.01)", "c.perturb(#{ amplitude: 0.1 })"] {
        case(
            &format!("{C}let r = sweep([1, 2, 3, 4, 5, 6, 7, 8], |p| {{ {change}; c.time }});"),
            &[
                "this continuum is shared by every call of the sweep",
                "change a copy there (let d = c.copy(); d.run_periods(1); ...)",
            ],
            1,
        );
    }
    case(
        &format!("{C}c.perturb(#{{ amplitude: 0.5 }});\nlet r = sweep([1, 2, 3, 4], |p| {{ let d = c.copy(); d.run_periods(0.01 * p); [d.time > 0.0, c.time, d.counts()[0] > 0.99, c.mode(\"density\", [1, 0, 0]).abs > 0.0] }});\nprint(r);\nprint(c.time);"),
        &["[true, 0.0, true, true]", "\n0.0\n"],
        0,
    );
    // Long readings at once (draws of 20,000 swimmers, ~0.5 s each) wait for the continuum's own
    // lock; Rhai's lock on the captured variable gave up after a few milliseconds ("Data race").
    case(
        "let side = 400e-6;\nlet s = scene();\ns.model = \"averaged\";\ns.box = [side, side, side];\ns.add_random(dumbbell(), 40, 1, #{ phase: 0.0 });\ns.add_random(dumbbell(), 40, 2, #{ phase: pi() / 2.0 });\nlet c = continuum(s, #{ grid: 16, orientations: 4 });\nc.perturb(#{ amplitude: 0.5 });\nprint(sweep([1, 2, 3, 4], |seed| { let t = scene(); t.model = \"averaged\"; t.box = [side, side, side]; c.sample(t, 20000, seed); t.count }));",
        &["[20000, 20000, 20000, 20000]"],
        0,
    );
    // Given in more than one parameter, it is shared as well.
    case(
        &format!("{C}let r = sweep([c, c], |d| {{ d.run_periods(0.01); 1 }});"),
        &["this continuum is shared by every call of the sweep"],
        1,
    );
}

/// ∫ D^{2−m} S(D) j_l(kD) dD from `core` to `cutoff` for l = 0..=6, m = 3, 4, 5 by Simpson's rule,
/// a reference independent of the kernel's panels: in u = ln D below 1 µm (the integrand's D^{−3}
/// then smooth in u), in D above (where j_l(kD) oscillates), split at the switch's start.
fn radial_reference(core: f64, cutoff: f64, k: f64) -> [[f64; 7]; 3] {
    use swimlab::engine::averaged::CUTOFF_SWITCH_WIDTH;
    use swimlab::engine::continuum::kernel::spherical_bessel;
    // The particle runs' switch: 1 − x⁴(35 − 84x + 70x² − 20x³) over the cutoff's last tenth.
    let inner = (1.0 - CUTOFF_SWITCH_WIDTH) * cutoff;
    let switch = |d: f64| {
        let x = ((d - inner) / (CUTOFF_SWITCH_WIDTH * cutoff)).clamp(0.0, 1.0);
        1.0 - x.powi(4) * (35.0 - 84.0 * x + 70.0 * x * x - 20.0 * x.powi(3))
    };
    let low = core.max(1e-6);
    let mut r = [[0.0; 7]; 3];
    for (a, b, log) in [
        (core, low, true),
        (low, inner, false),
        (inner, cutoff, false),
    ] {
        if b <= a {
            continue;
        }
        let (ua, ub) = if log { (a.ln(), b.ln()) } else { (a, b) };
        let n = 60_000;
        let h = (ub - ua) / n as f64;
        for i in 0..=n {
            let simpson = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let u = ua + i as f64 * h;
            let (d, jacobian) = if log { (u.exp(), u.exp()) } else { (u, 1.0) };
            let j = spherical_bessel(k * d);
            for (m, row) in r.iter_mut().enumerate() {
                let f = simpson * h / 3.0 * jacobian * d.powi(-1 - m as i32) * switch(d);
                for l in 0..7 {
                    row[l] += f * j[l];
                }
            }
        }
    }
    r
}

/// The kernel's radial quadrature is graded to the core: panels no wider than a quarter of their
/// distance nor than 1/k_max, so a core far below the cutoff costs some log(cutoff/core) panels
/// (a core of 1e-12 m once took 11 GB and never returned; at 1e-9 m, 2e5 panels). Its integrals
/// match an independent Simpson rule to 1e-9 of the largest at each m (the reference's own error,
/// h⁴ with 6e4 intervals a piece, is some 1e-12).
#[test]
fn the_radial_quadrature_is_graded_to_the_core() {
    use swimlab::engine::continuum::kernel::Radial;
    let (ell, cutoff) = (5e-6, 60e-6);
    for core in [0.25 * ell, 1e-9, 1e-12] {
        for k_max in [1e5, 1e6] {
            let radial = Radial::new(core, cutoff, k_max);
            let panels = radial.nodes() / 8;
            // log_1.25(4/(k_max core)) graded panels, then k_max·cutoff equal ones, and the split.
            let bound = ((4.0 / (k_max * core)).max(1.0).ln() / 1.25f64.ln() + k_max * cutoff + 3.0)
                .ceil() as usize;
            assert!(
                panels <= bound,
                "core {core:e}, k_max {k_max:e}: {panels} panels, more than {bound}"
            );
            if k_max < 1e6 {
                continue;
            }
            for k in [0.0, k_max] {
                let got = radial.integrals(k);
                let want = radial_reference(core, cutoff, k);
                for m in 0..3 {
                    let scale = want[m].iter().fold(0.0f64, |a, x| a.max(x.abs()));
                    for l in 0..7 {
                        assert!(
                            (got[m][l] - want[m][l]).abs() <= 1e-9 * scale,
                            "core {core:e}, k {k:e}, m {}, l {l}: {} vs {}",
                            m + 3,
                            got[m][l],
                            want[m][l]
                        );
                    }
                }
            }
        }
    }
}

/// A closure is refused unless it is a map of diffusion coefficients and says where it was
/// fitted; a good one is shown with the continuum.
#[test]
fn a_closure_is_checked_and_shown() {
    let tries = [
        "continuum(b, #{ closure: 3 })",
        "continuum(b, #{ closure: #{ rotation: -1, fitted: \"x\" } })",
        "continuum(b, #{ closure: #{ rotation: 0.1 } })",
        "continuum(b, #{ closure: #{ rot: 0.1, fitted: \"x\" } })",
        "continuum(b, #{ closure: #{ translation: \"big\", fitted: \"x\" } })",
        "continuum(b, #{ closure: #{ rotation: 0.1, fitted: 2 } })",
    ]
    .map(|t| format!("try {{ {t}; print(\"accepted\"); }} catch (e) {{ print(e); }}\n"))
    .concat();
    let out = case(
        &format!(
            "{C}{tries}print(continuum(b, #{{ grid: 4, orientations: 2, closure: #{{ rotation: 0.02, translation: 1e-13, fitted: \"here\" }} }}));\n"
        ),
        &[
            "continuum closure must be a map, got 3",
            "the closure's rotation must be a diffusion coefficient of zero or more (1/s), got -1",
            "a closure says where it was fitted",
            "continuum closure: unknown key \"rot\"",
            "continuum closure translation must be a number",
            "continuum closure fitted must be a string",
            "closure D_r 2.0000e-2 1/s and D_t 1.0000e-13 m²/s (fitted: here)",
        ],
        0,
    );
    assert!(!out.contains("accepted"), "{out}");
}
