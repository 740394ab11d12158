//! The stroke-averaged model (e:eom … e:eom_last): each swimmer is its hydrodynamic centre R_H and
//! unit orientation N, moved by the pairwise I, J, K, L terms:
//!
//! dR_H^σ/dt = A_R Σ_ρ I^σρ + c_J Σ_ρ J^σρ,   dN^σ/dt = −(1 − N^σN^σᵀ)(A_N Σ_ρ K^σρ + Σ_ρ L^σρ).
//!
//! With the "paper" coefficients A_R = (a2²−a1²)/(a1²+a2²) and c_J = 1; with "leading_order" ones
//! A_R = (a2−a1)/(a1+a2) and c_J = 4a1a2/(a1+a2)². A_N = (a2−a1)/(a1+a2) in both. The terms use
//! the parameters of the swimmer being moved (σ); the model assumes equal ω, λ, ℓ (the scene checks).
//!
//! What a scene does not need is skipped: pairs with sin(φσ−φρ) = 0, the I and K terms of symmetric
//! swimmers, and for an aligned scene the 3D algebra (the 1D reduction e:stroke_averaged).
//!
//! The system's shortcuts, settings and per-swimmer state in `system`; a pair's terms and the
//! rows over all partners in `rows`; the per-swimmer constants, the cutoff's switch and a pair's
//! phase weight in `terms`; the `OdeSystem` (rates, guards, noise, projection) in `ode`; the
//! all-pairs rows in vector lanes in `lanes`; a cutoff's rows over neighbour lists in
//! `list_rows`, and the lists' upkeep, steric forces and contact guard in `listed`; steric
//! contact clusters in `implicit`; the multirate stepper's rates of a subset in `partitioned`.
//! tests/averaged_model.rs compares every shortcut with the general 3D sum.

mod arrays;
mod implicit;
mod lanes;
mod list_rows;
mod listed;
mod model;
mod ode;
mod partitioned;
mod rows;
mod system;
mod terms;

pub use implicit::{CONTACT_MARGIN_OF_RANGE, DISPLACEMENT_FLOOR, MAX_CLUSTER_SWIMMERS};
pub use model::{check_identical, check_open, cutoff_in, StrokeAveraged};
pub use system::{
    AveragedSystem, Shortcuts, DEFAULT_SKIN_OF_CUTOFF, LANE_SWIMMERS, LIST_SWIMMERS,
    PARALLEL_SWIMMERS,
};
pub(crate) use terms::pair_constants;
pub use terms::{CutoffSwitch, CUTOFF_SWITCH_WIDTH};
