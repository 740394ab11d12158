//! What acts on the swimmers from outside: the external forces (gravity with buoyancy), and what
//! a failed step learns from them.

use super::*;
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

    /// The words of [`Scene::explain_failure`] when the external forces carry a sphere, at its
    /// Stokes speed |F|/(6πμa), across [`Scene::reach`] in less than the shortest stroke period.
    fn overwhelming_force(&self) -> Option<String> {
        let reach = self.reach().limit;
        let period = self.shortest_period();
        let radii = self.swimmers.iter().flat_map(|d| [d.a1, d.a2]);
        // (sphere, |F| in N, its mobility 1/(6πμa) in m/(N s)); |F| without squaring, so a
        // force of 1e200 N has a finite size.
        let (k, force, mobility) = self
            .sphere_forces()
            .iter()
            .zip(radii)
            .map(|(f, a)| {
                let m = crate::engine::mobility::self_mobility(self.mu, a);
                (f.x.hypot(f.y).hypot(f.z), m)
            })
            .enumerate()
            .map(|(k, (f, m))| (k, f, m))
            .max_by(|p, q| (p.1 * p.2).total_cmp(&(q.1 * q.2)))?;
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
