//! The averaged model's answers to the model seam ([`StrokeAveraged`]): its state holds the unit
//! orientation N of swimmers whose spheres sit at ℓ, its equations are those of identical
//! strokes in open space or a box free of external forces, its cutoff, and the integrators it
//! takes (dopri5, the suspension stepper; no stroboscopic averaging).

use super::{AveragedSystem, DEFAULT_SKIN_OF_CUTOFF, LIST_SWIMMERS};
use crate::engine::error::{invalid, unsupported, EngineError, Result, Setting};
use crate::engine::ewald::EwaldMethod;
use crate::engine::integrators::{
    noisy_euler, IntegratorSpec, OdeSystem, DEFAULT_AVERAGED_RTOL, DEFAULT_SUSPENSION_TOL,
};
use crate::engine::model::{DeviceKernel, Model, SceneView, SwimmerModel};
use crate::engine::periodic::PeriodicBox;
use crate::engine::swimmer::Dumbbell;

/// The stroke-averaged model's answers to the model seam.
#[derive(Debug, Clone, Copy, Default)]
pub struct StrokeAveraged;

/// The averaged model's cutoff in `periodic` with `cutoff` set: the one set; in a box at most
/// half its shortest side (a pair meets one image), and when none is set the longest that
/// leaves the neighbour lists their skin within that half, L/2 / (1 + [`DEFAULT_SKIN_OF_CUTOFF`])
/// = 0.476 L. At L/2 itself the lists would have no skin and every right-hand side would rebuild
/// them, tens of times the cost, for pair terms that change the rates by far less than a
/// suspension's tolerance (the measurements are in the book's "Suspensions, boxes and fields").
pub fn cutoff_in(periodic: Option<&PeriodicBox>, cutoff: Option<f64>) -> Result<Option<f64>> {
    let Some(b) = periodic else {
        return Ok(cutoff);
    };
    let half = 0.5 * b.shortest();
    match cutoff {
        None => Ok(Some(half / (1.0 + DEFAULT_SKIN_OF_CUTOFF))),
        Some(c) if c <= half => Ok(Some(c)),
        Some(c) => Err(invalid!(
            "the averaged model's cutoff {c:e} m is longer than half the box's shortest side ({half:e} m): a pair would meet two images; set the cutoff to {half:e} m or less, or use a larger box"
        )),
    }
}

/// The averaged equations describe identical strokes: ω, λ and ℓ must agree.
pub fn check_identical(swimmers: &[Dumbbell]) -> Result<()> {
    if let Some(first) = swimmers.first() {
        for (i, d) in swimmers.iter().enumerate() {
            if d.omega != first.omega || d.lambda != first.lambda || d.ell != first.ell {
                return Err(unsupported(
                    format!("the averaged model needs equal omega, lambda and ell for all swimmers (swimmer {i} differs from swimmer 0)"),
                    &[Setting::Model("micro")],
                ));
            }
        }
    }
    Ok(())
}

/// The averaged equations are those of swimmers in open space or a box, free of external
/// forces: a solid boundary (a wall) or external forces are refused with the reason.
pub fn check_open(s: &dyn SceneView) -> Result<()> {
    if s.boundary().geometry().solid() {
        return Err(unsupported(
            "the averaged model has no wall equations (its pair terms are open space's); long runs near a wall come from auto or stroboscopic averaging on the microscopic model",
            &[Setting::Model("micro"), Setting::Model("rigid"), Setting::NoWall],
        ));
    }
    if !s.external().is_none() {
        return Err(unsupported(
            "the averaged model has no external forces (its swimmers are force-free); the microscopic and rigid-stroke models take them",
            &[Setting::Model("micro"), Setting::Model("rigid")],
        ));
    }
    Ok(())
}

impl SwimmerModel for StrokeAveraged {
    fn choice(&self) -> Model {
        Model::Averaged
    }

    /// ℓ: the swimmers are stroke-averaged (the contact guard and steric repulsion use ℓ too).
    fn contact_length(&self, d: &Dumbbell, _t: f64) -> f64 {
        d.ell
    }

    fn stroke_averaged(&self) -> bool {
        true
    }

