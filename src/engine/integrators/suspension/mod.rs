//! `suspension(tol)`: ROS34PW2 (Rang & Angermann's Rosenbrock-W method of [`super::Rosenbrock`],
//! order 3 with an embedded order 2, L-stable) made linearly implicit in the system's sparse stiff
//! part alone ([`OdeSystem::stiff_groups`]: in a suspension the steric contacts, a few small
//! clusters) and explicit in the rest, with the system's own error norm
//! ([`OdeSystem::step_error_norm`]: each swimmer's error against its own displacement over the
//! step).
//!
//! Why this method for suspensions: the far field moves a swimmer by ~1e-4ℓ a period and changes
//! over hundreds of periods, while a steric contact relaxes at k/(6πμa) ~ 700/s, nine times a
//! period. An explicit method is held to a step within its stability bound of that rate however
//! slow the motion; a W-method keeps its order with any matrix in place of the Jacobian, so the
//! contacts' own blocks (dense LU per cluster) remove that bound while everything else stays
//! explicit and costs what an explicit stage costs. The error norm then lets the step follow the
//! slow far field: a tolerance relative to each swimmer's displacement is what a suspension's
//! structure is made of, where the default error scale of the averaged model (the closest pair's
//! drift a period) would hold every swimmer to the slowest pair's precision.
//!
//! Individual steps. A close pair or a contact sliding over the kink of the repulsion's force
//! law moves on a time scale of a period or less, while the rest of the suspension could take
//! steps of many periods. A step is therefore taken for every swimmer and judged swimmer by
//! swimmer ([`Partitioned::body_errors`]): when a few swimmers (at most [`MAX_REFINED_FRACTION`]
//! of them, each within [`MAX_REFINED_ERROR`] of the tolerance) miss it and the rest meet it,
//! the rest keep their step, and those few, with every swimmer in contact with them, are stepped
//! again across the same interval by the same method with steps of their own (adaptive, at
//! most [`MAX_SUBSTEPS`]), reading the other swimmers' states from the coarse step (quadratic
//! through its start, its end and its starting rates; their error is within the tolerance).
//! Groups of refined swimmers that read none of each other's states are stepped apart, on
//! rayon's threads when the system can give rates without changing (its neighbour lists still
//! hold the swimmers read). What the few did wrong in the coarse step reaches the rest only
//! through the far field: the neighbours whose rates change, when they read the refined path
//! instead of the coarse one, by more than [`RING_SHARE`] of the tolerance (or by more than
//! their own error leaves to it) are stepped again reading the refined path (the *ring*); a
//! contact forming between the few and the rest during the interval grows the few instead.
//! (Savcenco, Hundsdorfer & Verwer, BIT 47 (2007) 137, refine a coarse step the same way.)
//!
//! Stage equations (with k including the factor h; autonomous systems skip ∂f/∂t):
//! (I − hγJ) kᵢ = h f(t + cᵢh, y + Σⱼ aᵢⱼ kⱼ) + hJ Σⱼ γᵢⱼ kⱼ + h² γ̂ᵢ ∂f/∂t, y₁ = y + Σ bᵢ kᵢ.
//!
//! Files: `stepper.rs` (the stepper and its attempt for the controller), `stages.rs` (the
//! W-method's stages, whole or for a subset), `judge.rs` (the coarse step judged swimmer by
//! swimmer), `refine.rs` (refining the few), `ring.rs` (the neighbours stepped again),
//! `scratch.rs` (the buffers and what a step's rounds keep).
//!
//! [`OdeSystem::stiff_groups`]: super::OdeSystem::stiff_groups
//! [`OdeSystem::step_error_norm`]: super::OdeSystem::step_error_norm
//! [`Partitioned::body_errors`]: super::Partitioned::body_errors
//! [`MAX_REFINED_FRACTION`]: judge::MAX_REFINED_FRACTION
//! [`MAX_SUBSTEPS`]: refine::MAX_SUBSTEPS
//! [`RING_SHARE`]: ring::RING_SHARE

mod judge;
mod refine;
mod ring;
mod scratch;
mod stages;
mod stepper;

pub use stepper::Suspension;
