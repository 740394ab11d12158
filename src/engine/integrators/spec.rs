//! The user's choice of integrator, as saved with a scene, and the checks every run-like call
//! (a scene's, a continuum's) makes of its tolerance and of its end.

use super::{Dopri5, Euler, Platen, Rk4, Rosenbrock, Stepper};
use crate::engine::error::invalid;
use crate::engine::error::{require_positive, Result};
use serde::{Deserialize, Serialize};
use std::fmt;

/// Which integrator to use and its one parameter.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "method", rename_all = "lowercase")]
pub enum IntegratorSpec {
    /// Forward Euler with maximum step `dt` (s).
    Euler {
        /// Maximum step (s).
        dt: f64,
    },
    /// Classic RK4 with maximum step `dt` (s).
    Rk4 {
        /// Maximum step (s).
        dt: f64,
    },
    /// Adaptive Dormand-Prince 5(4) with relative tolerance `rtol`.
    Dopri5 {
        /// Relative tolerance (of the drift-sized error scale, see the models).
        rtol: f64,
    },
    /// Platen's explicit weak second-order scheme with maximum step `dt` (s) (see
    /// [`super::Platen`]); without thermal noise, Heun's method.
    Platen {
        /// Maximum step (s).
        dt: f64,
    },
    /// Adaptive Rosenbrock-W ROS34PW2 (stiff; implicit in each dumbbell's own dynamics).
    Rosw {
        /// Relative tolerance (as for dopri5).
        rtol: f64,
    },
    /// Stroboscopic averaging (see [`super::Stroboscopic`]): macro steps of many periods on
    /// samples of the stroboscopic map, taken by `inner` (`None`: the model's choice).
    Stroboscopic {
        /// Tolerance relative to the drift.
        tol: f64,
        /// The microscopic integrator that samples the stroboscopic map.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        inner: Option<Direct>,
    },
    /// The cheapest method expected to meet `tol` for the scene at hand, chosen when it runs
    /// (`Scene::auto_choice` says which and why).
    Auto {
        /// Tolerance relative to the drift.
        tol: f64,
    },
    /// ROS34PW2 implicit in the steric contacts alone, with each swimmer's error held to `tol` of
    /// its own displacement over the step (see [`super::Suspension`]): the averaged model's
    /// method for suspensions.
    Suspension {
        /// Tolerance relative to each swimmer's displacement over a step.
        tol: f64,
    },
}

/// A direct method: stroboscopic averaging's inner integrator.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "method", rename_all = "lowercase")]
pub enum Direct {
    /// See [`IntegratorSpec::Euler`].
    Euler {
        /// Maximum step (s).
        dt: f64,
    },
    /// See [`IntegratorSpec::Rk4`].
    Rk4 {
        /// Maximum step (s).
        dt: f64,
    },
    /// See [`IntegratorSpec::Dopri5`].
    Dopri5 {
        /// Relative tolerance.
        rtol: f64,
    },
    /// See [`IntegratorSpec::Rosw`].
    Rosw {
        /// Relative tolerance.
        rtol: f64,
    },
}

impl From<Direct> for IntegratorSpec {
    fn from(d: Direct) -> Self {
        match d {
            Direct::Euler { dt } => IntegratorSpec::Euler { dt },
            Direct::Rk4 { dt } => IntegratorSpec::Rk4 { dt },
            Direct::Dopri5 { rtol } => IntegratorSpec::Dopri5 { rtol },
            Direct::Rosw { rtol } => IntegratorSpec::Rosw { rtol },
        }
    }
}

impl TryFrom<IntegratorSpec> for Direct {
    type Error = crate::engine::error::EngineError;
    fn try_from(s: IntegratorSpec) -> Result<Self> {
        match s {
            IntegratorSpec::Euler { dt } => Ok(Direct::Euler { dt }),
            IntegratorSpec::Rk4 { dt } => Ok(Direct::Rk4 { dt }),
            IntegratorSpec::Dopri5 { rtol } => Ok(Direct::Dopri5 { rtol }),
            IntegratorSpec::Rosw { rtol } => Ok(Direct::Rosw { rtol }),
            IntegratorSpec::Platen { .. } => Err(invalid!(
                "platen(dt) is a scheme for thermal noise, and stroboscopic averaging is deterministic; give a direct inner integrator such as rk4(dt) or dopri5(rtol)"
            )),
            IntegratorSpec::Stroboscopic { .. } | IntegratorSpec::Auto { .. } => Err(invalid!(
                "stroboscopic averaging cannot sample itself; give a direct inner integrator such as rk4(dt) or dopri5(rtol)"
            )),
            IntegratorSpec::Suspension { .. } => Err(invalid!(
                "suspension(tol) is the averaged model's method and stroboscopic averaging is for the spring and rigid models; give a direct inner integrator such as rk4(dt) or dopri5(rtol)"
            )),
        }
    }
}

