//! Boxes, noise, fields, stroboscopic averaging and `auto`, trajectories, pictures and sweeps
//! tried as a hostile new user would: wrong types named in words, limits, one writer per file,
//! paths that cannot be written, placements that cannot be carried; nothing lost, nothing hangs.
//! Each case runs in its own `swimlab` process under a time limit, so a hang or an abort fails
//! the test instead of stalling it, and a panic shows as the "internal error" the script boundary
//! turns it into.

use crate::common::cli::{case, case_dir, run_in, text};
use std::time::{Duration, Instant};

const PAIR: &str = "let s = scene();\ns.add(dumbbell(#{ center: [-25e-6, 0, 0] }));\ns.add(dumbbell(#{ center: [25e-6, 0, 0], phase: 1.0 }));\n";

/// Every swimlab type given where another is wanted is named in script words, and `display`
/// shows every swimlab value as `print` does.
#[test]
fn script_types_are_named_in_words() {
    case(
        &format!("{PAIR}s.temperature = euler(1e-6);"),
        &["temperature must be a number, got euler(1e-6) (Integrator)"],
        1,
    );
    case(
        &format!("{PAIR}s.record([R_H(0)], s.field(\"density\"));"),
        &["got Field(density", "(Field)"],
        1,
    );
    case(
        &format!("{PAIR}s.add(every_periods(1));"),
        &["(Trigger)"],
        1,
    );
    case(
        &format!("{PAIR}s.run(s);"),
        &["got Scene(2 swimmers", "(Scene)"],
        1,
    );
    case(
        &format!("{PAIR}let r = s.record([R_H(0)], 1);\ns.phases = r;"),
        &["(Recorder)"],
        1,
    );
    case(
        &format!("{PAIR}R_H(s);"),
        &["R_H cannot be called as R_H(Scene)"],
        1,
    );
    case(
        &format!("{PAIR}s.mu = plot(#{{ x: [1, 2], y: [1, 2] }});"),
        &["(Picture)"],
        1,
    );
    let shown = case(
        &format!(
            "{PAIR}let f = s.field(\"density\");\ndisplay(f);\nprint(f);\ndisplay(euler(1e-6));\ndisplay(R_H(0));\ndisplay(every_periods(2));\ndisplay(dumbbell());"
        ),
        &[],
        0,
    );
    let lines: Vec<&str> = shown.lines().collect();
    assert!(lines[0].starts_with("Field(density, grid"), "{shown}");
    // The pair's density integrates to its two swimmers (to the kernel's truncation).
    assert!(lines[0].ends_with("integral 2.0000)"), "{shown}");
    assert_eq!(lines[0], lines[1], "display and print agree: {shown}");
    assert!(
        lines[2].starts_with("euler(") && lines[4].contains("every 2 periods"),
        "{shown}"
    );
}

