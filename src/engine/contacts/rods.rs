//! The steric repulsion between rods: each swimmer's body as the segment between its sphere
//! centres with its radii at the ends, the rods' contact points (blended near parallel so the
//! torque turns smoothly through it) and the pair forces and torques that follow.

use super::steric::{Steric, StericBody};
use crate::engine::periodic::{separation, PeriodicBox};
use nalgebra::Vector3;
use rayon::prelude::*;

/// A rod: its start, the vector from start to end, and its radii at the two ends.
pub(super) type Rod = (Vector3<f64>, Vector3<f64>, [f64; 2]);

impl Steric {
    /// The repulsion between the rods of swimmers `i` and `j` (spheres 2i, 2i+1 and 2j, 2j+1):
    /// the closest points of the two axes, at fractions s and t along them, and the force on
    /// rod `i` there, F = k (δ − gap) r̂ with gap = |r| − a_i(s) − a_j(t), the radii interpolated
    /// linearly between the spheres'. `None` when out of reach (or the axes cross exactly). The
    /// contact points are sought whatever the distance: a loop over many pairs skips the far
    /// ones first by their bounding spheres ([`apart`]).
    #[inline]
    pub(super) fn rod_force(
        &self,
        pos: &[Vector3<f64>],
        radii: &[f64],
        periodic: Option<&PeriodicBox>,
        i: usize,
        j: usize,
    ) -> Option<(f64, Vector3<f64>)> {
        let (p, d1) = (pos[2 * i], pos[2 * i + 1] - pos[2 * i]);
        // Rod j moved to its image nearest rod i (midpoints by the minimum image; open space: 0).
        let mid = |k: usize| (pos[2 * k] + pos[2 * k + 1]) * 0.5;
        let d = mid(i) - mid(j);
        let shift = d - separation(periodic, d);
        let (q, d2) = (pos[2 * j] + shift, pos[2 * j + 1] - pos[2 * j]);
        self.rod_pair_force_sought(
            (p, d1, [radii[2 * i], radii[2 * i + 1]]),
            (q, d2, [radii[2 * j], radii[2 * j + 1]]),
            0.0,
        )
    }

    /// The repulsion between rod `a` = (start, start-to-end, radii at both ends) and rod `b`, as
    /// [`Steric::rod_force`] (the fraction s along `a` where it acts and the force on `a`), with
    /// the law carried on to gaps of δ + `extra` as [`Steric::sphere_force_within`]; a pair
    /// whose bounding spheres lie apart is out of reach without its contact points sought.
    #[inline]
    pub(super) fn rod_pair_force_within(
        &self,
        a: Rod,
        b: Rod,
        extra: f64,
    ) -> Option<(f64, Vector3<f64>)> {
        if out_of_reach(a, b, self.range + extra) {
            return None;
        }
        self.rod_pair_force_sought(a, b, extra)
    }

    /// [`Steric::rod_pair_force_within`] without the bounding test: the contact points sought
    /// for every pair.
    #[inline]
    fn rod_pair_force_sought(&self, a: Rod, b: Rod, extra: f64) -> Option<(f64, Vector3<f64>)> {
        let ((p, d1, ra), (q, d2, rb)) = (a, b);
        let (s, t) = contact_points(&p, &d1, &q, &d2);
        let r = (p + d1 * s) - (q + d2 * t);
        let reach = self.range + (1.0 - s) * ra[0] + s * ra[1] + (1.0 - t) * rb[0] + t * rb[1];
        let limit = reach + extra;
        let d2r = r.norm_squared();
        (d2r < limit * limit && d2r > 0.0).then(|| {
            let d = d2r.sqrt();
            (
                s,
                r * (self.stiffness * self.law.force(reach - d, self.range) / d),
            )
        })
    }

    /// The forces on swimmer A's two spheres (centres `a`, radii `ra`) from swimmer B's (`b`,
    /// `rb`; B already at the image A meets), as [`Steric::add_forces`] adds them for this
    /// body: per sphere pair, or rod to rod, the rod's force shared by its spheres.
    #[inline]
    pub(crate) fn swimmer_pair_forces(
        &self,
        a: [Vector3<f64>; 2],
        ra: [f64; 2],
        b: [Vector3<f64>; 2],
        rb: [f64; 2],
    ) -> [Vector3<f64>; 2] {
        self.swimmer_pair_forces_within(a, ra, b, rb, 0.0)
    }