/// One integrator method as users name it: the name, its one parameter, and a checked
/// constructor. The script's constructors, `Display` and messages read this table.
#[derive(Debug, Clone, Copy)]
pub struct Method {
    /// The name (`rk4`), also the script constructor's.
    pub name: &'static str,
    /// Its parameter (`dt`) and what that is.
    pub parameter: &'static str,
    /// What the parameter means, with its unit.
    pub parameter_about: &'static str,
    /// A few words on the method.
    pub about: &'static str,
    /// The checked constructor.
    pub make: fn(f64) -> Result<IntegratorSpec>,
    /// Steps of exactly the parameter (s) rather than error control: the checks before a run
    /// (the step resolvable at the scene's time, the step count bounded) apply.
    pub fixed_step: bool,
    /// A scheme for thermal noise (the deterministic methods refuse a temperature).
    pub takes_noise: bool,
    /// The GPU backend steps it (`gpu::support::tableau` holds its device tableau).
    pub gpu: bool,
}

const EULER: Method = Method {
    name: "euler",
    parameter: "dt",
    parameter_about: "the step in s",
    about: "forward Euler, fixed step",
    make: IntegratorSpec::euler,
    fixed_step: true,
    takes_noise: true,
    gpu: true,
};

const RK4: Method = Method {
    name: "rk4",
    parameter: "dt",
    parameter_about: "the step in s",
    about: "classic Runge-Kutta, fixed step",
    make: IntegratorSpec::rk4,
    fixed_step: true,
    takes_noise: false,
    gpu: true,
};

const DOPRI5: Method = Method {
    name: "dopri5",
    parameter: "rtol",
    parameter_about: "the relative tolerance",
    about: "adaptive Dormand-Prince 5(4)",
    make: IntegratorSpec::dopri5,
    fixed_step: false,
    takes_noise: false,
    gpu: true,
};

const STROBOSCOPIC: Method = Method {
    name: "stroboscopic",
    parameter: "tol",
    parameter_about: "the tolerance relative to the drift",
    about: "stroboscopic averaging: macro steps of many periods (spring and rigid models)",
    make: IntegratorSpec::stroboscopic,
    fixed_step: false,
    takes_noise: false,
    gpu: false,
};

const AUTO: Method = Method {
    name: "auto",
    parameter: "tol",
    parameter_about: "the tolerance relative to the drift",
    about: "the cheapest method expected to meet tol for the scene (s.integrator_info says which)",
    make: IntegratorSpec::auto,
    fixed_step: false,
    takes_noise: false,
    gpu: false,
};

const SUSPENSION: Method = Method {
    name: "suspension",
    parameter: "tol",
    parameter_about: "the tolerance relative to each swimmer's displacement over a step",
    about: "for suspensions (averaged model): implicit in the steric contacts, each swimmer's error against its own displacement",
    make: IntegratorSpec::suspension,
    fixed_step: false,
    takes_noise: false,
    gpu: false,
};

const PLATEN: Method = Method {
    name: "platen",
    parameter: "dt",
    parameter_about: "the step in s",
    about: "Platen's weak order 2 scheme for thermal noise, fixed step (Heun without noise)",
    make: IntegratorSpec::platen,
    fixed_step: true,
    takes_noise: true,
    gpu: false,
};

const ROSW: Method = Method {
    name: "rosw",
    parameter: "rtol",
    parameter_about: "the relative tolerance",
    about: "adaptive Rosenbrock-W ROS34PW2, for stiff springs",
    make: IntegratorSpec::rosw,
    fixed_step: false,
    takes_noise: false,
    gpu: false,
};

/// Every method, in the order messages list them.
pub const METHODS: &[Method] = &[
    EULER,
    RK4,
    DOPRI5,
    STROBOSCOPIC,
    AUTO,
    ROSW,
    SUSPENSION,
    PLATEN,
];

