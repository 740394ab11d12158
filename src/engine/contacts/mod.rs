//! Close approaches between swimmers: whether spheres of different swimmers may overlap, and an
//! optional short-range steric repulsion that keeps them apart.
//!
//! By default a run stops when two spheres touch (the guard of [`super::spheres`]). With
//! `allow_overlap`, spheres of *different* swimmers may overlap: the RPY mobility switches to the
//! overlapping-sphere form of Zuk et al. (2014), which stays positive definite, so the dynamics
//! stay well posed. A dumbbell's own two spheres overlapping still stops the run (its spring has
//! collapsed). The steric repulsion is a soft harmonic wall between spheres of different
//! swimmers: F = k (δ − gap) r̂ for gap < δ, zero beyond, pushing the spheres apart; it is a
//! pair force (momentum is conserved) and costs an O(N²) pass per right-hand side, paid only
//! when it is on. The averaged model places its swimmers' spheres at length ℓ for both (see
//! [`super::averaged::AveragedSystem::set_contacts`]).

use super::choice::{self, Choice, Named};
use super::error::{invalid, Result};
use super::periodic::{separation, PeriodicBox};
use nalgebra::Vector3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

mod rods;

/// Contact handling of a scene (saved with it).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Contacts {
    /// Let spheres of different swimmers overlap instead of stopping the run.
    pub allow_overlap: bool,
    /// Steric repulsion between spheres of different swimmers (microscopic and averaged models).
    pub steric: Option<Steric>,
}

impl Contacts {
    /// What touching spheres of different swimmers do.
    pub fn overlaps(&self) -> Overlaps {
        if self.allow_overlap {
            Overlaps::Allow
        } else {
            Overlaps::Stop
        }
    }
}

/// What happens when spheres of different swimmers touch (saved as [`Contacts::allow_overlap`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Overlaps {
    /// The run stops with an error naming the two spheres.
    #[default]
    Stop,
    /// They overlap, moved by the RPY tensor for overlapping spheres.
    Allow,
}

impl Named for Overlaps {
    const KIND: &'static str = "overlaps setting";
    const CHOICES: &'static [Choice<Self>] = &[
        Choice {
            value: Overlaps::Stop,
            name: "stop",
            about: "default: the run stops when spheres of different swimmers touch",
        },
        Choice {
            value: Overlaps::Allow,
            name: "allow",
            about: "they overlap, moved by the RPY tensor for overlapping spheres",
        },
    ];
}

choice::inherent_names!(Overlaps);

/// A harmonic repulsion F = k (δ − gap) r̂ for surface gaps below δ.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Steric {
    /// δ: the gap below which spheres repel (m).
    pub range: f64,
    /// k: force per unit of gap below δ (N/m).
    pub stiffness: f64,
    /// What repels: the spheres alone, or each swimmer's whole body (saved; spheres for older files).
    #[serde(default)]
    pub body: StericBody,
    /// How the force grows inside the range (saved only when not harmonic).
    #[serde(default, skip_serializing_if = "StericLaw::is_harmonic")]
    pub law: StericLaw,
}

/// How a steric force grows with the overlap x = δ − gap of the range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum StericLaw {
    /// F = k x: a spring from the edge of the range (default); its stiffness starts at once.
    #[default]
    Harmonic,
    /// F = k x²/δ: the same force at contact (x = δ), growing from zero force and zero stiffness
    /// at the edge of the range, so the rates have no kink where a contact starts. A contact held
    /// near the edge by the far field then costs an adaptive step no more than the far field
    /// does, where the harmonic law's kink holds it to a fraction of a period.
    Smooth,
}

impl StericLaw {
    pub(crate) fn is_harmonic(&self) -> bool {
        *self == StericLaw::Harmonic
    }

    /// The force over the stiffness at overlap `x` of range `range` (m).
    #[inline]
    pub(crate) fn force(self, x: f64, range: f64) -> f64 {
        match self {
            StericLaw::Harmonic => x,
            // Past contact (x > δ, overlapping bodies) the parabola's tangent carries on.
            StericLaw::Smooth if x <= range => x * x / range,
            StericLaw::Smooth => 2.0 * x - range,
        }
    }
}

impl Named for StericLaw {
    const KIND: &'static str = "steric law";
    const CHOICES: &'static [Choice<Self>] = &[
        Choice {
            value: StericLaw::Harmonic,
            name: "harmonic",
            about: "default: force stiffness * (range - gap)",
        },
        Choice {
            value: StericLaw::Smooth,
            name: "smooth",
            about: "force stiffness * (range - gap)^2 / range: the same at contact, no kink at the range's edge",
        },
    ];
}

choice::inherent_names!(StericLaw);

/// The bodies a steric repulsion keeps apart.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum StericBody {
    /// Spheres of different swimmers (default).
    #[default]
    Spheres,
    /// Each swimmer as a rod: the segment joining its sphere centres, thickened by the radii
    /// interpolated along it (its spheres at the ends). Swimmers cannot pass through each other.
    Rods,
}

