//! Placing swimmers: the checks a new swimmer, a centre or a box side must pass (room, reach, no
//! overlap, no meeting its own image), `add` and `add_many` through cells, and the closest pair.

use super::*;
use crate::engine::error::short;

/// Refuse a swimmer centre that the scene's positions cannot carry: beyond the extent of
/// swimmers `ds` ([`MAX_EXTENT_IN_RADII`]).
pub(super) fn check_center<'a>(
    center: &Vector3<f64>,
    ds: impl IntoIterator<Item = &'a Dumbbell>,
) -> Result<()> {
    match Extent::of(ds) {
        Some(extent) => check_center_within(center, &extent),
        None => Ok(()),
    }
}

/// [`check_center`] with the extent already known.
fn check_center_within(center: &Vector3<f64>, extent: &Extent) -> Result<()> {
    let (limit, r) = (extent.limit, extent.radius);
    for (k, c) in ["x", "y", "z"].iter().zip(center.iter()) {
        if c.abs() > limit {
            return Err(invalid!(
                "a swimmer's centre at {k} = {c:e} m is beyond the {} m from the origin that positions may reach ({MAX_EXTENT_IN_RADII:e} times the smallest sphere radius, {} m): there f64 no longer resolves the spheres (separations, minimum images and wrapped positions err by more than {:.0e} of a radius); place it within {} m of the origin",
                short(limit),
                short(r),
                MAX_EXTENT_IN_RADII * f64::EPSILON,
                short(limit)
            ));
        }
    }
    Ok(())
}

/// Two spheres `gap` apart (m, surface to surface) are clear of each other by more than
/// `margin`; a NaN gap is not.
fn clear(gap: f64, margin: f64) -> bool {
    gap > margin
}

/// A new swimmer's spheres meet those of swimmer `s` (the gap, m, is ≤ 0 or NaN).
fn overlap_error(s: usize, gap: f64) -> EngineError {
    invalid!(
        "the new swimmer would overlap swimmer {s} (sphere gap {gap:.3e} m); place its centre further away"
    )
}

impl Scene {
    /// A region of sides `sides` (m, a cuboid centred on the origin) that copies of `d` are to
    /// be drawn in lies within the reach of positions ([`MAX_EXTENT_IN_RADII`]) of this scene's
    /// swimmers and `d`.
    pub(in crate::engine) fn check_region_reach(
        &self,
        d: &Dumbbell,
        sides: [f64; 3],
    ) -> Result<()> {
        let Some(extent) = Extent::of(self.swimmers.iter().chain([d])) else {
            return Ok(());
        };
        let half = 0.5 * sides.iter().copied().fold(0.0, f64::max);
        if half > extent.limit {
            return Err(invalid!(
                "swimmers drawn at random in a cube of side {} m would have coordinates up to {} m, beyond the {} m that positions may reach ({MAX_EXTENT_IN_RADII:e} times the smallest sphere radius, {} m: there f64 no longer resolves the spheres); give a larger volume fraction (the side is (n v / volume fraction)^(1/3)), or fewer swimmers",
                short(2.0 * half),
                short(half),
                short(extent.limit),
                short(extent.radius)
            ));
        }
        Ok(())
    }

    /// Whether swimmer `d` can be placed in this scene at all: valid, and in a box short of
    /// meeting its own image.
    pub(in crate::engine) fn check_placeable(&self, d: &Dumbbell) -> Result<()> {
        d.validate()?;
        self.geometry().check_fits(d)
    }

    /// Add a swimmer with hydrodynamic centre `center` (m) and orientation `dir` (any non-zero
    /// length), at length L(t) of the current time. Returns its 0-based index.
    pub fn add(&mut self, d: Dumbbell, center: Vector3<f64>, dir: Vector3<f64>) -> Result<usize> {
        d.validate()?;
        self.check_room(&d, center, dir, 0.0)?;
        let n = unit_direction(dir)?;
        Ok(self.push(d, center, n))
    }