    /// [`Steric::swimmer_pair_forces`] with the force law carried on to gaps of δ + `extra`.
    #[inline]
    pub(crate) fn swimmer_pair_forces_within(
        &self,
        a: [Vector3<f64>; 2],
        ra: [f64; 2],
        b: [Vector3<f64>; 2],
        rb: [f64; 2],
        extra: f64,
    ) -> [Vector3<f64>; 2] {
        let mut f = [Vector3::zeros(); 2];
        match self.body {
            StericBody::Spheres => {
                for k in 0..2 {
                    for m in 0..2 {
                        if let Some(df) = self.sphere_force_within(a[k] - b[m], ra[k], rb[m], extra)
                        {
                            f[k] += df;
                        }
                    }
                }
            }
            StericBody::Rods => {
                if let Some((s, df)) = self.rod_pair_force_within(
                    (a[0], a[1] - a[0], ra),
                    (b[0], b[1] - b[0], rb),
                    extra,
                ) {
                    f[0] += df * (1.0 - s);
                    f[1] += df * s;
                }
            }
        }
        f
    }

    /// [`Steric::add_forces`] between rods: the force on a rod at fraction s along it goes
    /// (1 − s) to its first sphere and s to its second, which carries its force and torque about
    /// any point. Each swimmer sums its partners in index order; from [`super::super::gaps::CELL_LIST_SPHERES`]
    /// spheres the partners come from cell lists of the midpoints (side: range + twice the
    /// largest radius + the longest rod), bitwise the same forces.
    pub(super) fn add_rod_forces(
        &self,
        pos: &[Vector3<f64>],
        radii: &[f64],
        periodic: Option<&PeriodicBox>,
        forces: &mut [Vector3<f64>],
        parallel: bool,
    ) {
        let swimmers = pos.len() / 2;
        // Each rod's bounding sphere: pairs whose spheres lie beyond the range are skipped
        // before their contact points are sought, and the cells hold the midpoints.
        let spheres: Vec<(Vector3<f64>, f64)> = (0..swimmers)
            .map(|k| {
                let rod = (pos[2 * k], pos[2 * k + 1] - pos[2 * k]);
                bounding_sphere((rod.0, rod.1, [radii[2 * k], radii[2 * k + 1]]))
            })
            .collect();
        let longest = (0..swimmers)
            .map(|k| (pos[2 * k + 1] - pos[2 * k]).norm())
            .fold(0.0, f64::max);
        let reach_max = self.range + 2.0 * radii.iter().copied().fold(0.0, f64::max) + longest;
        let fits = periodic.is_none_or(|b| reach_max <= 0.5 * b.shortest());
        let grid = (pos.len() >= super::super::gaps::CELL_LIST_SPHERES && fits && reach_max > 0.0)
            .then(|| {
                let mid = |d: usize| -> Vec<f64> { spheres.iter().map(|(m, _)| m[d]).collect() };
                super::super::cells::CellGrid::build_in(
                    &mid(0),
                    &mid(1),
                    &mid(2),
                    reach_max,
                    periodic,
                )
            });
        let row = |i: usize, f: &mut [Vector3<f64>]| {
            let add = |j: usize| {
                let ((mi, bi), (mj, bj)) = (spheres[i], spheres[j]);
                if apart(
                    separation(periodic, mi - mj).norm_squared(),
                    bi,
                    bj,
                    self.range,
                ) {
                    return;
                }
                if let Some((s, df)) = self.rod_force(pos, radii, periodic, i, j) {
                    f[0] += df * (1.0 - s);
                    f[1] += df * s;
                }
            };
            match &grid {
                None => (0..swimmers).filter(|&j| j != i).for_each(add),
                Some(grid) => {
                    let m = (pos[2 * i] + pos[2 * i + 1]) * 0.5;
                    let mut runs = Vec::with_capacity(27);
                    grid.neighbour_runs(m.x, m.y, m.z, &mut runs);
                    let mut near: Vec<usize> = runs
                        .iter()
                        .flat_map(|&(a, b)| grid.order[a as usize..b as usize].iter())
                        .map(|&j| j as usize)
                        .filter(|&j| j != i)
                        .collect();
                    near.sort_unstable();
                    near.dedup();
                    near.into_iter().for_each(add);
                }
            }
        };
        if parallel {
            forces
                .par_chunks_mut(2)
                .enumerate()
                .for_each(|(i, f)| row(i, f));
        } else {
            forces
                .chunks_mut(2)
                .enumerate()
                .for_each(|(i, f)| row(i, f));
        }
    }
}

