//! The scene's boundary, one [`Boundary`] value: open space, a periodic box or a wall, each set
//! with the checks the swimmers present must pass (asked of its [`Geometry`]); the mobility
//! operator of its fluid; and the reach that positions and the boundary are held to.

use super::*;
use crate::engine::boundary::ewald;

impl Scene {
    /// The boundary of the fluid: open space, a periodic box or a wall.
    pub fn boundary(&self) -> &Boundary {
        &self.boundary
    }

    /// What the boundary means for the spheres: images, what is solid, what fits.
    pub(crate) fn geometry(&self) -> &dyn Geometry {
        self.boundary.geometry()
    }

    /// The periodic box, if any (`None`: open space or a wall).
    pub fn periodic(&self) -> Option<&PeriodicBox> {
        self.boundary.periodic()
    }

    /// The no-slip wall, if any.
    pub fn wall(&self) -> Option<&Wall> {
        self.boundary.wall()
    }

    /// Put the scene in a periodic box of sides `sides` (m), centred on the origin, or (`None`)
    /// back in open space. Every swimmer must fit (a box side longer than twice its reach
    /// ℓ + λ + a1 + a2, so that it never meets its own image) and no spheres may overlap by their
    /// minimum images; otherwise the scene is unchanged and the error says which.
    pub fn set_box(&mut self, sides: Option<[f64; 3]>) -> Result<()> {
        let Some(sides) = sides else {
            self.boundary = self.boundary.without(Kind::Periodic);
            return Ok(());
        };
        self.boundary.check_replace(Kind::Periodic)?;
        let b = PeriodicBox::new(sides)?;
        self.set_boundary(Boundary::Periodic(b))
    }

    /// Put a no-slip wall below the fluid, or (`None`) take it away. Every sphere must lie clear
    /// above it, its height within the reach of positions, and a periodic box is refused (no images of
    /// the wall); otherwise the scene is unchanged and the error says which.
    pub fn set_wall(&mut self, wall: Option<Wall>) -> Result<()> {
        let Some(w) = wall else {
            self.boundary = self.boundary.without(Kind::Wall);
            return Ok(());
        };
        let w = w.checked()?;
        self.set_boundary(Boundary::Wall(w))
    }

    /// Take boundary `new` if it may replace the present one, every swimmer fits in it, it lies
    /// within the reach, every sphere is clear of its solid part and (with images) no sphere
    /// overlaps another's image; otherwise the scene is unchanged and the error says which.
    fn set_boundary(&mut self, new: Boundary) -> Result<()> {
        self.boundary.check_replace(new.kind())?;
        let g = new.geometry();
        for (i, d) in self.swimmers.iter().enumerate() {
            g.check_fits(d).map_err(|e| invalid!("swimmer {i}: {e}"))?;
        }
        if let Some(extent) = Extent::of(&self.swimmers) {
            g.check_cell(&extent)?;
            g.check_reach(&extent)?;
        }
        self.check_clear_of(g)?;
        let old = std::mem::replace(&mut self.boundary, new);
        if g.periodic().is_some() {
            if let Some((gap, a, c)) = self.closest_spheres() {
                let (sa, sc) = (self.owner(a), self.owner(c));
                if gap <= 0.0 && !(self.contacts.allow_overlap && sa != sc) {
                    self.boundary = old;
                    return Err(invalid!(
                        "in that box sphere {a} (swimmer {sa}) would overlap the image of sphere {c} (swimmer {sc}) by {:.3e} m; use a larger box or move the swimmers",
                        -gap
                    ));
                }
            }
        }
        Ok(())
    }

    /// How far from the origin swimmer centres and the boundary may lie: [`MAX_EXTENT_IN_RADII`]
    /// times the smallest sphere radius, with the words that say why (unbounded without
    /// swimmers). Placement holds the centres to it, the runs' guard each step's centres.
    pub(crate) fn reach(&self) -> Reach {
        Extent::of(&self.swimmers).map_or_else(Reach::default, |e| e.reach())
    }

    /// The boundary's solid part within [`Scene::reach`] of the swimmers now in the scene (a wall
    /// set before them, or before a smaller one came, may lie beyond it).
    pub(in crate::engine) fn check_boundary_reach(&self) -> Result<()> {
        match Extent::of(&self.swimmers) {
            Some(extent) => self.geometry().check_reach(&extent),
            None => Ok(()),
        }
    }

    /// Every sphere clear of the solid part of geometry `g`, or the error naming the first that
    /// is not.
    pub(in crate::engine) fn check_clear_of(&self, g: &dyn Geometry) -> Result<()> {
        if !g.solid() {
            return Ok(());
        }
        for i in 0..self.count() {
            let (x1, x2) = self.spheres(i);
            let d = &self.swimmers[i];
            for (k, (x, a)) in [(x1, d.a1), (x2, d.a2)].into_iter().enumerate() {
                g.check_present(i, k + 1, &x, a)?;
            }
        }
        Ok(())
    }

    /// Undo a change with `undo` if it left a sphere in the boundary's solid part, and say which.
    pub(super) fn keep_clear(&mut self, undo: impl FnOnce(&mut Self)) -> Result<()> {
        let boundary = self.boundary;
        self.check_clear_of(boundary.geometry())
            .inspect_err(|_| undo(self))
    }

    /// What the boundary's mobility is built from, with the box's products by `method`.
    fn mobility_settings(&self, method: EwaldMethod) -> MobilitySettings {
        MobilitySettings {
            mu: self.mu,
            kind: self.mobility,
            spheres: self.sphere_count(),
            ewald_tol: self.ewald_tol(),
            ewald_method: method,
        }
    }

    /// The box's periodic mobility for the sphere models (`None` in open space and at a wall),
    /// its products by the scene's Ewald method.
    pub(crate) fn ewald(&self) -> Result<Option<Ewald>> {
        let settings = self.mobility_settings(self.ewald_method);
        self.periodic().map(|b| ewald(b, &settings)).transpose()
    }

    /// The boundary's mobility for the sphere models: the box's Ewald sums with products by
    /// `method` (blocks and matrices are Beenakker's either way), the wall's, or open space.
    pub(crate) fn mobility_operator_by(
        &self,
        method: EwaldMethod,
    ) -> Result<Box<dyn MobilityOperator>> {
        self.geometry().mobility(&self.mobility_settings(method))
    }

    /// The boundary's mobility with the scene's Ewald method.
    pub(crate) fn mobility_operator(&self) -> Result<Box<dyn MobilityOperator>> {
        self.mobility_operator_by(self.ewald_method)
    }

    /// Position `p` as shown: wrapped into the box, if there is one.
    pub fn shown(&self, p: Vector3<f64>) -> Vector3<f64> {
        self.geometry().shown(p)
    }
}
