//! Which equations move the scene, the layout of their state vector, and the seam every model
//! answers through ([`SwimmerModel`], reading its scene through [`SceneView`]).
//!
//! Both models keep 6 numbers per swimmer σ at `y[6σ..6σ+6]`:
//! - `y[6σ..6σ+3]`: the displacement ΔR of the hydrodynamic centre from its *base* position (kept
//!   apart in the scene). The net drift per period is ~1e-7 ℓ at D = 10ℓ; adding it to an absolute
//!   position of size ~10ℓ every step would round it at ~1e-15·10ℓ per step, a systematic error of up to
//!   1e-4 of the drift over a period of ~1,000 steps. A displacement stays small and rounds far below.
//! - `y[6σ+3..6σ+6]`: the microscopic model's dumbbell vector b = X₂ − X₁ (m); the averaged model's
//!   unit orientation N, and so the rigid-stroke model's (whose length is L(t)).

use super::boundary::Boundary;
use super::choice::{self, Choice, Named};
use super::contacts::Contacts;
use super::error::{invalid, unsupported, EngineError, Result, Setting};
use super::ewald::EwaldMethod;
use super::forces::ExternalForces;
use super::integrators::{Facts, IntegratorSpec, OdeSystem, Reach};
use super::mobility::{Mobility, MobilityOperator};
use super::swimmer::Dumbbell;
use super::thermal::{NoiseRoot, Thermal};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Water at room temperature (Pa s), the paper's μ.
pub const DEFAULT_MU: f64 = 1e-3;

/// Numbers per swimmer in the state vector.
pub const STATE_PER_SWIMMER: usize = 6;

/// The model that moves a scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Model {
    /// All spheres, springs and the full mobility (e:langevin).
    #[default]
    Micro,
    /// Stroke-averaged R_H and N per swimmer (e:eom … e:eom_last).
    Averaged,
    /// The microscopic model in the rigid-stroke limit k0 → ∞: lengths follow L(t) exactly.
    Rigid,
}

impl Named for Model {
    const KIND: &'static str = "model";
    const CHOICES: &'static [Choice<Self>] = &[
        Choice {
            value: Model::Micro,
            name: "micro",
            about: "spheres and springs, default",
        },
        Choice {
            value: Model::Rigid,
            name: "rigid",
            about: "spheres, lengths prescribed",
        },
        Choice {
            value: Model::Averaged,
            name: "averaged",
            about: "stroke-averaged R_H and N",
        },
    ];
}

choice::inherent_names!(Model);

/// Coefficients of the averaged model's I and J terms.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Coefficients {
    /// Eqs. e:eom … e:eom_last exactly as published: I weighted by (a2²−a1²)/(a1²+a2²).
    #[default]
    Paper,
    /// Leading order (Oseen, shape-driven, far field): I weighted by (a2−a1)/(a1+a2), J by 4a1a2/(a1+a2)².
    LeadingOrder,
}

impl Named for Coefficients {
    const KIND: &'static str = "coefficient set";
    const CHOICES: &'static [Choice<Self>] = &[
        Choice {
            value: Coefficients::Paper,
            name: "paper",
            about: "as published, default",
        },
        Choice {
            value: Coefficients::LeadingOrder,
            name: "leading_order",
            about: "the leading-order ones",
        },
    ];
}

choice::inherent_names!(Coefficients);

/// The 3-vector at `y[i..i+3]`.
#[inline]
pub fn vec3(y: &[f64], i: usize) -> Vector3<f64> {
    Vector3::new(y[i], y[i + 1], y[i + 2])
}

/// Write a 3-vector to `y[i..i+3]`.
#[inline]
pub fn set_vec3(y: &mut [f64], i: usize, v: &Vector3<f64>) {
    y[i..i + 3].copy_from_slice(v.as_slice());
}

/// Spheres per swimmer in the models' sphere layout: every model moves dumbbells, sphere 2σ the
/// a1 sphere of swimmer σ and 2σ + 1 its a2 sphere.
pub const SPHERES_PER_SWIMMER: usize = 2;

/// The device kernels a model runs on: the spring model's sphere rates, or the averaged model's
/// pair terms.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DeviceKernel {
    /// Spheres and springs.
    Springs,
    /// Stroke-averaged R_H and N.
    Averaged,
}