    /// Add swimmers `(d, center, dir)` in order, all or none: the same checks as [`Scene::add`]
    /// one after another would make, each swimmer against the scene's and the earlier new ones,
    /// with the same first failure (the index into `items` and its error); on a failure the
    /// scene is unchanged. The overlaps are found through cell lists, O(n) for n swimmers at a
    /// bounded density, where adding them one at a time measures every pair, O(n²).
    pub fn add_many(
        &mut self,
        items: &[(Dumbbell, Vector3<f64>, Vector3<f64>)],
    ) -> std::result::Result<(), (usize, EngineError)> {
        // Everything but the overlaps, in order; the overlaps are looked for before the first
        // swimmer that fails here.
        let mut failed: Option<(usize, EngineError)> = None;
        let mut dirs = Vec::with_capacity(items.len());
        let mut a_min = self
            .swimmers
            .iter()
            .map(|o| o.a1.min(o.a2))
            .fold(f64::INFINITY, f64::min);
        for (k, (d, center, dir)) in items.iter().enumerate() {
            let checked = d.validate().and_then(|()| {
                for (name, c) in ["x", "y", "z"].iter().zip(center.iter()) {
                    require_finite(&format!("center.{name}"), *c)?;
                }
                let n = unit_direction(*dir)?;
                // The reach of the scene with this swimmer and the ones before it.
                a_min = a_min.min(d.a1.min(d.a2));
                let extent = Extent::of_radius(a_min);
                check_center_within(center, &extent)?;
                let g = self.geometry();
                g.check_fits(d)?;
                g.check_cell(&extent)?;
                let (x1, x2) = d.sphere_positions(*center, n, self.contact_length(d));
                self.check_placed(d, &x1, &x2, 0.0)?;
                Ok(n)
            });
            match checked {
                Ok(n) => dirs.push(n),
                Err(e) => {
                    failed = Some((k, e));
                    break;
                }
            }
        }
        // Placed, then measured where the scene holds them (as one add after another would).
        let old = self.count();
        for ((d, center, _), n) in items.iter().zip(&dirs) {
            self.push(*d, *center, *n);
        }
        if let Some((k, s, gap)) = self.first_overlap(old, &dirs) {
            self.truncate(old);
            return Err((k, overlap_error(s, gap)));
        }
        if let Some(f) = failed {
            self.truncate(old);
            return Err(f);
        }
        Ok(())
    }

    /// Keep the first `count` swimmers only.
    fn truncate(&mut self, count: usize) {
        self.swimmers.truncate(count);
        self.base.truncate(count);
        self.origins.truncate(count);
        self.state.truncate(STATE_PER_SWIMMER * count);
    }

    /// For [`Scene::add_many`], with its swimmers from `old` on just placed along `dirs`: the
    /// first of them (counted from `old`) that [`Scene::add`] would have refused for an overlap
    /// (a gap ≤ 0 between one of its spheres, where `add` measures them, and a sphere of an
    /// earlier swimmer, where the scene holds it), the first swimmer it overlaps, and the gap
    /// `add` would name.
    fn first_overlap(&self, old: usize, dirs: &[Vector3<f64>]) -> Option<(usize, usize, f64)> {
        let (total, per) = (self.count(), self.swimmer_model().spheres_per_swimmer());
        let spheres = self.sphere_count();
        let (mut x, mut y, mut z) = (vec![0.0; spheres], vec![0.0; spheres], vec![0.0; spheres]);
        let mut radii = Vec::with_capacity(spheres);
        for i in 0..total {
            let (x1, x2) = self.spheres(i);
            for (k, p) in [x1, x2].into_iter().enumerate() {
                (x[per * i + k], y[per * i + k], z[per * i + k]) = (p.x, p.y, p.z);
            }
            radii.extend([self.swimmers[i].a1, self.swimmers[i].a2]);
        }
        let at = |j: usize| Vector3::new(x[j], y[j], z[j]);
        let a_max = radii.iter().copied().fold(0.0, f64::max);
        // Spheres overlap closer than the sum of their radii, at most 2 a_max: every such pair
        // is in neighbouring cells of that side.
        let side = 2.0 * a_max;
        let g = self.geometry();
        let wraps = g.periodic().is_none_or(|b| side <= 0.5 * b.shortest());
        let grid = (side > 0.0 && side.is_finite() && wraps)
            .then(|| crate::engine::cells::CellGrid::build_in(&x, &y, &z, side, g.periodic()));
        let gap = |p: Vector3<f64>, a: f64, j: usize| g.separation(p - at(j)).norm() - a - radii[j];
        let mut runs = Vec::with_capacity(27);
        for (k, n) in dirs.iter().enumerate() {
            let swimmer = old + k;
            let d = &self.swimmers[swimmer];
            let (c1, c2) = d.sphere_positions(self.base[swimmer], *n, self.contact_length(d));
            let mine = [(c1, d.a1), (c2, d.a2)];
            let mut first: Option<usize> = None;
            for &(p, a) in &mine {
                let mut check = |j: usize| {
                    if !clear(gap(p, a, j), 0.0) && first.is_none_or(|s| self.owner(j) < s) {
                        first = Some(self.owner(j));
                    }
                };
                match &grid {
                    Some(g) => {
                        g.neighbour_runs(p.x, p.y, p.z, &mut runs);
                        for &(from, to) in &runs {
                            // A run holds its points in ascending order: the earlier swimmers'
                            // spheres come first.
                            for &j in &g.order[from as usize..to as usize] {
                                if j as usize >= per * swimmer {
                                    break;
                                }
                                check(j as usize);
                            }
                        }
                    }
                    None => (0..per * swimmer).for_each(check),
                }
            }
            if let Some(s) = first {
                // The gap `add` names: the first overlapping pair in its order.
                let named = mine
                    .iter()
                    .flat_map(|&(p, a)| (per * s..per * (s + 1)).map(move |j| gap(p, a, j)))
                    .find(|&g| !clear(g, 0.0))
                    .unwrap_or(f64::NAN);
                return Some((k, s, named));
            }
        }
        None
    }

