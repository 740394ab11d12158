//! The spheres of a set of dumbbells, as both sphere-resolved models (spring and rigid-stroke) see
//! them: radii, positions, the force on each, and the interaction velocities the mobility gives.
//! Sphere 2σ is dumbbell σ's a1 sphere, 2σ+1 its a2 sphere.

use super::integrators::Problem;
use super::mobility::Mobility;
use super::pairs::{self, SoaSpheres};
use super::swimmer::Dumbbell;
use nalgebra::Vector3;

/// Sphere data and scratch of the sphere-resolved models.
#[derive(Debug, Clone)]
pub(crate) struct Spheres {
    pub(crate) mu: f64,
    pub(crate) mobility: Mobility,
    pub(crate) radii: Vec<f64>,
    /// Positions (m), filled by the model before [`Spheres::interact`].
    pub(crate) pos: Vec<Vector3<f64>>,
    forces: Vec<Vector3<f64>>,
    u: Vec<Vector3<f64>>,
    /// Scratch of the fast kernel (large scenes).
    soa: SoaSpheres,
    soa_u: Vec<[f64; 3]>,
}

/// From this many spheres on, the vectorised row kernel ([`pairs`]) replaces the symmetric
/// half-loop (below it the half-loop's halved arithmetic wins; measured in `benches/kernels.rs`).
pub const FAST_KERNEL_SPHERES: usize = 64;
/// From this many spheres on, the rows run in parallel (a product costs ≳ 0.3 ms, far above
/// rayon's few-µs dispatch).
pub const PARALLEL_SPHERES: usize = 256;

impl Spheres {
    /// Spheres of these dumbbells in a fluid of viscosity `mu`.
    pub(crate) fn new(swimmers: &[Dumbbell], mu: f64, mobility: Mobility) -> Self {
        let n = 2 * swimmers.len();
        Spheres {
            mu,
            mobility,
            radii: swimmers.iter().flat_map(|d| [d.a1, d.a2]).collect(),
            pos: vec![Vector3::zeros(); n],
            forces: vec![Vector3::zeros(); n],
            u: vec![Vector3::zeros(); n],
            soa: SoaSpheres::default(),
            soa_u: Vec::new(),
        }
    }

    /// Put force `f(σ)` on sphere 1 and −f(σ) on sphere 2 of every dumbbell (each dumbbell is
    /// force-free) and compute the interaction velocities u_α = Σ_{β≠α} H_αβ F_β.
    #[inline]
    pub(crate) fn interact(&mut self, f: impl Fn(usize) -> Vector3<f64>) {
        for s in 0..self.radii.len() / 2 {
            let fs = f(s);
            self.forces[2 * s] = fs;
            self.forces[2 * s + 1] = -fs;
        }
        let n = self.pos.len();
        if n < FAST_KERNEL_SPHERES {
            self.mobility.interaction_velocities(
                self.mu,
                &self.pos,
                &self.radii,
                &self.forces,
                &mut self.u,
            );
            return;
        }
        self.fill_soa();
        self.soa_u.resize(n, [0.0; 3]);
        pairs::interaction_velocities(
            self.mobility,
            self.mu,
            &self.soa,
            &mut self.soa_u,
            n >= PARALLEL_SPHERES,
        );
        for (u, v) in self.u.iter_mut().zip(&self.soa_u) {
            *u = Vector3::new(v[0], v[1], v[2]);
        }
    }

    fn fill_soa(&mut self) {
        let n = self.pos.len();
        let s = &mut self.soa;
        s.resize(n);
        for (i, (p, f)) in self.pos.iter().zip(&self.forces).enumerate() {
            s.x[i] = p.x;
            s.y[i] = p.y;
            s.z[i] = p.z;
            s.a2[i] = self.radii[i] * self.radii[i];
            s.fx[i] = f.x;
            s.fy[i] = f.y;
            s.fz[i] = f.z;
        }
    }

    /// The smallest gap between two spheres (m) at the current positions and the spheres that
    /// have it; `None` with fewer than two spheres.
    pub(crate) fn min_gap(&mut self) -> Option<(f64, usize, usize)> {
        self.fill_soa();
        pairs::min_gap(&self.soa, &self.radii, self.pos.len() >= PARALLEL_SPHERES)
    }

    /// The force on sphere 1 of dumbbell `s` set by the last [`Spheres::interact`].
    #[inline]
    pub(crate) fn force(&self, s: usize) -> Vector3<f64> {
        self.forces[2 * s]
    }

    /// dR_H/dt of dumbbell `s` = (a1 u₁ + a2 u₂)/(a1+a2): the drag parts cancel exactly (the
    /// dumbbell is force-free and R_H its centre of friction), so they are never added.
    #[inline]
    pub(crate) fn center_rate(&self, s: usize, d: &Dumbbell) -> Vector3<f64> {
        d.w1() * self.u[2 * s] + d.w2() * self.u[2 * s + 1]
    }

    /// u₂ − u₁ of dumbbell `s`: the interaction part of its spheres' relative velocity.
    #[inline]
    pub(crate) fn relative_rate(&self, s: usize) -> Vector3<f64> {
        self.u[2 * s + 1] - self.u[2 * s]
    }

    /// The first pair of overlapping spheres at the current positions, as a problem naming the
    /// swimmers.
    pub(crate) fn first_overlap(&mut self) -> Option<Problem> {
        if self.pos.len() >= FAST_KERNEL_SPHERES {
            return match self.min_gap() {
                Some((gap, a, b)) if gap <= 0.0 => Some(overlap_problem(gap, a, b)),
                _ => None,
            };
        }
        let (pos, radii) = (&self.pos, &self.radii);
        let n = pos.len();
        for a in 0..n {
            for b in (a + 1)..n {
                let gap = (pos[a] - pos[b]).norm() - radii[a] - radii[b];
                if gap <= 0.0 {
                    return Some(overlap_problem(gap, a, b));
                }
            }
        }
        None
    }
}

/// The guard's report of spheres `a` < `b` overlapping by −`gap`.
fn overlap_problem(gap: f64, a: usize, b: usize) -> Problem {
    let (sa, sb) = (a / 2, b / 2);
    let cause = if sa == sb {
        format!("the two spheres of swimmer {sa} overlap (gap {gap:.3e} m)")
    } else {
        format!(
            "sphere {} of swimmer {sa} overlaps sphere {} of swimmer {sb} (gap {gap:.3e} m)",
            a % 2 + 1,
            b % 2 + 1
        )
    };
    Problem {
        swimmer: Some(sa),
        cause,
        hint: "start the swimmers further apart, or use a smaller time step if the overlap came from a step that was too large".into(),
    }
}
