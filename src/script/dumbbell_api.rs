//! `dumbbell(#{...})`: a swimmer's parameters and pose, before it is added to a scene.

use super::convert::{array3, number, script_error, unknown_choice, vector3, ScriptResult};
use super::doc::{doc_entry, Doc};
use crate::engine::swimmer::unit_direction;
use crate::engine::Dumbbell;
use nalgebra::Vector3;
use rhai::{Engine, Map};

/// The keys `dumbbell(#{...})` accepts.
pub const KEYS: [&str; 9] = [
    "a1", "a2", "ell", "lambda", "omega", "k0", "phase", "center", "dir",
];

/// A swimmer description: parameters plus where to put it (Rhai type `Dumbbell`).
#[derive(Debug, Clone, PartialEq)]
pub struct DumbbellSpec {
    /// Parameters (SI).
    pub params: Dumbbell,
    /// Hydrodynamic centre (m).
    pub center: Vector3<f64>,
    /// Orientation (normalised on use).
    pub dir: Vector3<f64>,
}

impl Default for DumbbellSpec {
    fn default() -> Self {
        DumbbellSpec {
            params: Dumbbell::default(),
            center: Vector3::zeros(),
            dir: Vector3::x(),
        }
    }
}

impl DumbbellSpec {
    /// Build from a map; every key optional, unknown keys rejected, parameters validated.
    pub fn from_map(map: &Map) -> ScriptResult<Self> {
        let mut spec = DumbbellSpec::default();
        for (key, value) in map {
            let p = &mut spec.params;
            let what = format!("dumbbell key `{key}`");
            match key.as_str() {
                "a1" => p.a1 = number(&what, value)?,
                "a2" => p.a2 = number(&what, value)?,
                "ell" => p.ell = number(&what, value)?,
                "lambda" => p.lambda = number(&what, value)?,
                "omega" => p.omega = number(&what, value)?,
                "k0" => p.k0 = number(&what, value)?,
                "phase" => p.phase = number(&what, value)?,
                "center" => spec.center = vector3(&what, value)?,
                "dir" => spec.dir = vector3(&what, value)?,
                other => return Err(unknown_choice("dumbbell key", other, &KEYS)),
            }
        }
        spec.params
            .validate()
            .map_err(super::convert::from_engine)?;
        unit_direction(spec.dir).map_err(super::convert::from_engine)?;
        if spec.center.iter().any(|c| !c.is_finite()) {
            return Err(script_error("center must have finite components"));
        }
        Ok(spec)
    }
}

impl std::fmt::Display for DumbbellSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let p = &self.params;
        write!(
            f,
            "dumbbell(a1 = {:e} m, a2 = {:e} m, ell = {:e} m, lambda = {:e} m, omega = {} 1/s, k0 = {:e} kg/s^2, phase = {} rad, center = [{:e}, {:e}, {:e}] m, dir = [{}, {}, {}])",
            p.a1, p.a2, p.ell, p.lambda, p.omega, p.k0, p.phase,
            self.center.x, self.center.y, self.center.z, self.dir.x, self.dir.y, self.dir.z
        )
    }
}

/// Register the `Dumbbell` type and `dumbbell(...)`.
pub fn register(engine: &mut Engine) {
    engine
        .register_fn("dumbbell", |m: Map| DumbbellSpec::from_map(&m))
        .register_fn("dumbbell", DumbbellSpec::default)
        .register_fn("phase", |x: rhai::Dynamic| -> ScriptResult<f64> {
            Ok(super::convert::number("phase(x)", &x)?.rem_euclid(std::f64::consts::TAU))
        })
        .register_fn("phase_deg", |x: rhai::Dynamic| -> ScriptResult<f64> {
            Ok(super::convert::number("phase_deg(x)", &x)?
                .to_radians()
                .rem_euclid(std::f64::consts::TAU))
        })
        .register_get("a1", |d: &mut DumbbellSpec| d.params.a1)
        .register_get("a2", |d: &mut DumbbellSpec| d.params.a2)
        .register_get("ell", |d: &mut DumbbellSpec| d.params.ell)
        .register_get("lambda", |d: &mut DumbbellSpec| d.params.lambda)
        .register_get("omega", |d: &mut DumbbellSpec| d.params.omega)
        .register_get("k0", |d: &mut DumbbellSpec| d.params.k0)
        .register_get("phase", |d: &mut DumbbellSpec| d.params.phase)
        .register_get("center", |d: &mut DumbbellSpec| array3(&d.center))
        .register_get("dir", |d: &mut DumbbellSpec| array3(&d.dir));
}

/// The help text of this file's script names (`:help NAME`), gathered by [`super::docs`].
pub(super) const DOCS: &[Doc] = &[
    doc_entry!("dumbbell", "building", "dumbbell() -> Dumbbell\ndumbbell(#{ a1, a2, ell, lambda, omega, k0, phase, center, dir }) -> Dumbbell", "A swimmer description (SI units). Every key is optional; defaults are the paper's symmetric Fig-1 swimmer (a1 = a2 = 0.15 ell, ell = 5e-6 m, lambda = 0.1 ell, omega = 500 1/s, k0 = 1e-3 kg/s^2, phase 0, at the origin, along +x). Unknown keys are errors.", "let d = dumbbell(#{ a1: 1.125e-6, a2: 0.5625e-6, phase: 0.5 }); print(d.a2);"),
    doc_entry!("phase_deg", "phases", "phase_deg(x) -> float", "x degrees as radians in [0, 2 pi).", "print(phase_deg(90));"),
    doc_entry!("a1", "swimmer properties", "d.a1 -> float", "Radius of sphere 1 (m); N points from it to sphere 2.", "print(dumbbell().a1);"),
    doc_entry!("a2", "swimmer properties", "d.a2 -> float", "Radius of sphere 2 (m).", "print(dumbbell(#{ a2: 1e-6 }).a2);"),
    doc_entry!("ell", "swimmer properties", "d.ell -> float", "Mean length (m).", "print(dumbbell().ell);"),
    doc_entry!("lambda", "swimmer properties", "d.lambda -> float", "Stroke amplitude (m).", "print(dumbbell().lambda);"),
    doc_entry!("omega", "swimmer properties", "d.omega -> float", "Angular frequency (1/s).", "print(dumbbell().omega);"),
    doc_entry!("k0", "swimmer properties", "d.k0 -> float", "Spring constant (kg/s^2).", "print(dumbbell().k0);"),
];
