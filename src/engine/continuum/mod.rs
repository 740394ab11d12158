//! The kinetic theory of the averaged model: the one-swimmer distribution f_p(x, n, t) of each
//! phase population p in a periodic box, moved by the mean field of the averaged pair terms and
//! by the thermal model's diffusion, solved pseudo-spectrally.
//!
//! ∂_t f_p = −∇·(v_p f_p) − ∇_n·(ṅ_p f_p) + ∇·(D(n)·∇f_p) + D_r ∇_n² f_p,
//!
//! v_p(x, n) = Σ_q sin(φ_p − φ_q) ∫∫ H(|D|) V(D, n, n') f_q(x − D, n') dD dn', likewise ṅ_p with
//! −(1 − nn)T: the pair terms summed over the distribution instead of over particles ([`kernel`]).
//! The pair terms depend on the partner's orientation only through n'n', so the mean field needs
//! only the second moments of f_q; and each carries sin(φ_p − φ_q), so one population alone, or
//! phases spread uniformly (Σ_q sin(φ_p − φ_q) f_q = 0), has no mean-field motion at all.
//!
//! Orientations: Galerkin in the real spherical harmonics to degree L ([`sphere`]), the
//! integrals by a product rule exact for them (no aliasing in n). Space: the box's grid, fields
//! transformed by FFT, the convolution with the kernel's exact transform at each wave vector,
//! products at the grid points, and the 2/3 rule against aliasing. Time: Dormand-Prince 5(4) with
//! error control relative to the structure (the state's deviation from its spatial mean).
//!
//! The spec, its checks, the phase populations and the deposit in `spec`; the pair kernel and
//! its transform in `kernel`; the orientation basis in `sphere`; the mean-field operator and the
//! kinetic ODE in `operator`; the continuum's state and its plain reading in `state`; a continuum
//! built from a scene in `from_scene`; its runs in `solver`; fields, mean fields and Fourier modes
//! in `reading`; prepared states and particles drawn from it in `prepare`; linear stability in
//! `stability`.

mod from_scene;
pub mod kernel;
mod operator;
mod prepare;
mod reading;
mod solver;
mod spec;
pub mod sphere;
mod stability;
mod state;

pub use reading::{fourier_mode, particle_mode, MAX_PARTICLE_MODE};
pub use spec::{
    Closure, ContinuumSpec, Population, WholeOption, MAX_CELLS, MAX_POPULATIONS,
    MIN_CELLS_PER_AXIS, MIN_CORE_IN_LENGTHS, MIN_DEGREE, MIN_TOL,
};
pub use stability::{BaseState, Mode};
pub use state::Continuum;