impl IntegratorSpec {
    /// The method's entry in [`METHODS`].
    pub fn method(&self) -> &'static Method {
        match self {
            IntegratorSpec::Euler { .. } => &EULER,
            IntegratorSpec::Rk4 { .. } => &RK4,
            IntegratorSpec::Dopri5 { .. } => &DOPRI5,
            IntegratorSpec::Rosw { .. } => &ROSW,
            IntegratorSpec::Platen { .. } => &PLATEN,
            IntegratorSpec::Stroboscopic { .. } => &STROBOSCOPIC,
            IntegratorSpec::Auto { .. } => &AUTO,
            IntegratorSpec::Suspension { .. } => &SUSPENSION,
        }
    }

    /// The one parameter's value: the step (s) or the tolerance.
    pub fn parameter(&self) -> f64 {
        match *self {
            IntegratorSpec::Euler { dt }
            | IntegratorSpec::Rk4 { dt }
            | IntegratorSpec::Platen { dt } => dt,
            IntegratorSpec::Dopri5 { rtol } | IntegratorSpec::Rosw { rtol } => rtol,
            IntegratorSpec::Stroboscopic { tol, .. }
            | IntegratorSpec::Auto { tol }
            | IntegratorSpec::Suspension { tol } => tol,
        }
    }

    /// Forward Euler, checked.
    pub fn euler(dt: f64) -> Result<Self> {
        require_positive("euler(dt): dt", dt, "s")?;
        Ok(IntegratorSpec::Euler { dt })
    }

    /// Classic RK4, checked.
    pub fn rk4(dt: f64) -> Result<Self> {
        require_positive("rk4(dt): dt", dt, "s")?;
        Ok(IntegratorSpec::Rk4 { dt })
    }

    /// Platen's weak second-order scheme, checked.
    pub fn platen(dt: f64) -> Result<Self> {
        require_positive("platen(dt): dt", dt, "s")?;
        Ok(IntegratorSpec::Platen { dt })
    }

    /// Whether the method is a scheme for thermal noise (Euler-Maruyama or Platen's).
    pub fn takes_noise(&self) -> bool {
        self.method().takes_noise
    }

    /// The tolerance relative to the drift that the method keeps (auto, stroboscopic, dopri5,
    /// rosw); `None` for fixed steps and for `suspension(tol)`, whose tolerance is each
    /// swimmer's own displacement's.
    pub fn drift_tol(&self) -> Option<f64> {
        match *self {
            IntegratorSpec::Dopri5 { rtol } | IntegratorSpec::Rosw { rtol } => Some(rtol),
            IntegratorSpec::Stroboscopic { tol, .. } | IntegratorSpec::Auto { tol } => Some(tol),
            IntegratorSpec::Euler { .. }
            | IntegratorSpec::Rk4 { .. }
            | IntegratorSpec::Platen { .. }
            | IntegratorSpec::Suspension { .. } => None,
        }
    }

    /// The step (s) of a fixed-step method; `None` for error-controlled ones.
    pub fn fixed_step(&self) -> Option<f64> {
        self.method().fixed_step.then(|| self.parameter())
    }

    /// The same method through its checked constructor (and its inner method's): a value read
    /// from a file is refused as the script's constructor would refuse it.
    pub fn checked(&self) -> Result<Self> {
        match *self {
            IntegratorSpec::Stroboscopic { tol, inner } => {
                let inner = inner
                    .map(|i| IntegratorSpec::from(i).checked())
                    .transpose()?;
                Self::stroboscopic_with(tol, inner)
            }
            _ => (self.method().make)(self.parameter()),
        }
    }

    /// Dormand-Prince 5(4), checked: 1e-14 ≤ rtol < 1.
    pub fn dopri5(rtol: f64) -> Result<Self> {
        check_rtol("dopri5", rtol).map(|rtol| IntegratorSpec::Dopri5 { rtol })
    }

    /// Rosenbrock-W ROS34PW2, checked: 1e-14 ≤ rtol < 1.
    pub fn rosw(rtol: f64) -> Result<Self> {
        check_rtol("rosw", rtol).map(|rtol| IntegratorSpec::Rosw { rtol })
    }

    /// Stroboscopic averaging with the model's inner integrator, checked: 1e-10 ≤ tol < 1.
    pub fn stroboscopic(tol: f64) -> Result<Self> {
        Self::stroboscopic_with(tol, None)
    }

    /// Stroboscopic averaging sampled by `inner`, checked.
    pub fn stroboscopic_with(tol: f64, inner: Option<IntegratorSpec>) -> Result<Self> {
        let tol = check_drift_tol("stroboscopic", tol)?;
        let inner = inner.map(Direct::try_from).transpose()?;
        Ok(IntegratorSpec::Stroboscopic { tol, inner })
    }

    /// The cheapest method for `tol`, chosen when the scene runs, checked: 1e-10 ≤ tol < 1.
    pub fn auto(tol: f64) -> Result<Self> {
        check_drift_tol("auto", tol).map(|tol| IntegratorSpec::Auto { tol })
    }

    /// The suspension method, checked: 1e-10 ≤ tol < 1.
    pub fn suspension(tol: f64) -> Result<Self> {
        check_drift_tol("suspension", tol).map(|tol| IntegratorSpec::Suspension { tol })
    }

    /// A fresh stepper for a direct method; `None` for stroboscopic averaging and the suspension
    /// method, which the scene builds (they need the period and the model's time scales).
    pub fn build(&self) -> Option<Box<dyn Stepper>> {
        Some(match *self {
            IntegratorSpec::Euler { dt } => Box::new(Euler::new(dt)),
            IntegratorSpec::Rk4 { dt } => Box::new(Rk4::new(dt)),
            IntegratorSpec::Dopri5 { rtol } => Box::new(Dopri5::new(rtol)),
            IntegratorSpec::Rosw { rtol } => Box::new(Rosenbrock::new(rtol)),
            IntegratorSpec::Platen { dt } => Box::new(Platen::new(dt)),
            IntegratorSpec::Stroboscopic { .. }
            | IntegratorSpec::Auto { .. }
            | IntegratorSpec::Suspension { .. } => return None,
        })
    }
}