/// Wrong types into stdlib functions and operators name the operand types and the fix.
#[test]
fn stdlib_and_operators_name_wrong_types() {
    case(
        "import \"lattice\" as lattice;\nlet s = scene();\ns.box = [1e-4, 1e-4, 1e-4];\nlattice::fill(s.box, \"2\", 2, 2);",
        &["nx must be a whole number of points >= 1", "got \"2\" (a string)"],
        1,
    );
    case(
        "import \"lattice\" as lattice;\nlattice::cubic(2, 2, 2, \"1e-5\");",
        &["spacing must be a positive length in m"],
        1,
    );
    let t = case(
        "import \"phases\" as phases;\nlet s = scene();\ns.add(dumbbell());\ntry { phases::random(\"x\", 1); } catch (e) { print(e); }\ntry { phases::random(2, 0.5); } catch (e) { print(e); }\ntry { phases::alternating(2.0, 1); } catch (e) { print(e); }\ntry { phases::alternating(2, \"x\"); } catch (e) { print(e); }\ntry { phases::wave(s, [0, 0, 0], 1e-4); } catch (e) { print(e); }\ntry { phases::wave(s, [1, 0], 1e-4); } catch (e) { print(e); }\ntry { phases::wave(s, [1, 0, 0], 0.0 / 0.0); } catch (e) { print(e); }\nprint(phases::alternating(3, 1));",
        &[
            "phases::random: n must be a whole number of swimmers >= 0, such as s.count; got \"x\" (a string)",
            "phases::random: seed must be a whole number, such as 42; got 0.5 (a float)",
            "phases::alternating: n must be a whole number of swimmers >= 0, such as s.count; got 2.0 (a float)",
            "phases::alternating: dphi must be a finite number, such as pi() / 2.0; got \"x\" (a string)",
            "phases::wave: axis must not be [0, 0, 0]",
            "phases::wave: axis must be a direction [x, y, z], such as [1, 0, 0]; got [1, 0] (array)",
            "phases::wave: wavelength must be a finite number, such as 100e-6; got NaN (a float)",
            "[0.0, 1.0, 2.0]",
        ],
        0,
    );
    assert!(!t.contains("uniform_randoms"), "{t}");
    let t = case(
        "let x = 1.0 / \"2\";",
        &["the operator / cannot be applied to float and string"],
        1,
    );
    assert!(!t.contains("did you mean"), "{t}");
}

/// `param` refuses a name that no `--set` can give.
#[test]
fn param_refuses_names_no_set_can_give() {
    case(
        "param(\"\", 1e-6);",
        &["param(\"\", ...): the name must be a variable name"],
        1,
    );
    case("param(\"a b\", 1);", &["must be a variable name"], 1);
    case("print(param(\"D\", 2.5));", &["2.5"], 0);
}

/// One check of a run's end for every integrator: a run past 1e9 stroke periods, which a saved
/// scene could not be loaded at, is refused with the numbers before it starts, by stroboscopic
/// averaging and `auto` as by the direct methods, in open space and in a box; a scene run right
/// up to it saves and loads.
#[test]
fn no_integrator_runs_past_the_latest_time() {
    for integrator in [
        "stroboscopic(1e-2)",
        "auto(1e-3)",
        "dopri5(1e-6)",
        "rk4(1e-6)",
    ] {
        for place in ["", "s.box = [120e-6, 120e-6, 120e-6];\n"] {
            case(
                &format!("{PAIR}{place}s.integrator = {integrator};\ns.run_periods(9223372036854775807);"),
                &["past the latest time a scene may hold", "1e9 stroke periods", "run at most"],
                1,
            );
        }
    }
    case(
        &format!("{PAIR}s.integrator = stroboscopic(1e-2);\ns.run_periods(2e9);"),
        &["this run would end at t = 2.513274e7 s (2.000000e9 periods)"],
        1,
    );
    case(
        "let s = scene();\ns.add(dumbbell());\ns.integrator = auto(1e-3);\ns.run_periods(1e9);\ns.save(\"at_the_end.json\");\nlet t = load_scene(\"at_the_end.json\");\nprint(t.time / t.period);\ntry { t.run_periods(1); } catch (e) { print(e); }",
        &["1000000000", "past the latest time"],
        0,
    );
}

/// A run whose cost will be far beyond what its length suggests says so when it starts: spectral
/// Ewald sums on a few spheres (an FFT grid per product whatever their number).
#[test]
fn a_costly_ewald_method_says_so_when_the_run_starts() {
    let scene = "let s = scene();\ns.box = [120e-6, 120e-6, 120e-6];\ns.add(dumbbell(#{ center: [-30e-6, 0, 0] }));\ns.add(dumbbell(#{ phase: 1.0 }));\ns.add(dumbbell(#{ center: [30e-6, 0, 0], phase: 2.0 }));\n";
    let t = case(
        &format!("{scene}s.ewald_method = \"spectral\";\ns.run(1e-6);\ns.run(1e-6);"),
        &[
            "note: this run will cost far more than its length suggests",
            "with 6 spheres",
            "s.ewald_method = \"auto\"",
        ],
        0,
    );
    assert_eq!(t.matches("note:").count(), 2, "once a run: {t}");
    let t = case(&format!("{scene}s.run(1e-6);"), &[], 0);
    assert!(!t.contains("note:"), "{t}");
}

