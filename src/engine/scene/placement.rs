//! Placing swimmers: the checks a new swimmer, a centre or a box side must pass (room, reach, no
//! overlap, no meeting its own image), `add` and `add_many` through cells, and the closest pair.

use super::*;
use crate::engine::error::short;

/// How far from the origin a swimmer's centre, and how long a box side, may reach, in units of
/// the scene's smallest sphere radius. A coordinate carries an error of an ulp (2.2e-16 of
/// itself) into every separation, minimum image and wrapped position, so at this reach a sphere
/// is still resolved to 2.2e-8 of its radius; far beyond, spheres merge (a dumbbell at 1e20 m has
/// both at one point) and wrapping returns NaN.
pub const MAX_EXTENT_IN_RADII: f64 = 1e8;

/// The reach [`MAX_EXTENT_IN_RADII`] of swimmers `ds` (m), with the smallest radius; `None` without
/// swimmers.
fn extent_limit<'a>(ds: impl IntoIterator<Item = &'a Dumbbell>) -> Option<(f64, f64)> {
    let r = ds.into_iter().map(|d| d.a1.min(d.a2)).reduce(f64::min)?;
    Some((MAX_EXTENT_IN_RADII * r, r))
}

/// Refuse a swimmer centre that the scene's positions cannot carry ([`MAX_EXTENT_IN_RADII`]).
pub(super) fn check_center<'a>(
    center: &Vector3<f64>,
    ds: impl IntoIterator<Item = &'a Dumbbell>,
) -> Result<()> {
    match extent_limit(ds) {
        Some(reach) => check_center_within(center, reach),
        None => Ok(()),
    }
}

/// [`check_center`] with the reach and the smallest radius, `(limit, r)`, already known.
fn check_center_within(center: &Vector3<f64>, (limit, r): (f64, f64)) -> Result<()> {
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

/// Refuse a box whose sides the scene's positions cannot carry ([`MAX_EXTENT_IN_RADII`]).
pub(super) fn check_box_extent<'a>(
    b: &PeriodicBox,
    ds: impl IntoIterator<Item = &'a Dumbbell>,
) -> Result<()> {
    match extent_limit(ds) {
        Some(reach) => check_box_within(b, reach),
        None => Ok(()),
    }
}

