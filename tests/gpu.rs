//! The GPU backend against the CPU: one step to round-off, the Fig-1 drift over 10 periods, a
//! 1,000-swimmer suspension, guard failures, and the fallback without an adapter.
//!
//! Without an f64-capable adapter these tests skip with a message, unless SWIMLAB_REQUIRE_GPU=1
//! (set by .ci/run, which installs lavapipe), where a missing adapter fails them.

use crate::common;
use crate::common::{about_to_touch, aligned_pair, mirror_inwards, ELL};
use nalgebra::Vector3;
use swimlab::engine::build::{random_suspension, Orientations, Phases};
use swimlab::engine::error::Setting;
use swimlab::engine::{Backend, Dumbbell, EngineError, IntegratorSpec, Model, Scene, Simulation};

fn gpu_present(test: &str) -> bool {
    match swimlab::engine::gpu::device() {
        Ok(_) => true,
        Err(e) => {
            if std::env::var_os("SWIMLAB_REQUIRE_GPU").is_some_and(|v| v != "0") {
                panic!("{test}: SWIMLAB_REQUIRE_GPU is set but {e}");
            }
            eprintln!("{test}: skipped, {e}");
            false
        }
    }
}

/// A CPU and a GPU copy of the scene, stepped by the same method: the GPU's (its default is
/// the spring model's RK4 at 0.8/rate, where the CPU's default is `auto(tol)`).
fn twins(s: &Scene) -> (Scene, Scene) {
    let mut g = s.clone();
    g.set_backend(Backend::Gpu);
    let mut c = s.clone();
    c.set_backend(Backend::Cpu);
    c.set_integrator(Some(g.integrator()));
    (c, g)
}

/// [`twins`], ready to run.
fn sim_twins(s: &Scene) -> (Simulation, Simulation) {
    let (c, g) = twins(s);
    (Simulation::new(c), Simulation::new(g))
}

/// max |Δ_gpu − Δ_cpu| / max |Δ_cpu| over the components of each block (0: centres, 1: b or N),
/// where Δ is the change of the state over the run.
fn block_mismatch(y0: &[f64], cpu: &[f64], gpu: &[f64]) -> [f64; 2] {
    let mut out = [0.0; 2];
    for (block, o) in out.iter_mut().enumerate() {
        let (mut diff, mut size) = (0.0f64, 0.0f64);
        for i in (0..y0.len()).filter(|i| (i % 6) / 3 == block) {
            diff = diff.max(((gpu[i] - y0[i]) - (cpu[i] - y0[i])).abs());
            size = size.max((cpu[i] - y0[i]).abs());
        }
        // A block that moved on neither backend (a pair's fixed orientations) agrees.
        *o = if diff == 0.0 { 0.0 } else { diff / size };
    }
    out
}

fn one_step_mismatch(s: &Scene, dt: f64) -> [f64; 2] {
    let (mut c, mut g) = sim_twins(s);
    for x in [&mut c, &mut g] {
        x.scene_mut()
            .set_integrator(Some(IntegratorSpec::rk4(dt).unwrap()));
        x.run(dt).unwrap();
    }
    assert_eq!(c.time(), g.time());
    block_mismatch(s.raw_state().0, c.raw_state().0, g.raw_state().0)
}

// One RK4 step: both backends evaluate the same formulas in f64 in a different order (pair sums,
// stage combinations) and with a different sin (a polynomial on the device); the differences are
// a few ulps of each term, ~1e-15 of the step's change; 1e-12 leaves a thousandfold margin.
#[test]
fn one_step_agrees_to_round_off_micro() {
    if !gpu_present("one_step_agrees_to_round_off_micro") {
        return;
    }
    for s in [
        mirror_inwards(10.0, true),
        aligned_pair(4.0, false, 1.0, 1.0),
    ] {
        let dt = s.default_micro_step();
        let m = one_step_mismatch(&s, dt);
        eprintln!("micro one step: mismatch {m:?}");
        assert!(
            m[0] <= 1e-12 && m[1] <= 1e-12,
            "micro one-step mismatch {m:?}"
        );
    }
}