/// Two trajectories on one path: the second is refused (the first keeps writing whole frames
/// that ASE and OVITO read), and so is a whole-file write onto a trajectory's file (a CSV stream
/// cannot reach one: CSV under a trajectory's name is refused first); two streams on one CSV
/// file, and a whole-file write onto a stream's file, are refused the same way.
#[test]
fn one_writer_per_file() {
    let d = case_dir();
    let out = run_in(
        &format!("{PAIR}s.trajectory(\"out/t.xyz\", 0.5);\ntry {{ s.trajectory(\"out/t.xyz\", 0.25); }} catch (e) {{ print(e); }}\nlet u = s.copy();\ntry {{ u.trajectory(\"out/../out/t.xyz\", 0.5); }} catch (e) {{ print(e); }}\nlet r = u.record([R_H(0)], 1);\ntry {{ r.stream_csv(\"out/t.xyz\"); }} catch (e) {{ print(e); }}\ntry {{ s.save(\"out/t.xyz\"); }} catch (e) {{ print(e); }}\nr.stream_csv(\"out/r.csv\");\nlet q = s.record([R_H(0)], 1);\ntry {{ q.stream_csv(\"out/r.csv\"); }} catch (e) {{ print(e); }}\ntry {{ q.to_csv(\"out/r.csv\"); }} catch (e) {{ print(e); }}\ns.run_periods(1);"),
        &d,
    );
    let t = text(&out);
    assert_eq!(out.status.code(), Some(0), "{t}");
    let refused = |start: &str, holder: &str| {
        t.lines()
            .filter(|l| {
                l.starts_with(start) && l.contains(&format!("is being written by {holder}"))
            })
            .count()
    };
    // The second trajectory and the save; the same file by another spelling.
    assert_eq!(refused("out/t.xyz ", "a trajectory"), 2, "{t}");
    assert_eq!(refused("out/../out/t.xyz ", "a trajectory"), 1, "{t}");
    assert!(t.contains("stream_csv: out/t.xyz ends in .xyz"), "{t}");
    // The second stream and the whole-file write.
    assert_eq!(refused("out/r.csv ", "a recorder's CSV stream"), 2, "{t}");
    let xyz = std::fs::read_to_string(d.join("out/t.xyz")).unwrap();
    let lines: Vec<&str> = xyz.lines().collect();
    assert_eq!(lines.len(), 3 * 6, "three frames of 4 spheres: {xyz}");
    for f in 0..3 {
        assert_eq!(lines[6 * f], "4", "{xyz}");
        assert!(lines[6 * f + 1].contains("Properties="), "{xyz}");
    }
}