impl Named for StericBody {
    const KIND: &'static str = "steric body";
    const CHOICES: &'static [Choice<Self>] = &[
        Choice {
            value: StericBody::Spheres,
            name: "spheres",
            about: "default: spheres of different swimmers repel",
        },
        Choice {
            value: StericBody::Rods,
            name: "rods",
            about: "each swimmer is a rod from sphere to sphere: swimmers cannot cross",
        },
    ];
}

choice::inherent_names!(StericBody);

impl Steric {
    /// A repulsion of range δ (m) and stiffness k (N/m), both positive and finite.
    pub fn new(range: f64, stiffness: f64) -> Result<Self> {
        for (name, v, unit) in [("range", range, "m"), ("stiffness", stiffness, "N/m")] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid!(
                    "steric {name} must be a positive number of {unit}, got {v}; e.g. range 1e-7 m and stiffness 1e-3 N/m"
                ));
            }
        }
        Ok(Steric {
            range,
            stiffness,
            body: StericBody::Spheres,
            law: StericLaw::Harmonic,
        })
    }

    /// The same repulsion between other bodies.
    pub fn with_body(self, body: StericBody) -> Self {
        Steric { body, ..self }
    }

    /// The same repulsion with force law `law`.
    pub fn with_law(self, law: StericLaw) -> Self {
        Steric { law, ..self }
    }

    /// The repulsion on sphere `i` from sphere `j`, if they are within reach.
    #[inline]
    fn pair_force(
        &self,
        pos: &[Vector3<f64>],
        radii: &[f64],
        periodic: Option<&PeriodicBox>,
        i: usize,
        j: usize,
    ) -> Option<Vector3<f64>> {
        self.sphere_force(separation(periodic, pos[i] - pos[j]), radii[i], radii[j])
    }

    /// The repulsion on a sphere of radius `ai` from one of radius `aj` at separation `r` (its
    /// centre minus the other's), if they are within reach.
    #[inline]
    pub(crate) fn sphere_force(&self, r: Vector3<f64>, ai: f64, aj: f64) -> Option<Vector3<f64>> {
        self.sphere_force_within(r, ai, aj, 0.0)
    }

    /// [`Steric::sphere_force`] with the law k (δ − gap) r̂ carried on, attractive, to gaps of
    /// δ + `extra` (the linearly implicit methods' Jacobian of contacts about to form).
    #[inline]
    fn sphere_force_within(
        &self,
        r: Vector3<f64>,
        ai: f64,
        aj: f64,
        extra: f64,
    ) -> Option<Vector3<f64>> {
        // Compare squares first: the square root is taken for the few close pairs only.
        let reach = self.range + ai + aj;
        let limit = reach + extra;
        let d2 = r.norm_squared();
        (d2 < limit * limit && d2 > 0.0).then(|| {
            let d = d2.sqrt();
            r * (self.stiffness * self.law.force(reach - d, self.range) / d)
        })
    }

    /// Adds the repulsion on every sphere to `forces`. Sphere α belongs to swimmer α/2; spheres of
    /// one swimmer do not repel. Each row sums its own partners in index order (no scatter), so
    /// rows run in parallel when `parallel` with results independent of the thread count. In a
    /// periodic box pairs are measured by their minimum image.
    pub(crate) fn add_forces(
        &self,
        pos: &[Vector3<f64>],
        radii: &[f64],
        periodic: Option<&PeriodicBox>,
        forces: &mut [Vector3<f64>],
        parallel: bool,
    ) {
        if self.body == StericBody::Rods {
            return self.add_rod_forces(pos, radii, periodic, forces, parallel);
        }
        let row = |i: usize, f: &mut Vector3<f64>| {
            for j in 0..pos.len() {
                if j / 2 != i / 2 {
                    if let Some(df) = self.pair_force(pos, radii, periodic, i, j) {
                        *f += df;
                    }
                }
            }
        };
        let reach_max = self.range + 2.0 * radii.iter().copied().fold(0.0, f64::max);
        let fits = periodic.is_none_or(|b| reach_max <= 0.5 * b.shortest());
        if pos.len() >= super::gaps::CELL_LIST_SPHERES && fits {
            return self.add_forces_by_cells(pos, radii, periodic, forces, parallel);
        }
        if parallel {
            forces
                .par_iter_mut()
                .enumerate()
                .for_each(|(i, f)| row(i, f));
        } else {
            forces.iter_mut().enumerate().for_each(|(i, f)| row(i, f));
        }
    }

    /// [`Steric::add_forces`] for large scenes: the partners within reach come from the cells (of
    /// side range + 2·largest radius) around each sphere, and are added in index order, so the
    /// forces are bitwise the all-pairs loop's (the pairs out of reach add nothing there).
    fn add_forces_by_cells(
        &self,
        pos: &[Vector3<f64>],
        radii: &[f64],
        periodic: Option<&PeriodicBox>,
        forces: &mut [Vector3<f64>],
        parallel: bool,
    ) {
        let reach_max = self.range + 2.0 * radii.iter().copied().fold(0.0, f64::max);
        let coords = |k: usize| -> Vec<f64> { pos.iter().map(|p| p[k]).collect() };
        let grid = super::cells::CellGrid::build_in(
            &coords(0),
            &coords(1),
            &coords(2),
            reach_max,
            periodic,
        );
        let row = |i: usize, f: &mut Vector3<f64>| {
            let mut runs = Vec::with_capacity(27);
            grid.neighbour_runs(pos[i].x, pos[i].y, pos[i].z, &mut runs);
            let mut close: Vec<(usize, Vector3<f64>)> = Vec::new();
            for (a, b) in runs {
                for &j in &grid.order[a as usize..b as usize] {
                    let j = j as usize;
                    if j / 2 != i / 2 {
                        if let Some(df) = self.pair_force(pos, radii, periodic, i, j) {
                            close.push((j, df));
                        }
                    }
                }
            }
            close.sort_unstable_by_key(|c| c.0);
            for (_, df) in close {
                *f += df;
            }
        };
        if parallel {
            forces
                .par_iter_mut()
                .enumerate()
                .for_each(|(i, f)| row(i, f));
        } else {
            forces.iter_mut().enumerate().for_each(|(i, f)| row(i, f));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::rods::{closest_on_segments, contact_points};
    use super::*;

    /// The cell-list path gives bitwise the all-pairs loop's forces: 1,200 spheres (above the
    /// threshold) at random in a box where a few hundred pairs are within reach.
    #[test]
    fn steric_forces_by_cells_are_the_all_pairs_forces() {
        let n = 1200;
        let mut state = 0x9e3779b97f4a7c15u64;
        let mut uniform = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let side = 60e-6;
        let pos: Vec<Vector3<f64>> = (0..n)
            .map(|_| Vector3::new(uniform(), uniform(), uniform()) * side)
            .collect();
        let radii: Vec<f64> = (0..n)
            .map(|i| if i % 2 == 0 { 1e-6 } else { 0.5e-6 })
            .collect();
        let st = Steric::new(1e-6, 1e-3).unwrap();
        let mut by_cells = vec![Vector3::zeros(); n];
        st.add_forces(&pos, &radii, None, &mut by_cells, true);
        let mut all = vec![Vector3::zeros(); n];
        // The all-pairs loop, as add_forces runs it below the threshold.
        for i in 0..n {
            for j in 0..n {
                if j / 2 == i / 2 {
                    continue;
                }
                let r = pos[i] - pos[j];
                let reach = st.range + radii[i] + radii[j];
                let d2 = r.norm_squared();
                if d2 < reach * reach && d2 > 0.0 {
                    let d = d2.sqrt();
                    all[i] += r * (st.stiffness * (reach - d) / d);
                }
            }
        }
        let pushed = all.iter().filter(|f| f.norm() > 0.0).count();
        assert!(pushed > 50, "only {pushed} spheres within reach");
        assert_eq!(by_cells, all);
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

    /// The smooth law: the harmonic law's force at contact, none from the range on, and a slope
    /// that starts from zero at the range (the harmonic law's jumps there from 0 to k); past
    /// contact the tangent carries on. Tolerances: rounding of forces of size kδ (1e-12), and
    /// the finite-difference slope's own error, h/δ = 1e-6.
    #[test]
    fn the_smooth_law_starts_without_a_kink() {
        let (range, k, a) = (0.5e-6, 1e-4, 1e-6);
        let harmonic = Steric::new(range, k).unwrap();
        let smooth = harmonic.with_law(StericLaw::Smooth);
        let at = |st: &Steric, gap: f64| {
            st.sphere_force(Vector3::new(2.0 * a + gap, 0.0, 0.0), a, a)
                .map_or(0.0, |f| f.x)
        };
        assert!((at(&smooth, 0.0) - at(&harmonic, 0.0)).abs() <= 1e-12 * k * range);
        assert!((at(&smooth, 0.0) - k * range).abs() <= 1e-12 * k * range);
        assert_eq!(at(&smooth, range), 0.0);
        assert_eq!(at(&smooth, 2.0 * range), 0.0);
        let h = 1e-6 * range;
        let slope = |st: &Steric| (at(st, range - 2.0 * h) - at(st, range - h)) / h;
        assert!(slope(&smooth).abs() < 1e-5 * k, "{:e}", slope(&smooth));
        assert!(
            (slope(&harmonic) - k).abs() < 1e-6 * k,
            "{:e}",
            slope(&harmonic)
        );
        // Past contact: F = k(2x − δ) at overlap x, slope 2k.
        let x = 0.2 * range;
        assert!(
            (at(&smooth, -0.2 * range) - k * (2.0 * (range + x) - range)).abs()
                <= 1e-12 * k * range
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