/// What a model reads of the scene it moves: its swimmers and state, the fluid and its
/// boundary, the numerics. The scene implements it; the models see no more of it.
pub trait SceneView {
    /// The swimmers' parameters.
    fn swimmers(&self) -> &[Dumbbell];
    /// The base positions the state's displacements are measured from (m).
    fn base(&self) -> &[Vector3<f64>];
    /// The state vector (see the layout above).
    fn state(&self) -> &[f64];
    /// The current time (s).
    fn time(&self) -> f64;
    /// Viscosity μ (Pa s).
    fn mu(&self) -> f64;
    /// The pair tensor.
    fn mobility(&self) -> Mobility;
    /// The averaged model's coefficient set.
    fn coefficients(&self) -> Coefficients;
    /// Overlaps and steric repulsion between swimmers.
    fn contacts(&self) -> Contacts;
    /// Temperature and noise seed.
    fn thermal(&self) -> Thermal;
    /// The boundary of the fluid.
    fn boundary(&self) -> &Boundary;
    /// The far-field cutoff set (m), if any.
    fn cutoff(&self) -> Option<f64>;
    /// The external forces.
    fn external(&self) -> ExternalForces;
    /// How far the centres may go.
    fn reach(&self) -> Reach;
    /// The boundary's mobility operator with a box's products by `method`.
    fn mobility_operator_by(&self, method: EwaldMethod) -> Result<Box<dyn MobilityOperator>>;
    /// The Ewald method the scene sets.
    fn ewald_method(&self) -> EwaldMethod;
    /// What the integrator policy reads.
    fn facts(&self) -> Facts;
    /// The integrator the scene runs (set, or the model's default).
    fn integrator(&self) -> IntegratorSpec;
    /// Whether the gpu backend is chosen.
    fn on_gpu(&self) -> bool;
    /// Whether the scene is crowded: a periodic box, a cutoff, steric repulsion or many swimmers
    /// (a crowded scene of the averaged model is a suspension).
    fn crowded(&self) -> bool;

    /// The external force on every sphere in sphere order (empty when there is none).
    fn sphere_forces(&self) -> Vec<Vector3<f64>> {
        self.external()
            .per_sphere(self.swimmers().iter().flat_map(|d| [d.a1, d.a2]))
    }
}

/// A model of the swimmers: what its state holds and where that puts the spheres, its
/// right-hand side, the integrators it takes and what the device runs of it. [`Model`] stays the
/// user's choice; `engine::models` maps each choice to its implementation in one place.
///
/// The provided methods are those of the models whose state holds the unit orientation N (the
/// rigid-stroke and averaged models); the spring model, whose state holds the dumbbell vector,
/// overrides them.
pub trait SwimmerModel: Sync {
    /// The user's choice this model answers for.
    fn choice(&self) -> Model;

    /// Spheres per swimmer.
    fn spheres_per_swimmer(&self) -> usize {
        SPHERES_PER_SWIMMER
    }

    // ----- the state -------------------------------------------------------------------------

    /// The state's vector part of a new swimmer with unit orientation `n` at rest length `len`.
    fn initial_vector(&self, n: &Vector3<f64>, _len: f64) -> Vector3<f64> {
        *n
    }

    /// The state's vector part of a swimmer whose vector in another model's state is `v`, at
    /// rest length `len` (a model switched).
    fn converted_vector(&self, v: &Vector3<f64>, _len: f64) -> Vector3<f64> {
        v.normalize()
    }

    /// Swimmer `i`'s vector `v` as a file gives it, or the error saying what is wrong with it.
    fn check_vector(&self, i: usize, v: &Vector3<f64>) -> Result<()> {
        let len = v.norm();
        if (len - 1.0).abs() > 1e-9 {
            return Err(invalid!(
                "swimmer {i}: its orientation N has length {len}, not 1; in the {} model the state holds the unit vector N",
                self.choice().name()
            ));
        }
        Ok(())
    }

    /// The length at which swimmer `d`'s spheres sit at time `t` (contacts, placement).
    fn contact_length(&self, d: &Dumbbell, t: f64) -> f64 {
        d.rest_length(t)
    }

    /// The length |X₂ − X₁| of swimmer `d` with state vector `v` at time `t` (m).
    fn length(&self, d: &Dumbbell, _v: &Vector3<f64>, t: f64) -> f64 {
        d.rest_length(t)
    }