/// A box or a position that wrapping cannot carry is refused with the reach positions may have
/// (1e8 sphere radii), and the scene is unchanged; an elongated box the Ewald sums cannot take is
/// refused at the run with settings that exist.
#[test]
fn boxes_and_positions_that_wrapping_cannot_carry_are_refused() {
    let t = case(
        &format!("{PAIR}s.box = [1e-4, 1e-4, 1e-4];\ntry {{ s.add_at(dumbbell(), [[1e308, 0, 0]]); }} catch (e) {{ print(e); }}\nprint(s.count);\nprint(s.observe(min_gap()));"),
        &["beyond the 75 m from the origin that positions may reach", "1e8 times the smallest sphere radius"],
        0,
    );
    let lines: Vec<&str> = t.lines().collect();
    assert_eq!(lines[1], "2", "{t}");
    assert!(lines[2].parse::<f64>().unwrap() > 0.0, "{t}");
    let t = case(
        &format!("{PAIR}try {{ s.box = [1e308, 1e-4, 1e-4]; }} catch (e) {{ print(e); }}\nprint(type_of(s.box));"),
        &["the box side along x, 1e308 m, is longer than the 75 m"],
        0,
    );
    assert!(t.trim_end().ends_with("()"), "still no box: {t}");
    case(
        "let s = scene();\ns.box = [1e200, 1e200, 1e-4];",
        &["a volume f64 cannot hold"],
        1,
    );
    case(
        "let s = scene();\ns.box = [1e308, 1e-4, 1e-4];\ns.add(dumbbell());",
        &["the box side along x, 1e308 m"],
        1,
    );
    case(
        "let s = scene();\ns.add(dumbbell(#{ center: [1e20, 0, 0] }));",
        &["a swimmer's centre at x = 1e20 m"],
        1,
    );
    let t = case(
        "let s = scene();\ns.add(dumbbell());\ns.box = [70, 1e-4, 1e-4];\ns.run_periods(0.01);",
        &["the box is too elongated", "s.model = \"averaged\""],
        1,
    );
    assert!(!t.contains("splitting"), "{t}");
}

/// A scene every call of a sweep reaches (captured by the closure, or in two parameters) may be
/// read by the calls, not changed: changed from several threads at once, its results changed from
/// run to run. Reading it, copying it and running the copies, and scenes of their own are fine,
/// and the same every time.
#[test]
fn sweeps_do_not_race_on_a_shared_scene() {
    let t = case(
        &format!("{PAIR}sweep([1, 2, 3, 4], |p| {{ s.run_periods(0.01); s.time }}, 4);"),
        &[
            "sweep: the call for parameter 0 (1) failed: in the closure: this scene is shared by every call of the sweep",
            "let t = s.copy()",
        ],
        1,
    );
    assert!(!t.contains("anon$") && !t.contains("Runtime error"), "{t}");
    case(
        &format!("{PAIR}sweep([s, s], |x| {{ x.mu = 2e-3; }});"),
        &["shared by every call of the sweep"],
        1,
    );
    case(
        &format!("{PAIR}let r = s.record([R_H(0)], 1);\nsweep([1, 2], |p| {{ r.stream_csv(`r${{p}}.csv`); }});"),
        &["shared by every call of the sweep"],
        1,
    );
    let script = format!(
        "{PAIR}print(sweep([1, 2, 3, 4], |p| {{ let t = s.copy(); t.run_periods(0.01 * p); t.time / t.period }}, 4));\nprint(sweep([1, 2], |p| s.observe(R_H(p - 1))[0]));\nlet a = s.copy();\nlet b = s.copy();\nprint(sweep([a, b], |x| {{ x.run_periods(0.01); x.count }}));\ns.run_periods(0.01);\nprint(s.time > 0.0);"
    );
    let first = case(&script, &[], 0);
    let lines: Vec<&str> = first.lines().collect();
    let periods: Vec<f64> = lines[0]
        .trim_matches(|c| c == '[' || c == ']')
        .split(", ")
        .map(|x| x.parse().unwrap())
        .collect();
    // Each copy ran 0.01 p periods from time 0 (to rounding of the period's multiples).
    for (k, p) in periods.iter().enumerate() {
        assert!((p - 0.01 * (k + 1) as f64).abs() < 1e-12, "{first}");
    }
    assert_eq!(lines[1], "[-2.5e-5, 2.5e-5]", "{first}");
    assert_eq!(lines[2], "[2, 2]", "{first}");
    assert_eq!(
        lines[3], "true",
        "the scene is free again after the sweep: {first}"
    );
    assert_eq!(case(&script, &[], 0), first, "the same every time");
}