/// The least tolerance relative to a drift or a structure (stroboscopic averaging, `auto`, the
/// suspension method, a continuum): below, round-off rather than the error it bounds sets it.
pub const MIN_DRIFT_TOL: f64 = 1e-10;

/// The least relative tolerance of an adaptive direct method (dopri5, rosw).
const MIN_RTOL: f64 = 1e-14;

/// A tolerance relative to the drift: 1e-10 ≤ tol < 1 (below, the samples' round-off is larger
/// than what is asked).
fn check_drift_tol(method: &str, tol: f64) -> Result<f64> {
    check_tolerance(
        &format!("{method}(tol): tol"),
        tol,
        MIN_DRIFT_TOL,
        "the samples' round-off is larger than what is asked",
    )
}

/// An adaptive method's tolerance: 1e-14 ≤ rtol < 1.
fn check_rtol(method: &str, rtol: f64) -> Result<f64> {
    check_tolerance(
        &format!("{method}(rtol): rtol"),
        rtol,
        MIN_RTOL,
        "the error estimate is round-off",
    )
}

/// The one check of a run's tolerance (a scene's integrator, a continuum's): `value` positive, in
/// [`min`, 1); `what` names it in the message, `why` says what fails below `min`.
pub fn check_tolerance(what: &str, value: f64, min: f64, why: &str) -> Result<f64> {
    require_positive(what, value, "dimensionless")?;
    if !(min..1.0).contains(&value) {
        return Err(invalid!(
            "{what} must lie in [{min:e}, 1) (below {min:e} {why}), got {value:e}"
        ));
    }
    Ok(value)
}

/// The latest time a state that runs may hold (a scene's, a continuum's): a number of its
/// longest stroke period, beyond which f64 no longer resolves the stroke. Every run-like call
/// checks its end against it before it starts ([`Horizon::check`]).
#[derive(Debug, Clone, Copy)]
pub struct Horizon<'a> {
    /// What holds the state, in the message ("a scene").
    pub holder: &'a str,
    /// The latest time it may hold (s).
    pub latest: f64,
    /// `latest` in stroke periods.
    pub max_periods: f64,
    /// The common stroke period (s), if there is one: times are then shown in periods too.
    pub period: Option<f64>,
    /// What else fails beyond (", and a saved scene would not load"), or "".
    pub beyond: &'a str,
    /// The fix besides a shorter run ("continue in a new scene from time 0").
    pub restart: &'a str,
}

impl Horizon<'_> {
    /// Refuse a run from `now` to `end` (s) that ends past the latest time, or at no time at all
    /// (NaN, inf); an end at or before `now` is no run and passes.
    pub fn check(&self, now: f64, end: f64) -> Result<()> {
        if end.is_nan() {
            return Err(invalid!(
                "a run of {} must end at a time, and this one would end at t = NaN s; give its length as a number",
                self.holder
            ));
        }
        if end <= now || end <= self.latest {
            return Ok(());
        }
        let periods = |t: f64| {
            self.period
                .map_or(String::new(), |p| format!(" ({:.6e} periods)", t / p))
        };
        Err(invalid!(
            "this run would end at t = {end:.6e} s{}, past the latest time {} may hold, {:.6e} s{} ({:e} stroke periods: beyond, f64 no longer resolves the stroke{}); run at most {:.6e} s{} more, or {}",
            periods(end),
            self.holder,
            self.latest,
            periods(self.latest),
            self.max_periods,
            self.beyond,
            self.latest - now,
            periods(self.latest - now),
            self.restart,
        ))
    }
}

impl fmt::Display for IntegratorSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}({:e}", self.method().name, self.parameter())?;
        if let IntegratorSpec::Stroboscopic {
            inner: Some(inner), ..
        } = self
        {
            write!(f, ", {}", IntegratorSpec::from(*inner))?;
        }
        f.write_str(")")
    }
}