    /// The sphere centres (X₁, X₂) of swimmer `d` with centre `rh` and state vector `v` at
    /// time `t`.
    fn sphere_positions(
        &self,
        d: &Dumbbell,
        rh: Vector3<f64>,
        v: Vector3<f64>,
        t: f64,
    ) -> (Vector3<f64>, Vector3<f64>) {
        d.sphere_positions(rh, v, self.contact_length(d, t))
    }

    /// The swimmer's spin dN/dt (1/s) from its state vector `v` and that vector's rate `w`.
    fn spin(&self, _v: &Vector3<f64>, w: Vector3<f64>) -> Vector3<f64> {
        w
    }

    /// Whether the state is stroke-averaged: dR_H/dt is then the swimming velocity itself, and
    /// a state never lies off the stroke's cycle.
    fn stroke_averaged(&self) -> bool {
        false
    }

    // ----- the dynamics ----------------------------------------------------------------------

    /// The right-hand side for the scene `s` as it is now.
    fn system(&self, s: &dyn SceneView) -> Result<Box<dyn OdeSystem>>;

    /// The tension of swimmer `i` (N), positive when it pulls the spheres together.
    fn tension(&self, s: &dyn SceneView, i: usize) -> Result<f64>;

    /// How the model's mobility products of a box are summed, the scene setting `set`; `None`
    /// where the model takes no Ewald sums.
    fn ewald_method(&self, set: EwaldMethod) -> Option<EwaldMethod> {
        Some(set)
    }

    /// What makes the next run of `s` far costlier than its length suggests, in the model's
    /// own terms (the scene adds the boundary's).
    fn cost_notices(&self, _s: &dyn SceneView) -> Vec<(&'static str, EngineError)> {
        Vec::new()
    }

    // ----- the integrators -------------------------------------------------------------------

    /// The model's default integrator for `s` without thermal noise.
    fn default_integrator(&self, s: &dyn SceneView) -> IntegratorSpec;

    /// The model's default integrator for `s` with thermal noise.
    fn default_noisy_integrator(&self, s: &dyn SceneView) -> IntegratorSpec;

    /// The method `auto(tol)` runs directly instead of stroboscopic averaging, and why, where the
    /// model has one.
    fn auto_direct(&self, _tol: f64) -> Option<(IntegratorSpec, String)> {
        None
    }

    /// Stroboscopic averaging's inner integrator when none is named.
    fn stroboscopic_inner(&self, s: &dyn SceneView, tol: f64) -> IntegratorSpec {
        s.facts().rk4_inner(tol)
    }

    /// Periods stroboscopic averaging over `period` integrates directly after a start, for the
    /// model's fast variables to settle.
    fn settling_periods(&self, _s: &dyn SceneView, _period: f64) -> u32 {
        0
    }

    /// What the model refuses of integrator `spec` whatever the noise: the suspension stepper
    /// outside the averaged model, stroboscopic averaging inside it.
    fn check_integrator(&self, spec: IntegratorSpec) -> Result<()> {
        match spec {
            IntegratorSpec::Suspension { .. } => Err(unsupported(
                format!("{spec} is the averaged model's method for suspensions: the {} model's springs or strokes have no steric-contact structure for it to use", self.choice().name()),
                &[Setting::Model("averaged"), Setting::DefaultIntegrator],
            )),
            _ => Ok(()),
        }
    }

    /// The model's refusal of thermal noise at `temperature` (K), if it takes none.
    fn refuses_noise(&self, _temperature: f64) -> Option<EngineError> {
        None
    }

    /// The model's refusal of Platen's scheme `spec` under noise, if it has no diffusion
    /// matrix for it.
    fn refuses_platen(&self, _spec: IntegratorSpec) -> Option<EngineError> {
        None
    }

    /// The spheres whose mobility the noise of `swimmers` swimmers factors densely by `root`'s
    /// choice, if the model's noise does.
    fn dense_noise_spheres(&self, _root: NoiseRoot, _swimmers: usize) -> Option<usize> {
        None
    }

    // ----- the device --------------------------------------------------------------------------

    /// The device kernels the model runs on, or who lacks them and why (in words for "… runs
    /// on the CPU only (why)").
    fn device_kernel(&self) -> std::result::Result<DeviceKernel, (&'static str, &'static str)>;

    /// What the model's cost grows with, per swimmer, and its name: spheres, or swimmers.
    fn bodies(&self) -> (usize, &'static str) {
        (self.spheres_per_swimmer(), "spheres")
    }
}