/// Pictures, animations and fields written where no file can be made get the message every file
/// writer gives: the path, the cause and the fix, never the drawing library's debug text.
#[test]
fn pictures_name_the_path_they_cannot_write() {
    for (call, path) in [
        (
            "plot(\"/proc/x.png\", #{ x: [1, 2], y: [1, 2] });",
            "/proc/x.png",
        ),
        (
            "plot(\"/proc/x.svg\", #{ x: [1, 2], y: [1, 2] });",
            "/proc/x.svg",
        ),
        ("s.snapshot(\"/proc/x.png\");", "/proc/x.png"),
        (
            "s.animate(\"/proc/x.gif\", #{ frames: 2, periods: 0.1 });",
            "/proc/x.gif",
        ),
        ("s.field(\"density\").plot(\"/proc/x.png\");", "/proc/x.png"),
        (
            "plot(#{ x: [1, 2], y: [1, 2] }).save(\"/proc/x.png\");",
            "/proc/x.png",
        ),
    ] {
        case(
            &format!("{PAIR}{call}"),
            &[
                &format!("cannot write {path}: No such file or directory"),
                "check that the folder is writable",
            ],
            1,
        );
    }
    let d = case_dir();
    let out = run_in(
        &format!("{PAIR}print(s.animate(\"a.gif\", #{{ frames: 3, periods: 0.1 }}));"),
        &d,
    );
    assert!(out.status.success(), "{}", text(&out));
    let decoder = gif::DecodeOptions::new();
    let mut r = decoder
        .read_info(std::fs::File::open(d.join("a.gif")).unwrap())
        .unwrap();
    let mut frames = 0;
    while r.read_next_frame().unwrap().is_some() {
        frames += 1;
    }
    assert_eq!(frames, 4, "the snapshot now and after each of 3 slices");
}

/// The smaller items: a trajectory's row limit names the trajectory; CSV is not written under
/// the name of another format (refused: a `.png` holding CSV opens in no picture viewer).
#[test]
fn row_limits_name_the_trajectory_and_csv_keeps_to_csv_names() {
    let t = case(
        &format!("{PAIR}s.trajectory(\"out/t.xyz\", every_seconds(1e-9));\ns.run_periods(1);"),
        &["rows to the trajectory out/t.xyz (every 1e-9 s)"],
        1,
    );
    assert!(!t.contains("recorder of  ("), "{t}");
    case(
        &format!("{PAIR}let r = s.record([], every_seconds(1e-12));\ns.run_periods(10);"),
        &["rows to the recorder of times only"],
        1,
    );
    for (call, ext) in [
        ("r.to_csv(\"out/r.png\")", "png"),
        ("r.stream_csv(\"out/r.gif\")", "gif"),
        ("r.to_csv(\"out/r.VTI\")", "vti"),
        ("write_csv(\"out/r.svg\", [#{ a: 1 }])", "svg"),
    ] {
        case(
            &format!("{PAIR}let r = s.record([R_H(0)], 1);\n{call};"),
            &[&format!("ends in .{ext}"), "give a name ending in .csv"],
            1,
        );
    }
    let d = case_dir();
    let out = run_in(
        &format!("{PAIR}let r = s.record([R_H(0)], 1);\nr.to_csv(\"r.csv\");\nr.to_csv(\"r.txt\");\nwrite_csv(\"w.dat\", [#{{ a: 1 }}]);"),
        &d,
    );
    assert!(out.status.success(), "{}", text(&out));
    for f in ["r.csv", "r.txt", "w.dat"] {
        assert!(d.join(f).is_file(), "{f}");
    }
}

