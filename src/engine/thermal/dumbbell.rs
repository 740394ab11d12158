//! The diffusion of a rigid dumbbell: two spheres a fixed distance apart, moved through the
//! two-sphere mobility (RPY or Oseen) as one rigid body. The averaged model's swimmers diffuse so.

use crate::engine::error::{invalid, Result};
use crate::engine::mobility::{self_mobility, Mobility};
use crate::engine::swimmer::Dumbbell;

/// Translational and rotational diffusion coefficients of a rigid dumbbell, and the point on its
/// axis about which translation and rotation decouple.
///
/// Along the axis (from the a1 sphere to the a2 sphere, R_H at 0) the spheres sit at z₁ = −w2·L
/// and z₂ = w1·L. With m_α = 1/(6πμa_α) and the pair's coupling c (c_I + c_rr along the axis, c_I
/// across it), each direction's 2×2 sphere mobility is [[m₁, c], [c, m₂]]; the friction of a
/// translation is 1ᵀM⁻¹1 and that of a rotation about z_c is rᵀM⁻¹r, r = (z₁ − z_c, z₂ − z_c).
/// At z_c = ((m₂ − c)z₁ + (m₁ − c)z₂)/(m₁ + m₂ − 2c), the centre of mobility, the forces of a
/// translation exert no torque, so translation and rotation are independent there. Without the
/// pair coupling (c = 0) z_c is R_H, the centre of friction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidDiffusion {
    /// D_∥: translation along the axis (m²/s).
    pub parallel: f64,
    /// D_⊥: translation across the axis (m²/s).
    pub perpendicular: f64,
    /// D_r: rotation of the axis (1/s).
    pub rotation: f64,
    /// z_c: the centre of mobility's position along N from R_H (m).
    pub offset: f64,
}

impl RigidDiffusion {
    /// The coefficients of dumbbell `d` held at length `length` in fluid of viscosity `mu` at
    /// thermal energy `kt` (J).
    pub fn new(d: &Dumbbell, length: f64, mu: f64, mobility: Mobility, kt: f64) -> Result<Self> {
        let (m1, m2) = (self_mobility(mu, d.a1), self_mobility(mu, d.a2));
        let (ci, crr) = mobility.pair_coefficients(mu, length, d.a1, d.a2);
        let (z1, z2) = (-d.w2() * length, d.w1() * length);
        let friction = |c: f64, r1: f64, r2: f64| {
            let det = m1 * m2 - c * c;
            (det > 0.0).then(|| (m2 * r1 * r1 - 2.0 * c * r1 * r2 + m1 * r2 * r2) / det)
        };
        let not_positive = || {
            invalid!(
                "the dumbbell's two-sphere mobility is not positive definite at length {length:e} m (spheres of radii {:e} and {:e} m); use the rpy mobility",
                d.a1,
                d.a2
            )
        };
        let along = friction(ci + crr, 1.0, 1.0).ok_or_else(not_positive)?;
        let across = friction(ci, 1.0, 1.0).ok_or_else(not_positive)?;
        let zc = ((m2 - ci) * z1 + (m1 - ci) * z2) / (m1 + m2 - 2.0 * ci);
        let turn = friction(ci, z1 - zc, z2 - zc).ok_or_else(not_positive)?;
        Ok(RigidDiffusion {
            parallel: kt / along,
            perpendicular: kt / across,
            rotation: kt / turn,
            offset: zc,
        })
    }

    /// The orientation-averaged translational coefficient (D_∥ + 2D_⊥)/3 (m²/s): a centre's mean
    /// squared displacement grows as 6 D_t t.
    pub fn translation(&self) -> f64 {
        (self.parallel + 2.0 * self.perpendicular) / 3.0
    }
}