    fn system(&self, s: &dyn SceneView) -> Result<Box<dyn OdeSystem>> {
        check_identical(s.swimmers())?;
        check_open(s)?;
        let mut sys = AveragedSystem::new(s.swimmers(), s.base(), s.coefficients(), s.state());
        let periodic = s.boundary().periodic();
        sys.set_cutoff(cutoff_in(periodic, s.cutoff())?);
        sys.set_periodic(periodic.copied());
        sys.set_contacts(s.contacts(), s.mu());
        sys.set_thermal(s.thermal(), s.swimmers(), s.mu(), s.mobility())?;
        Ok(Box::new(sys))
    }

    fn tension(&self, _s: &dyn SceneView, i: usize) -> Result<f64> {
        Err(unsupported(
            format!("tension({i}) does not exist in the averaged model (it has no springs)"),
            &[Setting::Model("micro"), Setting::Model("rigid")],
        ))
    }

    fn ewald_method(&self, _set: EwaldMethod) -> Option<EwaldMethod> {
        None
    }

    /// A suspension's cutoff set to half the box, which leaves its neighbour lists no skin
    /// (every right-hand side rebuilds them).
    fn cost_notices(&self, s: &dyn SceneView) -> Vec<(&'static str, EngineError)> {
        let mut out = Vec::new();
        let count = s.swimmers().len();
        if let (Some(b), Some(c)) = (s.boundary().periodic(), s.cutoff()) {
            let half = 0.5 * b.shortest();
            if count >= LIST_SWIMMERS && c >= half {
                out.push((
                    "cutoff without skin",
                    unsupported(
                        format!(
                            "this run will cost far more than its length suggests: the cutoff {c:e} m reaches half the box's shortest side, which leaves the neighbour lists of its {count} swimmers no skin (pairs within the cutoff plus {:.0}% of it must meet one image), so every right-hand side rebuilds them; the box's default cutoff, {:.4e} m, keeps the skin, and the pairs it leaves out change the rates by far less than a suspension's tolerance",
                            100.0 * DEFAULT_SKIN_OF_CUTOFF,
                            half / (1.0 + DEFAULT_SKIN_OF_CUTOFF)
                        ),
                        &[Setting::NoCutoff],
                    ),
                ));
            }
        }
        out
    }

    /// For a suspension `suspension(tol)` at [`DEFAULT_SUSPENSION_TOL`], else dopri5, whose steps
    /// grow to a good fraction of a period (the averaged model is not stiff).
    fn default_integrator(&self, s: &dyn SceneView) -> IntegratorSpec {
        if s.crowded() {
            IntegratorSpec::Suspension {
                tol: DEFAULT_SUSPENSION_TOL,
            }
        } else {
            IntegratorSpec::Dopri5 {
                rtol: DEFAULT_AVERAGED_RTOL,
            }
        }
    }

    /// Euler-Maruyama at 1/20 of the shortest period (no stroke inside a period to resolve).
    fn default_noisy_integrator(&self, s: &dyn SceneView) -> IntegratorSpec {
        noisy_euler(s.facts().shortest_period / 20.0)
    }

    /// dopri5 a hundred times tighter than `tol`, never looser than its default.
    fn auto_direct(&self, tol: f64) -> Option<(IntegratorSpec, String)> {
        let rtol = (tol * 1e-2).clamp(1e-13, DEFAULT_AVERAGED_RTOL);
        Some((
            IntegratorSpec::Dopri5 { rtol },
            "the averaged model is not stiff: dopri5 at a hundredth of tol, never looser than its default".into(),
        ))
    }

    /// The suspension stepper is this model's; stroboscopic averaging is not (it is averaged
    /// already).
    fn check_integrator(&self, spec: IntegratorSpec) -> Result<()> {
        match spec {
            IntegratorSpec::Stroboscopic { .. } => Err(unsupported(
                "stroboscopic averaging is for the spring and rigid-stroke models: the averaged model is averaged already",
                &[Setting::Model("micro"), Setting::Model("rigid"), Setting::DefaultIntegrator],
            )),
            _ => Ok(()),
        }
    }

    fn refuses_platen(&self, spec: IntegratorSpec) -> Option<EngineError> {
        Some(unsupported(
            format!("{spec} needs the diffusion matrix at shifted states, and the averaged model turns its orientations on the unit sphere instead"),
            &[Setting::NoiseIntegrator, Setting::DefaultIntegrator],
        ))
    }

    fn device_kernel(&self) -> std::result::Result<DeviceKernel, (&'static str, &'static str)> {
        Ok(DeviceKernel::Averaged)
    }

    /// Its cost grows with the swimmers: it has no spheres to move.
    fn bodies(&self) -> (usize, &'static str) {
        (1, "swimmers")
    }
}