/// A lattice is added in time that follows its size: `add_at` finds overlaps through cell lists
/// and the stdlib sets its points by index (measuring every pair, or walking the whole array for
/// the size check at every `push`, is O(n²)); an array past the limits is refused before it is
/// built.
#[test]
fn a_large_lattice_is_added_in_time_that_follows_its_size() {
    // 100,000 swimmers take about a second in an optimised build, where the O(n²) ways take
    // minutes; the bound leaves room for debug assertions and a loaded machine.
    let started = Instant::now();
    case(
        "import \"lattice\" as lattice;\nlet s = scene();\nprint(s.add_at(dumbbell(), lattice::cubic(50, 50, 40, 20e-6)));\nimport \"phases\" as phases;\ns.phases = phases::alternating(s.count, 0.5);\nprint(s.phases.len());",
        &["100000\n100000"],
        0,
    );
    assert!(
        started.elapsed() < Duration::from_secs(30),
        "{:?}",
        started.elapsed()
    );
    case(
        "import \"lattice\" as lattice;\nlattice::cubic(200, 200, 200, 20e-6);",
        &[
            "limit of 20000000 elements in one array",
            "SWIMLAB_MAX_ARRAY",
        ],
        1,
    );
    case(
        "import \"lattice\" as lattice;\nlattice::hexagonal(2000000000, 2000000000, 1e-6);",
        &["lattice: 2000000000 x 2000000000 = 4e18 points, more than any array holds"],
        1,
    );
}

/// `Scene::add_many` (what `add_at` calls) makes the checks of one `add` after another, with the
/// same first failure and, when all fit, the same scene; a failure leaves the scene unchanged.
#[test]
fn adding_many_checks_as_one_add_after_another() {
    use swimlab::engine::swimmer::Dumbbell;
    use swimlab::engine::{Model, Scene};
    /// SplitMix64 in [0, 1).
    struct Rng(u64);
    impl Rng {
        fn uniform(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        }
    }
    type Outcome = Result<(), (usize, String)>;
    let mut rng = Rng(38);
    let (mut refused, mut overlapping) = (0, 0);
    for case in 0..120 {
        let mut scene = Scene::new();
        if case % 3 == 1 {
            scene.set_model(Model::Averaged);
        }
        let side = 20e-6 + 180e-6 * rng.uniform();
        if case % 2 == 0 {
            scene
                .set_box(Some([side, side * (0.5 + rng.uniform()), side]))
                .unwrap();
        }
        let small = Dumbbell {
            a2: 0.4e-6,
            ..Dumbbell::default()
        };
        let point = |rng: &mut Rng| {
            nalgebra::Vector3::new(
                side * (2.0 * rng.uniform() - 1.0),
                side * (2.0 * rng.uniform() - 1.0),
                side * (2.0 * rng.uniform() - 1.0),
            )
        };
        // A few swimmers there already.
        for _ in 0..3 {
            let _ = scene.add(Dumbbell::default(), point(&mut rng), point(&mut rng));
        }
        let items: Vec<_> = (0..200)
            .map(|k| {
                let d = if k % 5 == 0 {
                    small
                } else {
                    Dumbbell::default()
                };
                let mut c = point(&mut rng);
                let mut dir = point(&mut rng);
                match (rng.uniform() * 400.0) as u32 {
                    0 => c.x = f64::NAN,
                    1 => dir = nalgebra::Vector3::zeros(),
                    2 => c.y = 1e20,
                    _ => {}
                }
                (d, c, dir)
            })
            .collect();
        let mut one_by_one = scene.clone();
        let mut expected: Outcome = Ok(());
        for (k, (d, c, dir)) in items.iter().enumerate() {
            if let Err(e) = one_by_one.add(*d, *c, *dir) {
                expected = Err((k, e.to_string()));
                break;
            }
        }
        let mut at_once = scene.clone();
        let got: Outcome = at_once
            .add_many(&items)
            .map_err(|(k, e)| (k, e.to_string()));
        assert_eq!(got, expected, "case {case}");
        match got {
            Ok(()) => {
                assert_eq!(at_once.count(), one_by_one.count());
                for i in 0..at_once.count() {
                    assert_eq!(at_once.spheres(i), one_by_one.spheres(i), "case {case}");
                }
            }
            Err((_, msg)) => {
                refused += 1;
                overlapping += usize::from(msg.contains("would overlap"));
                assert_eq!(at_once.count(), scene.count(), "unchanged: case {case}");
            }
        }
    }
    // Both outcomes, and both kinds of refusal, were met.
    assert!(
        refused < 120 && overlapping > 0 && overlapping < refused,
        "{refused} refused, {overlapping} for overlaps"
    );
}