#[test]
fn one_step_agrees_to_round_off_averaged() {
    if !gpu_present("one_step_agrees_to_round_off_averaged") {
        return;
    }
    let mut s = Scene::new();
    s.set_model(Model::Averaged);
    let d = common::swimmer(0.15, true, 0.0);
    s.add(d, Vector3::zeros(), Vector3::new(1.0, 0.2, 0.1))
        .unwrap();
    s.add(
        Dumbbell { phase: 1.0, ..d },
        Vector3::new(6.0, 2.0, -1.0) * ELL,
        Vector3::new(-0.3, 1.0, 0.5),
    )
    .unwrap();
    s.add(
        Dumbbell { phase: 2.5, ..d },
        Vector3::new(-3.0, 5.0, 2.0) * ELL,
        Vector3::new(0.0, 0.0, 1.0),
    )
    .unwrap();
    let m = one_step_mismatch(&s, 100.0 * d.period());
    eprintln!("averaged one step: mismatch {m:?}");
    assert!(
        m[0] <= 1e-12 && m[1] <= 1e-12,
        "averaged one-step mismatch {m:?}"
    );
}

// Fig-1 pair, default RK4 step, 10 periods after one settling period: the drift (~1e-6 ℓ per
// period) is the difference of two positions ~10ℓ apart, so round-off differences of 1e-16 in
// the positions appear at ~1e-10 of the drift; 1e-9 leaves a tenfold margin.
#[test]
fn fig1_drift_over_ten_periods_agrees() {
    if !gpu_present("fig1_drift_over_ten_periods_agrees") {
        return;
    }
    let (mut c, mut g) = twins(&mirror_inwards(10.0, true));
    let (dc, _) = common::drift_per_period(&mut c, 10.0);
    let (dg, _) = common::drift_per_period(&mut g, 10.0);
    let rel = common::rel(dg, dc);
    eprintln!("Fig-1 drift per period: cpu {dc:.12e} ell, gpu {dg:.12e} ell, relative difference {rel:.2e}");
    assert!(rel <= 1e-9, "10-period drift differs by {rel:e}");
}

#[test]
fn averaged_drift_over_many_periods_agrees() {
    if !gpu_present("averaged_drift_over_many_periods_agrees") {
        return;
    }
    let mut s = mirror_inwards(10.0, true);
    s.set_model(Model::Averaged);
    let t = s.period().unwrap();
    s.set_integrator(Some(IntegratorSpec::rk4(t).unwrap()));
    let (mut c, mut g) = twins(&s);
    let (dc, sc) = common::drift_per_period(&mut c, 10.0);
    let (dg, sg) = common::drift_per_period(&mut g, 10.0);
    assert!(common::rel(dg, dc) <= 1e-9, "drift {dg:e} vs {dc:e}");
    assert!(
        (sg - sc).abs() <= 1e-9 * dc.abs(),
        "separation {sg:e} vs {sc:e}"
    );
}

/// 1,000 randomly placed and oriented swimmers with random phases at sphere volume fraction `phi`.
fn suspension(model: Model, phi: f64) -> Scene {
    let mut s = Scene::new();
    s.set_model(model);
    let d = common::swimmer(0.15, true, 0.0);
    let side = swimlab::engine::build::box_side(1000, &d, phi).unwrap();
    random_suspension(
        &mut s,
        1000,
        d,
        [side; 3],
        Orientations::Random,
        Phases::Random,
        7,
    )
    .unwrap();
    s
}

