//! What acts on the swimmers from outside, and how far they may go: the wall and the external
//! forces (gravity with buoyancy), the reach that positions and the wall are held to (where f64
//! still resolves the spheres), and what a failed step learns from the forces.

use super::*;
use crate::engine::integrators::Problem;

impl Scene {
    /// The no-slip wall, if any.
    pub fn wall(&self) -> Option<&Wall> {
        self.wall.as_ref()
    }

    /// Put a no-slip wall below the fluid, or (`None`) take it away. Every sphere must lie clear
    /// above it, its height within [`Scene::reach`], and a periodic box is refused (no images of
    /// the wall); otherwise the scene is unchanged and the error says which.
    pub fn set_wall(&mut self, wall: Option<Wall>) -> Result<()> {
        let Some(w) = wall else {
            self.wall = None;
            return Ok(());
        };
        let w = w.checked()?;
        if self.periodic.is_some() {
            return Err(unsupported(
                "a wall in a periodic box is not available (the wall's mobility has no periodic images); leave the box first",
                &[Setting::NoBox],
            ));
        }
        self.check_wall_reach(&w)?;
        self.check_above(&w)?;
        self.wall = Some(w);
        Ok(())
    }

    /// How far from the origin swimmer centres and the wall may lie: [`MAX_EXTENT_IN_RADII`]
    /// times the smallest sphere radius, with the words that say why (unbounded without
    /// swimmers). Placement holds the centres to it, the runs' guard each step's centres.
    pub(crate) fn reach(&self) -> Reach {
        let r = self
            .swimmers
            .iter()
            .map(|d| d.a1.min(d.a2))
            .fold(f64::INFINITY, f64::min);
        if !r.is_finite() {
            return Reach::default();
        }
        Reach {
            limit: MAX_EXTENT_IN_RADII * r,
            why: format!(
                "{MAX_EXTENT_IN_RADII:e} times the smallest sphere radius, {r:e} m: beyond, f64 no longer resolves the spheres"
            ),
        }
    }

    /// Wall `w` within [`Scene::reach`]: the wall's mobility takes each sphere's image at twice
    /// its height, whose powers overflow far beyond it (every rate NaN), and a wall that far
    /// below the swimmers acts as none.
    pub(in crate::engine) fn check_wall_reach(&self, w: &Wall) -> Result<()> {
        let reach = self.reach();
        if w.z.abs() <= reach.limit {
            return Ok(());
        }
        Err(unsupported(
            format!(
                "the wall at z = {:e} m lies beyond the {:e} m from the origin that positions may reach ({}; the wall's mobility overflows there, and a wall that far from the swimmers acts as none); put the wall within {:e} m of the origin, just below the swimmers",
                w.z, reach.limit, reach.why, reach.limit
            ),
            &[Setting::NoWall],
        ))
    }

    /// Every sphere clear above wall `w`, or the error naming the first that is not.
    pub(in crate::engine) fn check_above(&self, w: &Wall) -> Result<()> {
        for i in 0..self.count() {
            let (x1, x2) = self.spheres(i);
            let d = &self.swimmers[i];
            for (k, (x, a)) in [(x1, d.a1), (x2, d.a2)].into_iter().enumerate() {
                let gap = w.gap(&x, a);
                if gap <= 0.0 {
                    return Err(invalid!(
                        "sphere {} of swimmer {i} is not above the wall at z = {:e} m (its gap is {gap:.3e} m); move the swimmers up or put the wall lower",
                        k + 1,
                        w.z
                    ));
                }
            }
        }
        Ok(())
    }

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

    /// The external force on every sphere in sphere order (empty when there is none).
    pub(crate) fn sphere_forces(&self) -> Vec<Vector3<f64>> {
        self.external
            .per_sphere(self.swimmers.iter().flat_map(|d| [d.a1, d.a2]))
    }

    /// Undo a change with `undo` if it left a sphere at or below the wall, and say which.
    pub(super) fn keep_above_wall(&mut self, undo: impl FnOnce(&mut Self)) -> Result<()> {
        let Some(w) = self.wall else {
            return Ok(());
        };
        self.check_above(&w).inspect_err(|_| undo(self))
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
            k / 2,
            reach / (period * mobility)
        ))
    }
}
