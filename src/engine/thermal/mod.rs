//! Thermal noise: the solvent's kicks at temperature T (overdamped Langevin dynamics).
//!
//! The spring model moves every sphere by dX = M F dt + kT (∇·M) dt + √(2kT) B dW with B Bᵀ = M,
//! the full mobility. The RPY tensor (Mazur's form and Zuk et al.'s for overlapping spheres) and
//! the Oseen tensor are divergence-free in open space (∇·M = 0, tested in `tests/thermal.rs`), so
//! no thermal drift term enters. B·ξ comes from a dense Cholesky factor for small scenes and from
//! a matrix-free Lanczos iteration on the pair kernel ([`lanczos`]) for large ones; the averaged
//! model's swimmers diffuse as rigid dumbbells ([`RigidDiffusion`]). The rigid-stroke model
//! refuses noise: a rigid constraint's Brownian motion needs the metric (Fixman) drift, which
//! that model does not carry.
//!
//! A scene's setting in `settings` ([`Thermal`]: temperature, seed, how the noise is rooted,
//! [`NoiseRoot`]); the rigid dumbbell's diffusion in `dumbbell`.

mod dumbbell;
pub mod lanczos;
mod settings;

pub use dumbbell::RigidDiffusion;
pub use settings::{
    NoiseRoot, Thermal, BOLTZMANN, CHOLESKY_MAX_SPHERES, DEFAULT_LANCZOS_TOL, MAX_TEMPERATURE,
};