// A few steps of a dense random suspension: many more terms per sum than the pair, so the
// round-off of the sums grows (~sqrt(terms) ulps); still far below 1e-12 of the change.
#[test]
fn random_suspension_of_1000_swimmers_agrees() {
    if !gpu_present("random_suspension_of_1000_swimmers_agrees") {
        return;
    }
    let s = suspension(Model::Micro, 0.01);
    let dt = s.default_micro_step();
    let (mut c, mut g) = sim_twins(&s);
    for x in [&mut c, &mut g] {
        x.scene_mut()
            .set_integrator(Some(IntegratorSpec::rk4(dt).unwrap()));
        x.run(3.0 * dt).unwrap();
    }
    let m = block_mismatch(s.raw_state().0, c.raw_state().0, g.raw_state().0);
    eprintln!("1,000-swimmer micro, 3 steps: mismatch {m:?}");
    assert!(m[0] <= 1e-12 && m[1] <= 1e-12, "{m:?}");

    // The far-field averaged model at a lower density: its rates grow as D⁻⁵, and at the closest
    // random distances of φ = 1% a period-long step would amplify round-off chaotically.
    let s = suspension(Model::Averaged, 1e-3);
    let (mut c, mut g) = sim_twins(&s);
    let h = s.period().unwrap();
    for x in [&mut c, &mut g] {
        x.scene_mut()
            .set_integrator(Some(IntegratorSpec::rk4(h).unwrap()));
        x.run(3.0 * h).unwrap();
    }
    let m = block_mismatch(s.raw_state().0, c.raw_state().0, g.raw_state().0);
    eprintln!("1,000-swimmer averaged, 3 steps: mismatch {m:?}");
    assert!(m[0] <= 1e-12 && m[1] <= 1e-12, "{m:?}");
}

// A step far above the stability limit: the device's guard stops the run, the CPU replays the
// step, and the error is the CPU backend's, word for word, with the last good state kept.
#[test]
fn unstable_step_fails_the_same_way_on_both_backends() {
    if !gpu_present("unstable_step_fails_the_same_way_on_both_backends") {
        return;
    }
    let s = mirror_inwards(10.0, true);
    let dt = 6.0 / s.stiff_rate();
    let (mut c, mut g) = sim_twins(&s);
    let mut errors = Vec::new();
    for x in [&mut c, &mut g] {
        x.scene_mut()
            .set_integrator(Some(IntegratorSpec::euler(dt).unwrap()));
        errors.push(x.run(200.0 * dt).unwrap_err().to_string());
    }
    assert_eq!(errors[0], errors[1]);
    assert_eq!(c.time(), g.time());
    assert!(errors[1].contains("spring"), "{}", errors[1]);
}

// dopri5 into a contact on the device: an accepted attempt whose state has two spheres
// overlapping ends the submission; the CPU replays that step from the step size it began with,
// its guard refuses it, and the step shrinks towards the contact until it stops advancing the
// time (the CPU stepper's floor). Both backends then stop with the same error naming the same
// spheres, at times within 1e-9 of each other (the crawl's last steps depend on rounding, so the
// step counts may differ by a few), each scene at a state whose spheres do not overlap.
#[test]
fn dopri5_into_a_contact_stops_the_same_way_on_both_backends() {
    if !gpu_present("dopri5_into_a_contact_stops_the_same_way_on_both_backends") {
        return;
    }
    for rtol in [1e-3, 1e-6] {
        let (mut c, mut g) = sim_twins(&about_to_touch());
        let mut ends = Vec::new();
        for x in [&mut c, &mut g] {
            x.scene_mut()
                .set_integrator(Some(IntegratorSpec::dopri5(rtol).unwrap()));
            let e = x.run_periods(1.0).unwrap_err().to_string();
            let gap = swimlab::engine::Observable::MinGap.evaluate(x).unwrap()[0];
            eprintln!(
                "dopri5({rtol:e}): t = {:e}, gap {gap:e}, {:?}",
                x.time(),
                x.stats()
            );
            assert!(gap >= 0.0, "gap {gap:e}");
            let cause = e
                .split(": ")
                .nth(1)
                .unwrap_or("")
                .split(" (gap")
                .next()
                .unwrap_or("");
            ends.push((cause.to_string(), x.time()));
        }
        assert!(ends[0].0.contains("overlaps"), "{ends:?}");
        assert_eq!(ends[0].0, ends[1].0);
        assert!(
            (ends[0].1 - ends[1].1).abs() <= 1e-9 * ends[0].1,
            "{ends:?}"
        );
        assert!(g.stats().rejected_by_guard > 0, "{:?}", g.stats());
    }
}