    /// Whether [`Scene::add`] would accept this swimmer with every sphere gap above `margin` (m):
    /// valid, and no sphere within `margin` of another.
    pub fn fits(&self, d: &Dumbbell, center: Vector3<f64>, dir: Vector3<f64>, margin: f64) -> bool {
        d.validate().is_ok() && self.check_room(d, center, dir, margin).is_ok()
    }

    fn check_room(
        &self,
        d: &Dumbbell,
        center: Vector3<f64>,
        dir: Vector3<f64>,
        margin: f64,
    ) -> Result<()> {
        for (k, c) in ["x", "y", "z"].iter().zip(center.iter()) {
            require_finite(&format!("center.{k}"), *c)?;
        }
        let n = unit_direction(dir)?;
        check_center(&center, self.swimmers.iter().chain([d]))?;
        let g = self.geometry();
        g.check_fits(d)?;
        if let Some(extent) = Extent::of(self.swimmers.iter().chain([d])) {
            g.check_cell(&extent)?;
        }
        let (x1, x2) = d.sphere_positions(center, n, self.contact_length(d));
        // One sphere's stroke closes half of what two spheres' strokes close between them.
        self.check_placed(d, &x1, &x2, 0.5 * margin)?;
        for (s, other) in self.swimmers.iter().enumerate() {
            let (y1, y2) = self.spheres(s);
            for (xa, aa) in [(x1, d.a1), (x2, d.a2)] {
                for (yb, ab) in [(y1, other.a1), (y2, other.a2)] {
                    let gap = g.separation(xa - yb).norm() - aa - ab;
                    if !clear(gap, margin) {
                        return Err(overlap_error(s, gap));
                    }
                }
            }
        }
        Ok(())
    }

    /// Whether spheres `x1`, `x2` of swimmer `d` are more than `margin` clear of the boundary's
    /// solid part: [`Scene::check_placed`] without its message, for the many draws of a random
    /// placement.
    pub(in crate::engine) fn clear_of_boundary(
        &self,
        d: &Dumbbell,
        x1: &Vector3<f64>,
        x2: &Vector3<f64>,
        margin: f64,
    ) -> bool {
        self.geometry().clear(&[(*x1, d.a1), (*x2, d.a2)], margin)
    }

    /// Spheres `x1`, `x2` of swimmer `d` more than `margin` clear of the boundary's solid part.
    pub(in crate::engine) fn check_placed(
        &self,
        d: &Dumbbell,
        x1: &Vector3<f64>,
        x2: &Vector3<f64>,
        margin: f64,
    ) -> Result<()> {
        let g = self.geometry();
        for (k, (x, a)) in [(x1, d.a1), (x2, d.a2)].into_iter().enumerate() {
            g.check_placed(k + 1, x, a, margin)?;
        }
        Ok(())
    }

    /// The smallest gap |x_α − x_β| − a_α − a_β over all pairs of spheres (m) and the two spheres
    /// (sphere α belongs to swimmer α/2, the a1 sphere first); `None` with fewer than two spheres.
    pub fn closest_spheres(&self) -> Option<(f64, usize, usize)> {
        let (n, per) = (
            self.sphere_count(),
            self.swimmer_model().spheres_per_swimmer(),
        );
        let mut soa = crate::engine::pairs::SoaSpheres::default();
        soa.resize(n);
        soa.periodic = self.periodic().copied();
        let mut radii = Vec::with_capacity(n);
        for i in 0..self.count() {
            let (a, b) = self.spheres(i);
            let d = &self.swimmers[i];
            for (k, (p, r)) in [(a, d.a1), (b, d.a2)].into_iter().enumerate() {
                let j = per * i + k;
                (soa.x[j], soa.y[j], soa.z[j]) = (p.x, p.y, p.z);
                radii.push(r);
            }
        }
        crate::engine::gaps::min_gap(&soa, &radii, n >= 256)
    }
}
