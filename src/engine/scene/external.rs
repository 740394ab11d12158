//! What acts on the swimmers from outside: the external forces (gravity with buoyancy), and what
//! a failed step learns from them.

use super::*;
use crate::engine::error::short;
use crate::engine::integrators::Problem;

impl Scene {
    /// The external forces on the spheres.
    pub fn external(&self) -> ExternalForces {
        self.external
    }

    /// Put the same force `force` (N) on every sphere ([0, 0, 0]: none).
    pub fn set_external_force(&mut self, force: [f64; 3]) -> Result<()> {
        self.external.force = ExternalForces::check_force(force)?;
        Ok(())
    }

    /// Gravity with buoyancy on the spheres, or (`None`) none.
    pub fn set_gravity(&mut self, gravity: Option<Gravity>) -> Result<()> {
        self.external.gravity = gravity.map(Gravity::checked).transpose()?;
        Ok(())
    }

    /// A failed step's problem with what the scene's settings tell about it: external forces that
    /// drive a sphere across the whole reach of positions within one stroke period are far beyond
    /// what the swimmers can carry, and whatever the guards saw (a stalled step, a state gone NaN,
    /// a centre beyond the reach, a stretched spring), no step size or tolerance mends it: the
    /// hint then names the force and the size below which a run can follow it.
    pub(crate) fn explain_failure(&self, mut problem: Problem) -> Problem {
        if let Some(hint) = self.overwhelming_force() {
            problem.hint = hint;
            problem.fixes = Vec::new();
        }
        problem
    }

    /// The sphere the external forces drive fastest at its Stokes speed |F|/(6πμa): (sphere,
    /// |F| in N, its mobility 1/(6πμa) in m/(N s), its radius a in m); `None` without spheres.
    /// |F| is taken without squaring, so a force of 1e200 N has a finite size.
    fn fastest_driven_sphere(&self) -> Option<(usize, f64, f64, f64)> {
        let radii = self.swimmers.iter().flat_map(|d| [d.a1, d.a2]);
        self.sphere_forces()
            .iter()
            .zip(radii)
            .map(|(f, a)| {
                let m = crate::engine::mobility::self_mobility(self.mu, a);
                (f.x.hypot(f.y).hypot(f.z), m, a)
            })
            .enumerate()
            .map(|(k, (f, m, a))| (k, f, m, a))
            .max_by(|p, q| (p.1 * p.2).total_cmp(&(q.1 * q.2)))
    }

    /// What may hold a run's steps short ([`Scene::collapsed_steps`]): the sphere the external
    /// forces drive fastest, if they drive one at all.
    pub(crate) fn collapse_cause(&self) -> CollapseCause {
        let driven = self
            .fastest_driven_sphere()
            .filter(|(_, force, mobility, _)| force * mobility > 0.0)
            .map(|(k, force, mobility, a)| (k, self.owner(k), force, mobility, a));
        CollapseCause { driven }
    }

    /// A run's steps have collapsed: from scene time `from` it reached `now` in `steps` steps and
    /// `wall` of wall-clock time, on its way to `t_end`. When its steps are below
    /// [`COLLAPSED_STEP`] of the shortest stroke period `period` and what is left would take over
    /// [`COLLAPSED_WAIT`] at this pace, the notice that says so, how long the rest would take,
    /// and `cause` ([`Scene::collapse_cause`]).
    pub(crate) fn collapsed_steps(
        period: f64,
        (from, now, t_end): (f64, f64, f64),
        steps: u64,
        wall: std::time::Duration,
        cause: &CollapseCause,
    ) -> Option<EngineError> {
        let covered = now - from;
        if steps == 0 || covered <= 0.0 {
            return None;
        }
        let dt = covered / steps as f64;
        let left = (t_end - now) / covered * wall.as_secs_f64();
        if !(dt < COLLAPSED_STEP * period && left > COLLAPSED_WAIT.as_secs_f64()) {
            return None;
        }
        let cause = cause.words(dt);
        Some(invalid!(
            "this run's steps have collapsed to {} s ({} of a stroke period; {steps} steps in {:.1} s): at this pace the {} s left to t = {} s take about {}; {cause}",
            short(dt),
            short(dt / period),
            wall.as_secs_f64(),
            short(t_end - now),
            short(t_end),
            duration_words(left)
        ))
    }

    /// The words of [`Scene::explain_failure`] when the external forces carry a sphere, at its
    /// Stokes speed |F|/(6πμa), across [`Scene::reach`] in less than the shortest stroke period.
    fn overwhelming_force(&self) -> Option<String> {
        let reach = self.reach().limit;
        let period = self.shortest_period();
        let (k, force, mobility, _) = self.fastest_driven_sphere()?;
        let speed = force * mobility;
        if speed * period <= reach || speed.is_nan() {
            return None;
        }
        let speed = if speed.is_finite() {
            format!("{speed:.3e} m/s")
        } else {
            "a speed beyond what f64 holds".into()
        };
        Some(format!(
            "the external forces drive sphere {k} (swimmer {}) at {speed}, its Stokes speed under {force:.3e} N, across the {reach:e} m that positions may reach in less than a stroke period ({period:.3e} s): far beyond what the swimmers can carry, whatever the step; use a smaller external force or weaker gravity (below {:.1e} N on that sphere a period stays within the reach; the paper's swimmers weigh about 1e-14 N)",
            self.owner(k),
            reach / (period * mobility)
        ))
    }
}

/// Steps shorter than this fraction of the shortest stroke period have collapsed (a stroke is
/// followed in a few hundred steps at most).
pub(crate) const COLLAPSED_STEP: f64 = 1e-5;

/// A collapsed run is noted when what is left of it would take longer than this.
pub(crate) const COLLAPSED_WAIT: std::time::Duration = std::time::Duration::from_secs(60);

/// `seconds` of wall-clock time as a reader takes them in: "2.5 minutes", "3.1e4 hours".
fn duration_words(seconds: f64) -> String {
    if seconds < 120.0 {
        format!("{} s", short(seconds))
    } else if seconds < 7200.0 {
        format!("{} minutes", short(seconds / 60.0))
    } else if seconds < 2.0 * 86400.0 {
        format!("{} hours", short(seconds / 3600.0))
    } else {
        format!("{} days", short(seconds / 86400.0))
    }
}

/// What may hold a run's steps short, taken when the run starts: the sphere the external forces
/// drive fastest (sphere, its swimmer, |F| in N, its mobility in m/(N s), its radius in m).
#[derive(Debug, Clone, Default)]
pub(crate) struct CollapseCause {
    driven: Option<(usize, usize, f64, f64, f64)>,
}

impl CollapseCause {
    /// The cause named, with its fix, for steps of `dt` (s): the external forces where they
    /// carry their sphere its own radius within ten steps, else the usual suspects.
    fn words(&self, dt: f64) -> String {
        match self.driven {
            Some((k, swimmer, force, mobility, a)) if a / (force * mobility) < 10.0 * dt => format!(
                "the external forces drive sphere {k} (swimmer {swimmer}) at {} m/s, its Stokes speed under {} N, its own radius in {} s: use a smaller external force or weaker gravity (the paper's swimmers weigh about 1e-14 N), or stop the run with Ctrl-C",
                short(force * mobility),
                short(force),
                short(a / (force * mobility))
            ),
            _ => "close or overlapping spheres, stiff contacts or a tight tolerance hold the steps short: s.integrator_info and s.stats tell more; stop the run with Ctrl-C".into(),
        }
    }
}