/// A rod's bounding sphere: its midpoint, and half its length plus its larger radius. No point
/// of the rod's body lies outside it.
#[inline]
fn bounding_sphere((p, d, r): Rod) -> (Vector3<f64>, f64) {
    (p + d * 0.5, 0.5 * d.norm() + r[0].max(r[1]))
}

/// Whether two bounding spheres of radii `ra` and `rb`, their centres `d2` apart squared, lie
/// farther apart than `range`: then no two points of their rods' bodies come within it. The
/// bound is widened by [`OUT_OF_REACH_MARGIN`] (the rounding of far positions), so a pair it
/// skips is one the contact points would find out of reach: a cheap test for the many far
/// pairs, bitwise the same forces.
#[inline]
fn apart(d2: f64, ra: f64, rb: f64, range: f64) -> bool {
    let bound = (range + ra + rb) * (1.0 + OUT_OF_REACH_MARGIN);
    d2 > bound * bound
}

/// Whether rods `a` and `b` lie beyond `range` of each other whatever their contact points
/// ([`apart`] of their bounding spheres).
#[inline]
fn out_of_reach(a: Rod, b: Rod, range: f64) -> bool {
    let ((ma, ra), (mb, rb)) = (bounding_sphere(a), bounding_sphere(b));
    apart((ma - mb).norm_squared(), ra, rb, range)
}

/// The relative margin of [`apart`]'s bound: positions up to 1e8 radii from the origin
/// (the reach they are held to) round at ~1e-8 of a radius, far below it.
const OUT_OF_REACH_MARGIN: f64 = 1e-6;

/// sin²θ below which two rods at angle θ act at points blended towards their overlap's middle
/// (see [`contact_points`]): θ ≈ 5.7°.
pub(super) const PARALLEL_BLEND_SIN2: f64 = 0.01;

/// Where the repulsion between segments p + s d1 and q + t d2 acts: their closest points, except
/// near parallel. There the closest points jump from one end to the other as the segments turn
/// through parallel (at parallel they are not unique), and with them the torque; so within
/// [`PARALLEL_BLEND_SIN2`] each point is drawn towards the middle of the part of its segment that
/// faces the other, fully at parallel, by a weight χ(sin²θ) = 3u² − 2u³ (u = sin²θ /
/// [`PARALLEL_BLEND_SIN2`]) whose derivative vanishes at both ends. The points are the same
/// seen from either segment, so the pair forces stay equal and opposite along one line.
pub(super) fn contact_points(
    p: &Vector3<f64>,
    d1: &Vector3<f64>,
    q: &Vector3<f64>,
    d2: &Vector3<f64>,
) -> (f64, f64) {
    let (s, t) = closest_on_segments(p, d1, q, d2);
    let (a, e) = (d1.dot(d1), d2.dot(d2));
    if a <= 0.0 || e <= 0.0 {
        return (s, t);
    }
    let b = d1.dot(d2);
    let u = ((a * e - b * b) / (a * e)).max(0.0) / PARALLEL_BLEND_SIN2;
    if u >= 1.0 {
        return (s, t);
    }
    let chi = u * u * (3.0 - 2.0 * u);
    let r = p - q;
    let (c, f) = (d1.dot(&r), d2.dot(&r));
    // The other segment's ends projected onto each, clamped: the facing parts' middles.
    let mid_s = 0.5 * ((-c / a).clamp(0.0, 1.0) + ((b - c) / a).clamp(0.0, 1.0));
    let mid_t = 0.5 * ((f / e).clamp(0.0, 1.0) + ((b + f) / e).clamp(0.0, 1.0));
    (mid_s + chi * (s - mid_s), mid_t + chi * (t - mid_t))
}

