//! Numerical stroboscopic averaging (after Calvo, Chartier, Murua & Sanz-Serna, "Numerical
//! stroboscopic averaging for ODEs and DAEs", Appl. Numer. Math. 61 (2011) 1077).
//!
//! A T-periodically forced system moves slowly from one period to the next: its stroboscopic map
//! Ψ: y(t) → y(t + T) is close to the identity. Short microscopic runs of whole periods sample Ψ,
//! and a macro integrator takes steps of many periods on the smooth flow those samples define.
//!
//! - **Slope.** The slope F(y) of the averaged flow at y is read off consecutive stroboscopic
//!   points y, Ψ(y), …, Ψ^d(y): the derivative at s = 0 of the polynomial through them at
//!   s = 0 … d periods (order d in T). The degree d (2 … [`MAX_DEGREE`]) is chosen at the start
//!   and at every step's end by comparing slopes of neighbouring degrees from the same points:
//!   the lowest whose error so estimated takes at most a tenth of the tolerance: a fixed low degree
//!   would leave close pairs with an error floor, its polynomial's truncation, whatever the
//!   tolerance (the book's design notes). A stage state y + H Σ a_j k_j is extrapolated
//!   from the step's start; its fast variables (the springs' lengths,
//!   [`OdeSystem::fast_variables`]) are extrapolated instead by their rates on the slow
//!   manifold (the derivative at 0 through their values at Ψ … Ψ^d of each earlier stage), which
//!   nothing left to relax pollutes. So a stage state lies next to the manifold, the fast motion has next to nothing
//!   to relax, and the macro flow is not stiff. Extrapolated with the slope itself, a spring's
//!   length would carry its own relaxation (a stiff mode under steps of many periods); left
//!   alone, an extrapolated turn stretches a dumbbell by ~ℓθ²/2 and the next stage fails the
//!   guards; set to the start state's length, a close pair errs many times more
//!   (tests/stroboscopic.rs; the factor is in the book's design notes).
//! - **Macro steps.** Dormand-Prince 5(4) (first-same-as-last: six new slopes a step) in whole
//!   periods, H = mT, so every macro state is a stroboscopic state of the same phase; every
//!   stage's Ψ starts at the step's own time. Fifth order rather than Bogacki-Shampine's third:
//!   at the same tolerance its steps span several times as many periods, so a step's samples
//!   (6d periods) buy more of them (the book's design notes). The error
//!   estimate is measured against the change the step makes (each 3-vector
//!   against the largest change of its kind among all swimmers: positions, or orientations, whose
//!   error turns the drift and so counts against the positions' change as well; orientations
//!   are measured across themselves, since along them lies a spring's length, a fast variable),
//!   not against absolute positions: `tol` is relative to the drift. A per-period round-off allowance
//!   keeps components that do not move from demanding the impossible.
//! - **Closing step.** A step that ends the run is first tried by Heun's method with Euler's
//!   embedded estimate: one new slope instead of six. A slow motion over a short run (a pair over
//!   100 periods changes its slope by far less than the tolerance) takes it; a rejection costs
//!   that one slope, Dormand-Prince takes the step as before where it would save at least as
//!   many periods as it samples (else the rest is integrated directly: a rejection would waste
//!   all its samples), and Heun is not tried again until the next start (a motion too fast for
//!   it once is rarely slow enough later in the run).
//! - **Direct runs.** The start transient (whenever the state is not the one this stepper left:
//!   a fresh run, a changed phase, a loaded scene), a remainder of less than [`MIN_MACRO`] periods
//!   and the fraction of a period before `t_end` are integrated by the inner (microscopic)
//!   integrator itself, so a row between period multiples is a true microscopic state; so are
//!   stretches where macro steps fail at their shortest or would be too short to pay for their
//!   samples (a step spans at least the 6d periods it samples), counted in [`Stats`] and
//!   told, with why, by [`Stepper::report`].
//!
//! Files: `stepper.rs` (the stepper, direct runs and the macro step loop), `samples.rs` (the
//! stroboscopic points and the slopes read off them, the degree chosen), `macro_step.rs` (one
//! macro step and its error norm).
//!
//! [`MAX_DEGREE`]: samples::MAX_DEGREE
//! [`MIN_MACRO`]: stepper::MIN_MACRO
//! [`OdeSystem::fast_variables`]: super::OdeSystem::fast_variables
//! [`Stats`]: super::Stats
//! [`Stepper::report`]: super::Stepper::report

mod macro_step;
mod samples;
mod stepper;

pub use stepper::{Stroboscopic, MIN_MACRO};