/// Both backends run `s` with dopri5(`rtol`) for `duration` seconds: the same steps and
/// rejections, and the state's change within `bound` (relative, per block).
fn dopri5_parity(s: &Scene, rtol: f64, duration: f64, bound: f64) -> [f64; 2] {
    let (mut c, mut g) = sim_twins(s);
    for x in [&mut c, &mut g] {
        x.scene_mut()
            .set_integrator(Some(IntegratorSpec::dopri5(rtol).unwrap()));
        x.run(duration).unwrap();
    }
    assert_eq!(c.time(), g.time());
    let (sc, sg) = (c.stats(), g.stats());
    assert!(sc.steps > 1, "{sc:?}");
    assert_eq!(
        (sc.steps, sc.rejected),
        (sg.steps, sg.rejected),
        "cpu {sc:?}, gpu {sg:?}"
    );
    let m = block_mismatch(s.raw_state().0, c.raw_state().0, g.raw_state().0);
    eprintln!("  {} steps, {} rejected on both", sc.steps, sc.rejected);
    assert!(m[0] <= bound && m[1] <= bound, "{m:?}");
    m
}

// Adaptive steps on the device decide accept/reject and the next step as the CPU does (its
// powers in f64, the guards counted for accepted attempts only); the sums and sin differ by
// ulps. The drifts agree within 1e-9 (round-off at ~1e-10 of the drift, as above), with the same steps and
// rejections. Loose tolerances are the
// hard case: there dopri5 rides the springs' stability limit, rejecting attempts whose states
// would fail the guards.
#[test]
fn dopri5_on_the_device_takes_the_cpus_steps() {
    if !gpu_present("dopri5_on_the_device_takes_the_cpus_steps") {
        return;
    }
    // The spring model: stiff springs make dopri5 reject steps at its stability limit.
    let s = mirror_inwards(10.0, true);
    let t = s.period().unwrap();
    for rtol in [0.5, 1e-3, 1e-8] {
        let m = dopri5_parity(&s, rtol, 0.2 * t, 1e-9);
        eprintln!("Fig-1 pair, micro, dopri5({rtol:e}), 0.2 periods: mismatch {m:?}");
    }
    // The averaged model, the default tolerance, 50 periods.
    let mut s = mirror_inwards(10.0, true);
    s.set_model(Model::Averaged);
    let m = dopri5_parity(&s, 1e-10, 50.0 * t, 1e-9);
    eprintln!("Fig-1 pair, averaged, dopri5(1e-10), 50 periods: mismatch {m:?}");
    // Many swimmers: the error norm reduced over many workgroups.
    let s = suspension(Model::Averaged, 1e-3);
    let m = dopri5_parity(&s, 1e-8, 5.0 * t, 1e-9);
    eprintln!("1,000-swimmer averaged, dopri5(1e-8), 5 periods: mismatch {m:?}");
}