/// The fractions (s, t) ∈ [0, 1]² of the closest points of segments p + s·d1 and q + t·d2
/// (Ericson, Real-Time Collision Detection, 5.1.9; parallel segments take s = 0 or the clamp).
pub(super) fn closest_on_segments(
    p: &Vector3<f64>,
    d1: &Vector3<f64>,
    q: &Vector3<f64>,
    d2: &Vector3<f64>,
) -> (f64, f64) {
    let r = p - q;
    let (a, e, f) = (d1.dot(d1), d2.dot(d2), d2.dot(&r));
    if a <= 0.0 && e <= 0.0 {
        return (0.0, 0.0);
    }
    if a <= 0.0 {
        return (0.0, (f / e).clamp(0.0, 1.0));
    }
    let c = d1.dot(&r);
    if e <= 0.0 {
        return ((-c / a).clamp(0.0, 1.0), 0.0);
    }
    let b = d1.dot(d2);
    let denom = a * e - b * b;
    let mut s = if denom > 1e-14 * a * e {
        ((b * f - c * e) / denom).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut t = (b * s + f) / e;
    if t < 0.0 {
        t = 0.0;
        s = (-c / a).clamp(0.0, 1.0);
    } else if t > 1.0 {
        t = 1.0;
        s = ((b - c) / a).clamp(0.0, 1.0);
    }
    (s, t)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bounding test skips only pairs out of reach: random rods (lengths 0-2, radii 0.05-0.3,
    /// any direction) at midpoint distances spread around their bound, each skipped pair checked
    /// against the contact points sought, under the smooth law with a reach carried on (`extra`)
    /// and without. The test must also skip most far pairs, or it saves nothing.
    #[test]
    fn the_bounding_test_skips_only_pairs_out_of_reach() {
        use super::super::steric::StericLaw;
        let mut rng = crate::engine::rng::Rng::new(0x9e37_79b9_7f4a_7c15);
        let mut draw = || rng.uniform();
        fn unit(draw: &mut dyn FnMut() -> f64) -> Vector3<f64> {
            let z: f64 = 2.0 * draw() - 1.0;
            let phi = 2.0 * std::f64::consts::PI * draw();
            let r = (1.0 - z * z).sqrt();
            Vector3::new(r * phi.cos(), r * phi.sin(), z)
        }
        let steric = Steric::new(0.1, 1.0)
            .unwrap()
            .with_body(StericBody::Rods)
            .with_law(StericLaw::Smooth);
        let (mut skipped, mut far) = (0, 0);
        for _ in 0..200_000 {
            let d1 = unit(&mut draw) * (2.0 * draw());
            let d2 = unit(&mut draw) * (2.0 * draw());
            let (ra, rb) = (
                [0.05 + 0.25 * draw(), 0.05 + 0.25 * draw()],
                [0.05 + 0.25 * draw(), 0.05 + 0.25 * draw()],
            );
            let extra = if draw() < 0.5 { 0.0 } else { 0.2 * draw() };
            let bound =
                0.1 + extra + ra[0].max(ra[1]) + rb[0].max(rb[1]) + 0.5 * (d1.norm() + d2.norm());
            let p = Vector3::new(1.0, -2.0, 0.5);
            let mid = p + d1 * 0.5 + unit(&mut draw) * (bound * (0.5 + 1.0 * draw()));
            let q = mid - d2 * 0.5;
            let (a, b) = ((p, d1, ra), (q, d2, rb));
            let sought = steric.rod_pair_force_sought(a, b, extra);
            if out_of_reach(a, b, 0.1 + extra) {
                skipped += 1;
                assert!(sought.is_none(), "skipped a pair in reach: {a:?} {b:?}");
            }
            assert_eq!(steric.rod_pair_force_within(a, b, extra), sought);
            if (p + d1 * 0.5 - mid).norm() > bound * 1.01 {
                far += 1;
            }
        }
        assert!(
            skipped >= far && far > 50_000,
            "{skipped} skipped, {far} far"
        );
    }

    /// Two rods in contact turned through parallel: the points where their repulsion acts move
    /// continuously (closest points jump from one end to the other at parallel), the same points
    /// seen from either rod, and away from parallel they are the closest points. Steps of 1e-5
    /// rad move a point by ~1e-5 × (the blend's slope, below 1e3): a jump would be ~1.
    #[test]
    fn contact_points_move_continuously_through_parallel() {
        let p = Vector3::new(0.0, 0.0, 0.0);
        let d1 = Vector3::new(10.0, 0.0, 0.0);
        let mut last: Option<(f64, f64)> = None;
        for k in -2000..=2000 {
            let th = k as f64 * 1e-5;
            let q = Vector3::new(1.0, 0.3, 0.0);
            let d2 = Vector3::new(10.0 * th.cos(), 10.0 * th.sin(), 0.0);
            let (s, t) = contact_points(&p, &d1, &q, &d2);
            let (t2, s2) = contact_points(&q, &d2, &p, &d1);
            assert!(
                (s - s2).abs() < 1e-12 && (t - t2).abs() < 1e-12,
                "not symmetric at {th}"
            );
            if let Some((s0, t0)) = last {
                assert!(
                    (s - s0).abs() < 1e-2 && (t - t0).abs() < 1e-2,
                    "jump at {th}: s {s0} -> {s}, t {t0} -> {t}"
                );
            }
            last = Some((s, t));
        }
        // At 45 degrees: the closest points.
        let d2 = Vector3::new(10.0 * 0.5f64.sqrt(), 10.0 * 0.5f64.sqrt(), 0.0);
        let q = Vector3::new(1.0, 0.3, 1.0);
        assert_eq!(
            contact_points(&p, &d1, &q, &d2),
            closest_on_segments(&p, &d1, &q, &d2)
        );
    }

    fn forces(st: &Steric, pos: &[Vector3<f64>], radii: &[f64]) -> Vec<Vector3<f64>> {
        let mut f = vec![Vector3::zeros(); pos.len()];
        st.add_forces(pos, radii, None, &mut f, true);
        f
    }

    /// Rod repulsion through cell lists (1,200 spheres, above the threshold) is bitwise the
    /// all-pairs sum of the pair forces in index order, in open space and in a box; the forces
    /// sum to zero and, in open space, so do their torques about the origin (a pair force along the line of the closest points, split over
    /// the spheres so that its moment is kept): both to rounding, 1e-12 of the largest force
    /// times the scene's size.
    #[test]
    fn rod_forces_by_cells_are_the_all_pairs_forces_and_conserve_momenta() {
        let swimmers = 600;
        let mut state = 0x2545f4914f6cdd1du64;
        let mut uniform = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (side, ell) = (40e-6, 5e-6);
        let mut pos = Vec::new();
        for _ in 0..swimmers {
            let c = Vector3::new(uniform(), uniform(), uniform()) * side;
            let n = Vector3::new(uniform() - 0.5, uniform() - 0.5, uniform() - 0.5).normalize();
            pos.push(c - n * (0.5 * ell));
            pos.push(c + n * (0.5 * ell));
        }
        let radii: Vec<f64> = (0..2 * swimmers)
            .map(|i| if i % 2 == 0 { 1e-6 } else { 0.5e-6 })
            .collect();
        let st = Steric::new(0.5e-6, 1e-3)
            .unwrap()
            .with_body(StericBody::Rods);
        // Open space, and the same points in a periodic box of the cloud's side (pairs across
        // the faces by their minimum images).
        let in_box = PeriodicBox::new([side; 3]).unwrap();
        for periodic in [None, Some(&in_box)] {
            let mut by_cells = vec![Vector3::zeros(); pos.len()];
            st.add_forces(&pos, &radii, periodic, &mut by_cells, true);
            let mut all = vec![Vector3::zeros(); pos.len()];
            let mut pairs = 0;
            for i in 0..swimmers {
                for j in (0..swimmers).filter(|&j| j != i) {
                    if let Some((s, f)) = st.rod_force(&pos, &radii, periodic, i, j) {
                        all[2 * i] += f * (1.0 - s);
                        all[2 * i + 1] += f * s;
                        pairs += 1;
                    }
                }
            }
            assert!(pairs > 100, "only {pairs} rods within reach");
            assert_eq!(by_cells, all);
            let big = all.iter().fold(0.0f64, |m, f| m.max(f.norm()));
            let net: Vector3<f64> = all.iter().sum();
            assert!(net.norm() < 1e-12 * big, "net force {net:?}");
            if periodic.is_none() {
                let torque: Vector3<f64> = pos.iter().zip(&all).map(|(p, f)| p.cross(f)).sum();
                assert!(torque.norm() < 1e-12 * big * side, "net torque {torque:?}");
            }
        }
    }

    /// Two swimmers crossing like an X, one rod's width above the other: their spheres are far
    /// apart (no sphere repulsion) but the rods repel, along the line of the closest points, the
    /// force split equally between the spheres (both closest points at the middle). End to end,
    /// the rods' closest points are the facing spheres', and the rods repel exactly as those
    /// spheres do.
    #[test]
    fn rods_repel_where_swimmers_cross_and_end_to_end_as_their_spheres() {
        let (ell, a, range, k) = (5e-6, 0.5e-6, 0.2e-6, 1e-3);
        let radii = [a, a, a, a];
        let h = 2.0 * a + 0.5 * range;
        let crossed = [
            Vector3::new(-0.5 * ell, 0.0, 0.0),
            Vector3::new(0.5 * ell, 0.0, 0.0),
            Vector3::new(0.0, -0.5 * ell, h),
            Vector3::new(0.0, 0.5 * ell, h),
        ];
        let spheres = Steric::new(range, k).unwrap();
        let rods = spheres.with_body(StericBody::Rods);
        assert!(forces(&spheres, &crossed, &radii)
            .iter()
            .all(|f| *f == Vector3::zeros()));
        let f = forces(&rods, &crossed, &radii);
        let push = k * (range + 2.0 * a - h);
        for (sphere, sign) in [(0, -1.0), (1, -1.0), (2, 1.0), (3, 1.0)] {
            let want = Vector3::new(0.0, 0.0, sign * 0.5 * push);
            assert!(
                (f[sphere] - want).norm() < 1e-12 * push,
                "sphere {sphere}: {:?}",
                f[sphere]
            );
        }
        // End to end along x, unequal radii: the rods' reach there is the spheres' own.
        let radii = [a, 0.6 * a, 0.8 * a, a];
        let gap = 0.3 * range;
        let x2 = ell + 0.6 * a + 0.8 * a + gap;
        let line = [
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(ell, 0.0, 0.0),
            Vector3::new(x2, 0.0, 0.0),
            Vector3::new(x2 + ell, 0.0, 0.0),
        ];
        let (fs, fr) = (
            forces(&spheres, &line, &radii),
            forces(&rods, &line, &radii),
        );
        assert!(fs[1].norm() > 0.0);
        for (x, y) in fs.iter().zip(&fr) {
            assert!(
                (x - y).norm() <= 1e-12 * fs[1].norm(),
                "{x:?} against {y:?}"
            );
        }
    }

    /// Closest points of segments in the cases of the algorithm: skew, parallel, and clamped.
    #[test]
    fn closest_points_of_segments() {
        let v = Vector3::new;
        let close = |got: (f64, f64), want: (f64, f64)| {
            assert!(
                (got.0 - want.0).abs() < 1e-14 && (got.1 - want.1).abs() < 1e-14,
                "{got:?} against {want:?}"
            );
        };
        for (p, d1, q, d2, want) in [
            // Skew: x axis from 0 to 2 and a y-directed segment over (0.5, −1..1, 1).
            (
                v(0.0, 0.0, 0.0),
                v(2.0, 0.0, 0.0),
                v(0.5, -1.0, 1.0),
                v(0.0, 2.0, 0.0),
                (0.25, 0.5),
            ),
            // Beyond the end: the second segment's foot lies past s = 1.
            (
                v(0.0, 0.0, 0.0),
                v(1.0, 0.0, 0.0),
                v(3.0, -1.0, 1.0),
                v(0.0, 2.0, 0.0),
                (1.0, 0.5),
            ),
            // Parallel, offset along their direction: s = 0 and t from it, clamped.
            (
                v(0.0, 0.0, 0.0),
                v(1.0, 0.0, 0.0),
                v(0.5, 1.0, 0.0),
                v(1.0, 0.0, 0.0),
                (0.5, 0.0),
            ),
        ] {
            close(closest_on_segments(&p, &d1, &q, &d2), want);
        }
    }
}
