//! The largest stable step of each explicit method, found by bisection, as a function of the spring
//! constant and the radii, against the linear estimate: the spring mode relaxes at
//! rate = k0 (1/γ1 + 1/γ2), and the stability regions of forward Euler and classic RK4 end at −2
//! and −2.785 on the real axis, so forward Euler is stable for dt·rate < 2, classic RK4 for
//! dt·rate < 2.785. Also what each method does beyond its limit. The measured limits are
//! higher: the dumbbell's own hydrodynamic interaction slows its spring mode ([`hi_factor`]).

use super::table::Table;
use crate::engine::{Dumbbell, IntegratorSpec, Scene, Simulation};
use nalgebra::Vector3;

/// The linear stability limit of dt·rate for a method on the decaying mode.
pub fn estimate(method: &str) -> f64 {
    match method {
        "euler" => 2.0,
        _ => 2.785,
    }
}

fn spec(method: &str, dt: f64) -> IntegratorSpec {
    match method {
        "euler" => IntegratorSpec::Euler { dt },
        _ => IntegratorSpec::Rk4 { dt },
    }
}

/// An isolated asymmetric dumbbell (a2 = a1/2) with harmonic-mean radius `big_l` ℓ and `k0`.
fn dumbbell_scene(k0: f64, big_l: f64) -> Scene {
    let ell = 5e-6;
    let l = big_l * ell;
    let mut s = Scene::new();
    let _ = s.add(
        Dumbbell {
            a1: 1.5 * l,
            a2: 0.75 * l,
            k0,
            ..Dumbbell::default()
        },
        Vector3::zeros(),
        Vector3::x(),
    );
    s
}

/// Run 4 periods at dt; stable when no guard fires and the spring ends within 5% of λ of its rest
/// length (its physical lag is ~λω/rate, below 1% of λ here). Returns the failure text if any.
fn trial(k0: f64, big_l: f64, method: &str, dt: f64) -> Result<(), String> {
    let mut s = Simulation::new(dumbbell_scene(k0, big_l));
    s.scene_mut().set_integrator(Some(spec(method, dt)));
    s.run_periods(4.0).map_err(|e| e.to_string())?;
    let d = s.swimmer(0).map_err(|e| e.to_string())?;
    let dev = (s.length(0).map_err(|e| e.to_string())? - d.rest_length(s.time())).abs();
    if dev > 0.05 * d.lambda {
        return Err(format!(
            "no guard fired, but the spring ended {:.2} λ off its rest length",
            dev / d.lambda
        ));
    }
    Ok(())
}

/// The spring mode's true relaxation rate includes the hydrodynamic interaction of the dumbbell's
/// own spheres: k0 (1/γ1 + 1/γ2 − 2h(d)), h(d) = 1/(4πμd) − (a1² + a2²)/(12πμd³) (RPY, forces along
/// the axis). It is fastest at the longest length d = ℓ + λ. Returns rate_HI / rate.
pub fn hi_factor(k0: f64, big_l: f64) -> f64 {
    let s = dumbbell_scene(k0, big_l);
    let Ok(d) = s.swimmer(0) else { return 1.0 };
    let mu = s.mu();
    let pi = std::f64::consts::PI;
    let len = d.ell + d.lambda;
    let h =
        1.0 / (4.0 * pi * mu * len) - (d.a1 * d.a1 + d.a2 * d.a2) / (12.0 * pi * mu * len.powi(3));
    let drag = 1.0 / (6.0 * pi * mu * d.a1) + 1.0 / (6.0 * pi * mu * d.a2);
    1.0 - 2.0 * h / drag
}

/// One row: found limit of dt·rate and what happens at 1.2× it.
pub struct Row {
    /// "euler" or "rk4".
    pub method: &'static str,
    /// Spring constant (kg/s²).
    pub k0: f64,
    /// Harmonic-mean radius in ℓ.
    pub big_l: f64,
    /// Relaxation rate (1/s).
    pub rate: f64,
    /// Largest stable dt·rate found.
    pub found: f64,
    /// What happened at 1.2× the found step.
    pub beyond: String,
}

/// Bisect the stability limit for every combination.
pub fn run(quick: bool) -> Vec<Row> {
    let k0s: &[f64] = if quick {
        &[1e-3]
    } else {
        &[2.5e-4, 1e-3, 4e-3]
    };
    let radii: &[f64] = if quick { &[0.15] } else { &[0.05, 0.15, 0.25] };
    let iterations = if quick { 8 } else { 30 };
    let mut rows = Vec::new();
    for method in ["euler", "rk4"] {
        for &k0 in k0s {
            for &big_l in radii {
                let rate = dumbbell_scene(k0, big_l).stiff_rate();
                let (mut lo, mut hi) = (0.5, 5.0);
                for _ in 0..iterations {
                    let mid = 0.5 * (lo + hi);
                    if trial(k0, big_l, method, mid / rate).is_ok() {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let beyond = match trial(k0, big_l, method, 1.2 * lo / rate) {
                    Ok(()) => "stable (limit not sharp)".to_string(),
                    Err(e) => e,
                };
                rows.push(Row {
                    method,
                    k0,
                    big_l,
                    rate,
                    found: lo,
                    beyond,
                });
            }
        }
    }
    rows
}

/// The result as a table.
pub fn table(rows: &[Row]) -> Table {
    let mut t = Table::new(&[
        "method",
        "k0 (kg/s^2)",
        "Lambda/ell",
        "rate (1/s)",
        "max dt*rate",
        "estimate",
        "estimate with HI",
        "max dt (s)",
        "steps/period",
        "at 1.2x the limit",
    ]);
    for r in rows {
        let period = 2.0 * std::f64::consts::PI / 500.0;
        t.rows.push(vec![
            r.method.into(),
            format!("{:.2e}", r.k0),
            format!("{}", r.big_l),
            format!("{:.3e}", r.rate),
            format!("{:.3}", r.found),
            format!("{}", estimate(r.method)),
            format!("{:.3}", estimate(r.method) / hi_factor(r.k0, r.big_l)),
            format!("{:.3e}", r.found / r.rate),
            format!("{:.0}", period * r.rate / r.found),
            r.beyond.chars().take(110).collect(),
        ]);
    }
    t
}
