//! Time integrators behind one interface: a [`Stepper`] advances an [`OdeSystem`] by one step.
//!
//! Fixed-step methods ([`Euler`], [`Rk4`]) split a run into equal steps no longer than `dt` so that a
//! run of any duration lands exactly on its end time. The adaptive [`Dopri5`] controls the error
//! per component against [`OdeSystem::error_scale`], which the models set to the size of the slow
//! drift rather than of the absolute positions (see `engine::micro`). The adaptive steppers
//! ([`Dopri5`], [`Rosenbrock`], [`Suspension`]) supply their attempt and error estimate; one
//! controller (`controller.rs`) accepts or rejects it and chooses the next step. With thermal noise on
//! ([`OdeSystem::noise`]), [`Euler`] is Euler-Maruyama and [`Platen`] a weak second-order scheme;
//! their noise comes from a counter-based generator ([`StepDraws`]).

mod controller;
mod dopri5;
mod euler;
mod philox;
mod policy;
mod rk4;
mod rosenbrock;
mod sde;
mod spec;
mod stroboscopic;
mod suspension;
mod system;

pub use dopri5::Dopri5;
/// The Dormand-Prince 5(4) tableau: stage times, stage matrix (last row: the solution), error weights.
pub use dopri5::{A as DOPRI5_A, C as DOPRI5_C, E as DOPRI5_E};
pub use euler::Euler;
pub use philox::StepDraws;
pub use policy::{
    auto_choice, check_noise, noisy_euler, Facts, CHOLESKY_LIMIT_SPHERES, DEFAULT_AUTO_TOL,
    DEFAULT_AVERAGED_RTOL, DEFAULT_MICRO_MAX_STEP_PER_PERIOD, DEFAULT_MICRO_STEP_TIMES_RATE,
    DEFAULT_NOISY_STEP_TIMES_RATE, DEFAULT_RIGID_RTOL, DEFAULT_SUSPENSION_TOL, PLATEN_MAX_SWIMMERS,
    RK4_DEFAULT_DRIFT_ERROR, RK4_STABLE_STEP_RATE, STIFF_STEPS_PER_PERIOD,
};
pub use rk4::Rk4;
pub use rosenbrock::Rosenbrock;
pub use sde::Platen;
pub use spec::{check_tolerance, Direct, Horizon, IntegratorSpec, Method, METHODS, MIN_DRIFT_TOL};
pub use stroboscopic::{Stroboscopic, MIN_MACRO};
pub use suspension::Suspension;
pub use system::{
    require_resolvable, time_scale_of, uniform_steps, ErrorMeasure, GroupJacobian, Interrupt,
    Noise, OdeSystem, Partitioned, Problem, Reach, StateWatch, Stats, StepFailure, Stepper,
    MIN_RELATIVE_INTERVAL,
};