// Rows cut the run into segments: each starts from the step the last one proposed, on both.
#[test]
fn dopri5_rows_agree_across_segments() {
    if !gpu_present("dopri5_rows_agree_across_segments") {
        return;
    }
    use swimlab::engine::{Observable, Recorder, Trigger};
    let mut s = mirror_inwards(10.0, true);
    s.set_model(Model::Averaged);
    s.set_integrator(Some(IntegratorSpec::dopri5(1e-9).unwrap()));
    let (mut c, mut g) = sim_twins(&s);
    let mut ids = Vec::new();
    for x in [&mut c, &mut g] {
        let t = x.period().unwrap();
        let r = Recorder::new(
            x,
            vec![Observable::CenterH(0), Observable::CenterH(1)],
            Trigger::EverySeconds(3.0 * t),
        )
        .unwrap();
        ids.push(x.add_recorder(r));
        x.run(30.0 * t).unwrap();
    }
    assert_eq!(
        (c.stats().steps, c.stats().rejected),
        (g.stats().steps, g.stats().rejected)
    );
    let (rc, rg) = (c.recorder(ids[0]).unwrap(), g.recorder(ids[1]).unwrap());
    assert!(rc.rows.len() >= 10);
    assert_eq!(rc.rows.len(), rg.rows.len());
    let x0 = rc.rows[0][1];
    for (a, b) in rc.rows.iter().zip(&rg.rows) {
        assert_eq!(a[0], b[0], "row times");
        let rel = ((a[1] - b[1]) / (a[1] - x0 + 1e-300)).abs();
        assert!(
            a[1] == b[1] || rel < 1e-9,
            "R_H.x moved differently by {rel:e}"
        );
    }
}

// An interrupt between submissions stops an adaptive device run at an accepted state, which a
// later run continues from (on the device, from the step size the device left).
#[test]
fn an_interrupt_stops_dopri5_on_the_device() {
    if !gpu_present("an_interrupt_stops_dopri5_on_the_device") {
        return;
    }
    use std::sync::atomic::{AtomicU64, Ordering};
    use std::sync::Arc;
    let mut s = mirror_inwards(10.0, true);
    s.set_integrator(Some(IntegratorSpec::dopri5(1e-6).unwrap()));
    s.set_backend(Backend::Gpu);
    let mut g = Simulation::new(s);
    let calls = Arc::new(AtomicU64::new(0));
    let c = calls.clone();
    g.set_interrupt(Some(Arc::new(move || {
        c.fetch_add(1, Ordering::Relaxed) >= 3
    })));
    let t = g.period().unwrap();
    let err = g.run(100.0 * t).unwrap_err();
    assert!(matches!(err, EngineError::Interrupted { .. }), "{err}");
    let stopped = g.time();
    assert!(stopped > 0.0 && stopped < 100.0 * t, "{}", stopped / t);
    assert!(g.stats().steps > 0);
    g.set_interrupt(None);
    g.run(0.1 * t).unwrap();
    assert!(g.time() > stopped);
}

#[test]
fn recorders_see_the_same_rows() {
    if !gpu_present("recorders_see_the_same_rows") {
        return;
    }
    use swimlab::engine::{Observable, Recorder, Trigger};
    let (mut c, mut g) = sim_twins(&mirror_inwards(10.0, true));
    let mut ids = Vec::new();
    for x in [&mut c, &mut g] {
        let t = x.period().unwrap();
        let r = Recorder::new(
            x,
            vec![Observable::CenterH(0)],
            Trigger::EverySeconds(t / 4.0),
        )
        .unwrap();
        ids.push(x.add_recorder(r));
        x.run(2.0 * t).unwrap();
    }
    let (rc, rg) = (c.recorder(ids[0]).unwrap(), g.recorder(ids[1]).unwrap());
    assert!(rc.rows.len() >= 8);
    assert_eq!(rc.rows.len(), rg.rows.len());
    for (a, b) in rc.rows.iter().zip(&rg.rows) {
        assert_eq!(a[0], b[0], "row times");
        let rel = ((a[1] - b[1]) / a[1]).abs();
        assert!(rel < 1e-14, "R_H.x differs by {rel:e}");
    }
}

