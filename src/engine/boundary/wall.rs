//! A plane wall's geometry: the solid plane below the fluid (gaps, its repulsion, the guard's
//! report of a sphere that touched it, the checks that spheres lie above it), its height within
//! the extent, and the Rotne-Prager-Blake mobility of [`WallMobility`].

use super::geometry::{Extent, Geometry, MobilitySettings, PairTerms};
use crate::engine::error::{invalid, unsupported, Result, Setting};
use crate::engine::integrators::Problem;
use crate::engine::mobility::MobilityOperator;
use crate::engine::wall::{Wall, WallMobility};
use nalgebra::Vector3;

impl Geometry for Wall {
    fn pair_terms(&self) -> PairTerms {
        PairTerms::Wall(*self)
    }

    fn solid(&self) -> bool {
        true
    }

    fn wall(&self) -> Option<&Wall> {
        Some(self)
    }

    fn floor(&self) -> Option<f64> {
        Some(self.z)
    }

    fn gap(&self, x: &Vector3<f64>, a: f64) -> f64 {
        Wall::gap(self, x, a)
    }

    fn clear(&self, spheres: &[(Vector3<f64>, f64)], margin: f64) -> bool {
        spheres.iter().all(|(x, a)| Wall::gap(self, x, *a) > margin)
    }

    fn add_forces(&self, pos: &[Vector3<f64>], radii: &[f64], forces: &mut [Vector3<f64>]) -> bool {
        Wall::add_forces(self, pos, radii, forces);
        true
    }

    fn touching(
        &self,
        pos: &[Vector3<f64>],
        radii: &[f64],
        owner: &dyn Fn(usize) -> (usize, usize),
    ) -> Option<Problem> {
        let (a, gap) = self.closest(pos, radii)?;
        if gap > 0.0 {
            return None;
        }
        let (s, sphere) = owner(a);
        Some(Problem {
            swimmer: Some(s),
            cause: format!("sphere {sphere} of swimmer {s} touched the wall (gap {gap:.3e} m)"),
            hint: "stiffen the wall's repulsion or widen its range (the wall's stiffness and range), take a smaller time step, or start the swimmers further from the wall".into(),
            fixes: Vec::new(),
        })
    }

    fn check_placed(&self, sphere: usize, x: &Vector3<f64>, a: f64, margin: f64) -> Result<()> {
        let gap = Wall::gap(self, x, a);
        if gap <= margin {
            return Err(invalid!(
                "sphere {sphere} of the swimmer would not be above the wall at z = {:e} m (its gap would be {gap:.3e} m); place it higher",
                self.z
            ));
        }
        Ok(())
    }

    fn check_present(&self, swimmer: usize, sphere: usize, x: &Vector3<f64>, a: f64) -> Result<()> {
        let gap = Wall::gap(self, x, a);
        if gap <= 0.0 {
            return Err(invalid!(
                "sphere {sphere} of swimmer {swimmer} is not above the wall at z = {:e} m (its gap is {gap:.3e} m); move the swimmers up or put the wall lower",
                self.z
            ));
        }
        Ok(())
    }

    /// The wall's mobility takes each sphere's image at twice its height, whose powers overflow
    /// far beyond the extent (every rate NaN), and a wall that far below the swimmers acts as
    /// none.
    fn check_reach(&self, extent: &Extent) -> Result<()> {
        if self.z.abs() <= extent.limit {
            return Ok(());
        }
        Err(unsupported(
            format!(
                "the wall at z = {:e} m lies beyond the {:e} m from the origin that positions may reach ({}; the wall's mobility overflows there, and a wall that far from the swimmers acts as none); put the wall within {:e} m of the origin, just below the swimmers",
                self.z,
                extent.limit,
                extent.why(),
                extent.limit
            ),
            &[Setting::NoWall],
        ))
    }

    fn mobility(&self, settings: &MobilitySettings) -> Result<Box<dyn MobilityOperator>> {
        Ok(Box::new(WallMobility::new(
            settings.mu,
            settings.kind,
            *self,
        )))
    }

    fn off_device(&self) -> Option<&'static str> {
        Some("a wall (the Rotne-Prager-Blake mobility)")
    }
}