/// [`check_box_extent`] with the reach and the smallest radius, `(limit, r)`, already known.
fn check_box_within(b: &PeriodicBox, (limit, r): (f64, f64)) -> Result<()> {
    for (k, l) in ["x", "y", "z"].iter().zip(b.sides()) {
        if l > limit {
            return Err(invalid!(
                "the box side along {k}, {l:e} m, is longer than the {} m that positions may reach ({MAX_EXTENT_IN_RADII:e} times the smallest sphere radius, {} m): across it f64 no longer resolves the spheres, and wrapping cannot carry them; give sides up to {} m, or no box for open space",
                short(limit),
                short(r),
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

/// Swimmer `d` must not reach its own image: the box's shortest side above 2(ℓ + λ + a1 + a2).
pub(super) fn check_fits_box(d: &Dumbbell, b: &PeriodicBox) -> Result<()> {
    let reach = d.ell + d.lambda + d.a1 + d.a2;
    if b.shortest() <= 2.0 * reach {
        return Err(invalid!(
            "a box side of {:e} m is too short for a swimmer of reach ell + lambda + a1 + a2 = {reach:e} m, which would meet its own image; make every side longer than {:e} m",
            b.shortest(),
            2.0 * reach
        ));
    }
    Ok(())
}

impl Scene {
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
                let reach = (MAX_EXTENT_IN_RADII * a_min, a_min);
                check_center_within(center, reach)?;
                if let Some(b) = &self.periodic {
                    check_fits_box(d, b)?;
                    check_box_within(b, reach)?;
                }
                let (x1, x2) = d.sphere_positions(*center, n, self.contact_length(d));
                self.check_clear_of_wall(d, &x1, &x2, 0.0)?;
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
        self.state.truncate(STATE_PER_SWIMMER * count);
    }

    /// For [`Scene::add_many`], with its swimmers from `old` on just placed along `dirs`: the
    /// first of them (counted from `old`) that [`Scene::add`] would have refused for an overlap
    /// (a gap ≤ 0 between one of its spheres, where `add` measures them, and a sphere of an
    /// earlier swimmer, where the scene holds it), the first swimmer it overlaps, and the gap
    /// `add` would name.
    fn first_overlap(&self, old: usize, dirs: &[Vector3<f64>]) -> Option<(usize, usize, f64)> {
        let total = self.count();
        let (mut x, mut y, mut z) = (
            vec![0.0; 2 * total],
            vec![0.0; 2 * total],
            vec![0.0; 2 * total],
        );
        let mut radii = Vec::with_capacity(2 * total);
        for i in 0..total {
            let (x1, x2) = self.spheres(i);
            for (k, p) in [x1, x2].into_iter().enumerate() {
                (x[2 * i + k], y[2 * i + k], z[2 * i + k]) = (p.x, p.y, p.z);
            }
            radii.extend([self.swimmers[i].a1, self.swimmers[i].a2]);
        }
        let at = |j: usize| Vector3::new(x[j], y[j], z[j]);
        let a_max = radii.iter().copied().fold(0.0, f64::max);
        // Spheres overlap closer than the sum of their radii, at most 2 a_max: every such pair
        // is in neighbouring cells of that side.
        let side = 2.0 * a_max;
        let wraps = self.periodic.is_none_or(|b| side <= 0.5 * b.shortest());
        let grid = (side > 0.0 && side.is_finite() && wraps).then(|| {
            crate::engine::cells::CellGrid::build_in(&x, &y, &z, side, self.periodic.as_ref())
        });
        let gap = |p: Vector3<f64>, a: f64, j: usize| {
            separation(self.periodic.as_ref(), p - at(j)).norm() - a - radii[j]
        };
        let mut runs = Vec::with_capacity(27);
        for (k, n) in dirs.iter().enumerate() {
            let swimmer = old + k;
            let d = &self.swimmers[swimmer];
            let (c1, c2) = d.sphere_positions(self.base[swimmer], *n, self.contact_length(d));
            let mine = [(c1, d.a1), (c2, d.a2)];
            let mut first: Option<usize> = None;
            for &(p, a) in &mine {
                let mut check = |j: usize| {
                    if !clear(gap(p, a, j), 0.0) && first.is_none_or(|s| j / 2 < s) {
                        first = Some(j / 2);
                    }
                };
                match &grid {
                    Some(g) => {
                        g.neighbour_runs(p.x, p.y, p.z, &mut runs);
                        for &(from, to) in &runs {
                            // A run holds its points in ascending order: the earlier swimmers'
                            // spheres come first.
                            for &j in &g.order[from as usize..to as usize] {
                                if j as usize >= 2 * swimmer {
                                    break;
                                }
                                check(j as usize);
                            }
                        }
                    }
                    None => (0..2 * swimmer).for_each(check),
                }
            }
            if let Some(s) = first {
                // The gap `add` names: the first overlapping pair in its order.
                let named = mine
                    .iter()
                    .flat_map(|&(p, a)| [2 * s, 2 * s + 1].map(|j| gap(p, a, j)))
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
        if let Some(b) = &self.periodic {
            check_fits_box(d, b)?;
            check_box_extent(b, self.swimmers.iter().chain([d]))?;
        }
        let (x1, x2) = d.sphere_positions(center, n, self.contact_length(d));
        // One sphere's stroke closes half of what two spheres' strokes close between them.
        self.check_clear_of_wall(d, &x1, &x2, 0.5 * margin)?;
        for (s, other) in self.swimmers.iter().enumerate() {
            let (y1, y2) = self.spheres(s);
            for (xa, aa) in [(x1, d.a1), (x2, d.a2)] {
                for (yb, ab) in [(y1, other.a1), (y2, other.a2)] {
                    let gap = separation(self.periodic.as_ref(), xa - yb).norm() - aa - ab;
                    if !clear(gap, margin) {
                        return Err(overlap_error(s, gap));
                    }
                }
            }
        }
        Ok(())
    }

    /// Whether spheres `x1`, `x2` of swimmer `d` are more than `margin` above the wall, if there
    /// is one: [`Scene::check_clear_of_wall`] without its message, for the many draws of a random
    /// placement.
    pub(in crate::engine) fn clear_of_wall(
        &self,
        d: &Dumbbell,
        x1: &Vector3<f64>,
        x2: &Vector3<f64>,
        margin: f64,
    ) -> bool {
        self.wall
            .is_none_or(|w| w.gap(x1, d.a1) > margin && w.gap(x2, d.a2) > margin)
    }

    /// Spheres `x1`, `x2` of swimmer `d` more than `margin` above the wall, if there is one.
    pub(in crate::engine) fn check_clear_of_wall(
        &self,
        d: &Dumbbell,
        x1: &Vector3<f64>,
        x2: &Vector3<f64>,
        margin: f64,
    ) -> Result<()> {
        let Some(w) = &self.wall else {
            return Ok(());
        };
        for (k, (x, a)) in [(x1, d.a1), (x2, d.a2)].into_iter().enumerate() {
            let gap = w.gap(x, a);
            if gap <= margin {
                return Err(invalid!(
                    "sphere {} of the swimmer would not be above the wall at z = {:e} m (its gap would be {gap:.3e} m); place it higher",
                    k + 1,
                    w.z
                ));
            }
        }
        Ok(())
    }

    /// The smallest gap |x_α − x_β| − a_α − a_β over all pairs of spheres (m) and the two spheres
    /// (sphere α belongs to swimmer α/2, the a1 sphere first); `None` with fewer than two spheres.
    pub fn closest_spheres(&self) -> Option<(f64, usize, usize)> {
        let n = 2 * self.count();
        let mut soa = crate::engine::pairs::SoaSpheres::default();
        soa.resize(n);
        soa.periodic = self.periodic;
        let mut radii = Vec::with_capacity(n);
        for i in 0..self.count() {
            let (a, b) = self.spheres(i);
            let d = &self.swimmers[i];
            for (k, (p, r)) in [(a, d.a1), (b, d.a2)].into_iter().enumerate() {
                let j = 2 * i + k;
                (soa.x[j], soa.y[j], soa.z[j]) = (p.x, p.y, p.z);
                radii.push(r);
            }
        }
        crate::engine::gaps::min_gap(&soa, &radii, n >= 256)
    }
}