#[test]
fn auto_explains_its_choice() {
    if !gpu_present("auto_explains_its_choice") {
        return;
    }
    let mut s = mirror_inwards(10.0, true);
    s.set_backend(Backend::Auto);
    let info = swimlab::engine::plan::backend_info(&s).unwrap();
    assert!(info.starts_with("cpu: auto:"), "{info}");
    s.set_model(Model::Rigid);
    assert!(swimlab::engine::plan::backend_info(&s)
        .unwrap()
        .contains("rigid"));
    s.set_backend(Backend::Gpu);
    let err = swimlab::engine::plan::backend_info(&s).unwrap_err();
    let e = err.to_string();
    // Engine terms for an embedder; the script layer shows the fix as `s.backend = "cpu"`.
    assert!(e.contains("rigid") && e.contains("the cpu backend"), "{e}");
    assert!(
        matches!(&err, EngineError::Unsupported { fixes, .. } if fixes.contains(&Setting::Backend("cpu"))),
        "{err:?}"
    );
    let shown = swimlab::script::engine_message(&err);
    assert!(shown.contains("s.backend = \"cpu\""), "{shown}");
}

// Without an adapter (hidden by SWIMLAB_NO_GPU): "auto" runs on the CPU and says so; "gpu" is a
// clear error at the script position, and the script stops there. Runs everywhere.
#[test]
fn without_an_adapter_auto_falls_back_and_gpu_refuses() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_swimlab"))
        .args([
            "-e",
            "let s = scene(); s.add(dumbbell(#{})); s.integrator = rk4(1e-6); s.backend = \"auto\"; print(s.backend_info); s.run(1e-4); print(`t=${s.time}`); s.backend = \"gpu\";",
        ])
        .env("SWIMLAB_NO_GPU", "1")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stdout.contains("cpu: auto: no GPU adapter: SWIMLAB_NO_GPU is set"),
        "{stdout}"
    );
    assert!(stdout.contains("t=0.0001"), "{stdout}");
    assert!(!out.status.success());
    assert!(
        stderr.contains("s.backend = \"gpu\": no GPU adapter"),
        "{stderr}"
    );
}

/// `bench scaling` measures both models on the GPU beside the CPU series when an adapter is
/// present: every series has a row per size, and the table names the GPU ones.
#[test]
fn bench_scaling_has_gpu_series() {
    if !gpu_present("bench_scaling_has_gpu_series") {
        return;
    }
    use swimlab::bench::scaling;
    let rows = scaling::run(4).unwrap();
    let lines = scaling::series(true);
    assert_eq!(lines.len(), 5);
    for line in &lines {
        let n = rows.iter().filter(|r| r.line == *line).count();
        let want = if line.cutoff.is_some() { 5 } else { 2 };
        assert_eq!(n, want, "{}", scaling::label(line));
    }
    assert!(rows.iter().all(|r| r.step > 0.0 && r.step.is_finite()));
    let table = scaling::table(&rows).render();
    assert!(
        table.contains("micro, gpu") && table.contains("averaged, gpu"),
        "{table}"
    );
}

/// On a machine without a session runtime folder (a server, CI), choosing the GPU
/// prints nothing but what swimlab says: Mesa's device-selection layer, which would connect to
/// the Wayland display and have its library print "XDG_RUNTIME_DIR is invalid or not set" twice,
/// is kept out of the process (the binary, which is what users run).
#[test]
fn no_display_noise_without_a_runtime_folder() {
    if !gpu_present("no_display_noise_without_a_runtime_folder") {
        return;
    }
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_swimlab"))
        .args([
            "-e",
            "let s = scene(); s.add(dumbbell()); s.backend = \"gpu\"; s.run_periods(0.01); s.backend_info",
        ])
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("NODEVICE_SELECT")
        .env_remove("MESA_VK_DEVICE_SELECT")
        .env("SWIMLAB_PROGRESS", "0")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}{stderr}");
    assert!(stdout.contains("gpu:"), "{stdout}");
    assert!(stderr.is_empty(), "nothing on stderr: {stderr}");
}
