//! What the device can run: one answer, [`supports`], for the plan, the calibration and the
//! errors; and the device tableau of each method the GPU steps ([`tableau`]).

use super::rk_stages::Tableau;
use crate::engine::contacts::Contacts;
use crate::engine::integrators::{IntegratorSpec, DOPRI5_A, DOPRI5_C, DOPRI5_E, METHODS};
use crate::engine::model::DeviceKernel;
use crate::engine::scene::Scene;

/// How the device steps: uniform steps of `dt`, or adaptive steps at relative tolerance `rtol`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GpuSteps {
    /// Uniform steps (s).
    Fixed(f64),
    /// Error-controlled steps of an embedded pair.
    Adaptive(f64),
}

/// Whether the device can run the next run of `s` (its model, options and integrator), or why
/// not, in words.
pub fn supports(s: &Scene) -> Result<(), String> {
    model(s)?;
    options(s)?;
    tableau(&s.integrator()).map(|_| ())
}

/// Whether the integrator alone keeps `s` off the device (its model and options could run
/// there), so that another integrator is a fix.
pub fn only_the_integrator_refused(s: &Scene) -> bool {
    model(s).is_ok() && options(s).is_ok() && tableau(&s.integrator()).is_err()
}

/// Whether the scene's model has device kernels, or who lacks them and why.
fn model(s: &Scene) -> Result<(), String> {
    s.swimmer_model()
        .device_kernel()
        .map(|_| ())
        .map_err(|(who, why)| format!("{who} runs on the CPU only ({why})"))
}

/// The options the device kernels do not have: a periodic box, a wall, external forces, contact
/// handling, the cutoff, thermal noise.
fn options(s: &Scene) -> Result<(), String> {
    let cpu_only = |what: &str| Err(format!("{what} runs on the CPU only"));
    if let Some(what) = s.geometry().off_device() {
        return cpu_only(what);
    }
    let averaged = matches!(
        s.swimmer_model().device_kernel(),
        Ok(DeviceKernel::Averaged)
    );
    if !s.external().is_none() {
        cpu_only("external forces and gravity")
    } else if s.thermal().is_on() {
        cpu_only("thermal noise (temperature above 0)")
    } else if s.contacts() != Contacts::default() {
        cpu_only("contact handling (overlaps allowed, steric repulsion)")
    } else if averaged && s.cutoff().is_some() {
        cpu_only("the far-field cutoff")
    } else {
        Ok(())
    }
}

/// The device Runge-Kutta method for an integrator, or why it has none. The methods marked
/// `gpu` in the method table are exactly those with a tableau here (a test holds the two
/// together).
pub fn tableau(spec: &IntegratorSpec) -> Result<(GpuSteps, Tableau), String> {
    match *spec {
        IntegratorSpec::Euler { dt } => Ok((GpuSteps::Fixed(dt), Tableau::euler())),
        IntegratorSpec::Rk4 { dt } => Ok((GpuSteps::Fixed(dt), Tableau::rk4())),
        IntegratorSpec::Dopri5 { rtol } => Ok((GpuSteps::Adaptive(rtol), dopri5_tableau())),
        other => {
            let noise = if other.takes_noise() {
                ", the weak scheme for thermal noise,"
            } else {
                ""
            };
            Err(format!(
                "the GPU backend steps {}; {other}{noise} runs on the CPU",
                gpu_methods()
            ))
        }
    }
}

/// The methods the device steps, as a user writes them: "euler(dt), rk4(dt) and dopri5(rtol)".
fn gpu_methods() -> String {
    let names: Vec<String> = METHODS
        .iter()
        .filter(|m| m.gpu)
        .map(|m| format!("{}({})", m.name, m.parameter))
        .collect();
    match names.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
        _ => names.join(""),
    }
}

/// The CPU's Dormand-Prince 5(4) tableau, for the device.
fn dopri5_tableau() -> Tableau {
    let a: Vec<Vec<f64>> = DOPRI5_A
        .iter()
        .enumerate()
        .map(|(s, row)| row[..s].to_vec())
        .collect();
    // The last row is the solution; its stage (taken there) has weight 0.
    let mut b = DOPRI5_A[6].to_vec();
    b.push(0.0);
    Tableau {
        c: DOPRI5_C.to_vec(),
        a,
        b,
        e: DOPRI5_E.to_vec(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_method_table_marks_exactly_the_methods_with_a_device_tableau() {
        for m in METHODS {
            let spec = (m.make)(1e-3).unwrap();
            assert_eq!(tableau(&spec).is_ok(), m.gpu, "{}", m.name);
        }
        assert_eq!(gpu_methods(), "euler(dt), rk4(dt) and dopri5(rtol)");
    }
}
