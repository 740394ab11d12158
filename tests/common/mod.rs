//! Shared builders for the physics tests: the paper's Fig-1 configurations.
#![allow(dead_code)]

use nalgebra::Vector3;
use std::f64::consts::FRAC_PI_2;
use swimlab::engine::{Dumbbell, IntegratorSpec, Scene, Simulation};

/// ℓ = 5 µm.
pub const ELL: f64 = 5e-6;

/// The paper's swimmer with harmonic-mean radius Λ = `big_l` ℓ: asymmetric (a2 = a1/2) or symmetric.
pub fn swimmer(big_l: f64, asymmetric: bool, phase: f64) -> Dumbbell {
    let l = big_l * ELL;
    let (a1, a2) = if asymmetric {
        (1.5 * l, 0.75 * l)
    } else {
        (l, l)
    };
    Dumbbell {
        a1,
        a2,
        phase,
        ..Dumbbell::default()
    }
}

/// Aligned pair on the x axis, centres at ∓D/2, phases 0 and π/2, orientations `n1`, `n2` (±1 along x).
pub fn aligned_pair(d_over_ell: f64, asymmetric: bool, n1: f64, n2: f64) -> Scene {
    let mut s = Scene::new();
    let half = 0.5 * d_over_ell * ELL;
    s.add(
        swimmer(0.15, asymmetric, 0.0),
        Vector3::new(-half, 0.0, 0.0),
        n1 * Vector3::x(),
    )
    .unwrap();
    s.add(
        swimmer(0.15, asymmetric, FRAC_PI_2),
        Vector3::new(half, 0.0, 0.0),
        n2 * Vector3::x(),
    )
    .unwrap();
    s
}

/// Fig-1(a) mirror pair with the small spheres inwards (N¹ = +x, N² = −x).
pub fn mirror_inwards(d_over_ell: f64, asymmetric: bool) -> Scene {
    aligned_pair(d_over_ell, asymmetric, 1.0, -1.0)
}

/// Per-period change of the mean displacement and of the separation along x (in ℓ), measured over
/// `periods` periods after one settling period (`s` is left at the end of the run).
pub fn drift_per_period(scene: &mut Scene, periods: f64) -> (f64, f64) {
    let mut sim = Simulation::new(std::mem::take(scene));
    let s = &mut sim;
    s.run_periods(1.0).unwrap();
    let x = |s: &Scene, i| s.displacement(i).unwrap().x + s.raw_state().1[i].x;
    let d = |s: &Scene, i| s.displacement(i).unwrap().x;
    let (m0, s0) = ((d(s, 0) + d(s, 1)) / 2.0, x(s, 1) - x(s, 0));
    s.run_periods(periods).unwrap();
    let (m1, s1) = ((d(s, 0) + d(s, 1)) / 2.0, x(s, 1) - x(s, 0));
    *scene = sim.into_scene();
    ((m1 - m0) / periods / ELL, (s1 - s0) / periods / ELL)
}

/// A converged reference integrator for the microscopic model (measured: changing it to 1e-12
/// moves the Fig-1 drift by < 2e-10 relative).
pub fn reference() -> IntegratorSpec {
    IntegratorSpec::Dopri5 { rtol: 1e-10 }
}

/// Relative difference |a − b| / |b|.
pub fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

/// A Python that imports `modules` (e.g. "ase.io"): `SWIMLAB_PYTHON`, else the `.venv` that
/// `.ci/run` makes. Without one the caller's test is skipped with a message saying how to get
/// one (`install`), unless the environment variable `require` is "1" (CI), which makes it a
/// failure.
pub fn python_with(modules: &str, require: &str, install: &str) -> Option<std::path::PathBuf> {
    use std::path::{Path, PathBuf};
    use std::process::{Command, Stdio};
    let candidates = [
        std::env::var_os("SWIMLAB_PYTHON").map(PathBuf::from),
        Some(Path::new(env!("CARGO_MANIFEST_DIR")).join(".venv/bin/python")),
    ];
    let found = candidates.into_iter().flatten().find(|p| {
        Command::new(p)
            .args(["-c", &format!("import {modules}")])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
    });
    if found.is_none() {
        assert!(
            std::env::var(require).as_deref() != Ok("1"),
            "{require}=1 but no Python with {modules} (set SWIMLAB_PYTHON or run .ci/run)"
        );
        eprintln!("skipped: no Python with {modules} ({install})");
    }
    found
}

/// Two Fig-1 swimmers at right angles, swimmer 1's first sphere 0.02 µm above swimmer 0's second
/// one at t = 0: the strokes (±λ/2 per sphere) push the two spheres into each other within the
/// first period (contact at t ≈ 0.029 T).
pub fn about_to_touch() -> Scene {
    let d = Dumbbell::default();
    let mut s = Scene::new();
    s.add(d, Vector3::zeros(), Vector3::x()).unwrap();
    let y = 2.0 * d.a1 + 0.02e-6 + d.ell / 2.0;
    s.add(d, Vector3::new(d.ell / 2.0, y, 0.0), Vector3::y())
        .unwrap();
    s
}

pub mod cli;

/// The fuzz tests' generator: the engine's SplitMix64 ([`swimlab::engine::rng::Rng`]), so the
/// same scripts on every machine, and a pick from a list.
pub struct Rng(swimlab::engine::rng::Rng);
impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(swimlab::engine::rng::Rng::new(seed))
    }
    pub fn next(&mut self) -> u64 {
        self.0.next_u64()
    }
    pub fn pick<'a>(&mut self, from: &[&'a str]) -> &'a str {
        from[(self.next() % from.len() as u64) as usize]
    }
}