/// In a script, `add_at` names the centre that one `add` after another would have stopped at
/// (an overlap before an unreadable centre is named first), and leaves the scene unchanged.
#[test]
fn add_at_names_the_first_failure_and_adds_none() {
    case(
        "let s = scene();\ns.add(dumbbell(#{ center: [0, 50e-6, 0] }));\ntry { s.add_at(dumbbell(), [[0, 0, 0], [1e-6, 0, 0], \"x\"]); } catch (e) { print(e); }\ntry { s.add_at(dumbbell(), [[0, 0, 0], \"x\", [1e-6, 0, 0]]); } catch (e) { print(e); }\ntry { s.add_at(dumbbell(), [[0, 0, 0], [30e-6, 0, 0], [0, 50e-6, 1e-6]]); } catch (e) { print(e); }\nprint(s.count);\nprint(s.add_at(dumbbell(), [[0, 0, 0], [30e-6, 0, 0]]));",
        &[
            "add_at: centre 1: the new swimmer would overlap swimmer 1 (sphere gap",
            "add_at: centre 1 must be an array of 3 numbers such as [1.0, 0.0, 0.0], got \"x\" (string)",
            "add_at: centre 2: the new swimmer would overlap swimmer 0 (sphere gap",
            "place its centre further away\n1\n3\n",
        ],
        0,
    );
}

/// A closure is shown as one, never by the generated name of its function ("anon$5f3c..."):
/// printed, displayed, in a string, in an array or a map, quoted by a message, and when it is
/// called with a number of arguments its parameters do not take.
#[test]
fn closures_are_named_as_such() {
    let t = case(
        "let f = |x| x + 1;\nprint(f);\ndisplay(f);\nprint(`${f}`);\nprint([f]);\nprint(#{ g: f });\ntry { scene().run(f); } catch (e) { print(e); }\nsweep([1, 2], |a, b| a);",
        &[
            "Fn(a closure)\nFn(a closure)\nFn(a closure)\n[Fn(a closure)]\n#{\"g\": Fn(a closure)}\n",
            "got Fn(a closure) (Fn)",
            "sweep: the call for parameter 0 (1) failed: a closure was called with 1 argument (int), which its parameters do not take; write it with 1 parameter, such as |p| ...",
        ],
        1,
    );
    assert!(!t.contains("anon$"), "{t}");
}

/// A swimlab function called with arguments none of its forms takes raises, caught or not, the
/// message that lists its forms: a `catch` receives that text, not Rhai's error map with Rust's
/// spelling of the argument types ("&str | ImmutableString | String"). A form that exists and
/// fails keeps its own error, and a script's own function of the same name is still called.
#[test]
fn a_caught_wrong_call_reads_as_an_uncaught_one() {
    let forms = "add_at cannot be called as add_at(Scene, Dumbbell, string); its forms: add_at(Scene, Dumbbell, array)";
    let t = case(
        &format!("{PAIR}let d = dumbbell();\ntry {{ s.add_at(d, \"x\"); }} catch (e) {{ print(type_of(e)); print(e); }}\ntry {{ s.diffusion(\"x\", 1, 2); }} catch (e) {{ print(e); }}\ntry {{ s.run_periods(-1); }} catch (e) {{ print(e); }}\nfn field(x) {{ x * 2 }}\nprint(field(21));\ns.add_at(d, \"x\");"),
        &[
            &format!("string\n{forms}\n"),
            "diffusion cannot be called as diffusion(Scene, string, int, int); its forms: diffusion(Scene, int)",
            "the number of periods must be >= 0, got -1",
            "\n42\n",
            &format!(":10:3: {forms}"),
        ],
        1,
    );
    assert!(
        !t.contains("ImmutableString") && !t.contains("ErrorFunctionNotFound"),
        "{t}"
    );
}
