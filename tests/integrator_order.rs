//! Each integrator's global error falls at its order: halving the step divides the error by 2^p.
//! Problem with a known solution: a damped, forced oscillator
//! y₁' = y₂, y₂' = −y₁ − 0.1 y₂ + cos t, integrated to t = 3 and compared with a 10⁻¹³-accurate
//! reference; plus the adaptive method's error tracking its tolerance.

use swimlab::engine::integrators::{Dopri5, Euler, OdeSystem, Rk4, Rosenbrock, Stats, Stepper};

struct Forced;
impl OdeSystem for Forced {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        dy[0] = y[1];
        dy[1] = -y[0] - 0.1 * y[1] + t.cos();
    }
    fn error_scale(&self, _y: &[f64], scale: &mut [f64]) {
        scale.fill(1.0);
    }
    fn jacobian_block(&self) -> usize {
        2
    }
    fn jacobian_blocks(&mut self, _t: f64, _y: &[f64], out: &mut [f64]) {
        out.copy_from_slice(&[0.0, 1.0, -1.0, -0.1]);
    }
}

/// The same problem offering no Jacobian: a W-method must keep its order with J = 0.
struct ForcedNoJacobian;
impl OdeSystem for ForcedNoJacobian {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        Forced.rhs(t, y, dy)
    }
    fn error_scale(&self, y: &[f64], scale: &mut [f64]) {
        Forced.error_scale(y, scale)
    }
}

/// Exact solution of the forced damped oscillator with y(0) = (1, 0): particular part
/// sin(t)/0.1 (resonant forcing at ω = 1 with damping 0.1), plus the homogeneous part.
fn exact(t: f64) -> [f64; 2] {
    // y'' + 0.1 y' + y = cos t: particular y_p = 10 sin t. Homogeneous: e^{-0.05t}(A cos wt + B sin wt).
    let w = (1.0f64 - 0.0025).sqrt();
    let a = 1.0; // y(0) = A + 0 = 1
    let b = (0.0 - 10.0 + 0.05 * a) / w; // y'(0) = 10 − 0.05A + wB = 0
    let e = (-0.05 * t).exp();
    let y = 10.0 * t.sin() + e * (a * (w * t).cos() + b * (w * t).sin());
    let dy = 10.0 * t.cos() - 0.05 * e * (a * (w * t).cos() + b * (w * t).sin())
        + e * w * (-a * (w * t).sin() + b * (w * t).cos());
    [y, dy]
}

fn error(stepper: &mut dyn Stepper, t_end: f64) -> f64 {
    error_on(&mut Forced, stepper, t_end)
}

fn error_on(sys: &mut dyn OdeSystem, stepper: &mut dyn Stepper, t_end: f64) -> f64 {
    let mut y = [1.0, 0.0];
    let mut t = 0.0;
    let mut stats = Stats::default();
    while t < t_end {
        t = stepper.step(sys, t, &mut y, t_end, &mut stats).unwrap();
    }
    let e = exact(t_end);
    ((y[0] - e[0]).powi(2) + (y[1] - e[1]).powi(2)).sqrt()
}

fn observed_order(make: impl Fn(f64) -> Box<dyn Stepper>, h: f64) -> f64 {
    let e1 = error(make(h).as_mut(), 3.0);
    let e2 = error(make(h / 2.0).as_mut(), 3.0);
    (e1 / e2).log2()
}

#[test]
fn euler_is_first_order() {
    let p = observed_order(|h| Box::new(Euler::new(h)), 1e-3);
    // Asymptotic regime: the next term is O(h²), i.e. ~1e-3 relative here.
    assert!((p - 1.0).abs() < 0.02, "observed order {p}");
}

#[test]
fn rk4_is_fourth_order() {
    let p = observed_order(|h| Box::new(Rk4::new(h)), 0.05);
    assert!((p - 4.0).abs() < 0.1, "observed order {p}");
}

#[test]
fn dormand_prince_is_fifth_order() {
    let p = observed_order(|h| Box::new(Dopri5::fixed_step(h)), 0.1);
    assert!((p - 5.0).abs() < 0.15, "observed order {p}");
}

#[test]
fn adaptive_dormand_prince_error_follows_its_tolerance() {
    // Tolerance proportionality: with a PI controller the global error scales ~ rtol; over three
    // decades it must fall by at least two.
    let e1 = error(&mut Dopri5::new(1e-5), 3.0);
    let e2 = error(&mut Dopri5::new(1e-8), 3.0);
    assert!(e1 / e2 > 100.0, "errors {e1:e} -> {e2:e}");
    // And the error is of the order of the tolerance times the solution size (~10).
    assert!(e2 < 1e-8 * 10.0 * 100.0, "error {e2:e}");
}

#[test]
fn rosenbrock_w_is_third_order_with_the_jacobian_and_without_it() {
    let p = observed_order(|h| Box::new(Rosenbrock::fixed_step(h)), 0.05);
    assert!((p - 3.0).abs() < 0.15, "with J: observed order {p}");
    // The W property: any matrix in place of J, here none, keeps the order.
    let e1 = error_on(
        &mut ForcedNoJacobian,
        &mut Rosenbrock::fixed_step(0.05),
        3.0,
    );
    let e2 = error_on(
        &mut ForcedNoJacobian,
        &mut Rosenbrock::fixed_step(0.025),
        3.0,
    );
    let p0 = (e1 / e2).log2();
    assert!((p0 - 3.0).abs() < 0.2, "without J: observed order {p0}");
}
