//! The spheres of a set of dumbbells, as both sphere-resolved models (spring and rigid-stroke) see
//! them: radii, positions, the force on each, and the interaction velocities the mobility gives.
//! Sphere 2σ is dumbbell σ's a1 sphere, 2σ+1 its a2 sphere.

use super::boundary::Boundary;
use super::contacts::Contacts;
use super::integrators::Problem;
use super::mobility::{self_mobility, Mobility, MobilityOperator};
use super::open_space::{OpenSpace, FAST_KERNEL_SPHERES};
use super::pairs::SoaSpheres;
use super::parallel::PARALLEL_SPHERES;
use super::swimmer::Dumbbell;
use nalgebra::Vector3;

/// Sphere data and scratch of the sphere-resolved models.
#[derive(Debug, Clone)]
pub(crate) struct Spheres {
    pub(crate) mu: f64,
    /// The pair tensor of each dumbbell's own stiff part in the Jacobians (open space's: a box's
    /// images, smooth over a dumbbell's length, stay with the explicit rates).
    pub(crate) mobility: Mobility,
    pub(crate) radii: Vec<f64>,
    /// Positions (m), filled by the model before [`Spheres::interact`].
    pub(crate) pos: Vec<Vector3<f64>>,
    /// Force on every sphere: ±spring (or tension) plus steric forces.
    forces: Vec<Vector3<f64>>,
    /// The dumbbell force f(σ) on sphere 1 of each dumbbell.
    spring: Vec<Vector3<f64>>,
    /// The forces on every sphere that no dumbbell balances: steric repulsion between swimmers,
    /// the boundary's repulsion and the external forces (empty when there are none).
    body: Vec<Vector3<f64>>,
    /// The constant external force on every sphere (N; empty when none).
    external: Vec<Vector3<f64>>,
    /// Open space, a periodic box (whose minimum images the gaps and steric forces take) or a
    /// wall (whose repulsion joins the body forces).
    boundary: Boundary,
    /// Scratch of the mobility's divergence.
    div: Vec<Vector3<f64>>,
    contacts: Contacts,
    u: Vec<Vector3<f64>>,
    /// Scratch of the gap passes (large scenes).
    soa: SoaSpheres,
    /// The boundary's mobility: open space's pairs, a periodic box's Ewald sums, or a wall's.
    operator: Box<dyn MobilityOperator>,
}

impl Spheres {
    /// Spheres of these dumbbells in a fluid of viscosity `mu`.
    pub(crate) fn new(
        swimmers: &[Dumbbell],
        mu: f64,
        mobility: Mobility,
        contacts: Contacts,
    ) -> Self {
        let n = 2 * swimmers.len();
        Spheres {
            mu,
            mobility,
            radii: swimmers.iter().flat_map(|d| [d.a1, d.a2]).collect(),
            pos: vec![Vector3::zeros(); n],
            forces: vec![Vector3::zeros(); n],
            spring: vec![Vector3::zeros(); swimmers.len()],
            body: Vec::new(),
            external: Vec::new(),
            boundary: Boundary::Open,
            div: Vec::new(),
            contacts,
            u: vec![Vector3::zeros(); n],
            soa: SoaSpheres::default(),
            operator: Box::new(OpenSpace::new(mu, mobility)),
        }
    }

    /// Put the spheres in `boundary`, whose mobility is `operator` (open space until set).
    pub(crate) fn set_boundary(&mut self, boundary: Boundary, operator: Box<dyn MobilityOperator>) {
        self.soa.periodic = boundary.periodic().copied();
        self.boundary = boundary;
        self.operator = operator;
    }

    /// Put the constant force `external[α]` (N) on every sphere α (none when empty).
    pub(crate) fn set_external(&mut self, external: Vec<Vector3<f64>>) {
        self.external = external;
    }

    /// Whether some sphere carries a force that no dumbbell balances.
    fn has_body_forces(&self) -> bool {
        self.contacts.steric.is_some()
            || self.boundary.geometry().solid()
            || !self.external.is_empty()
    }

    /// The forces of [`Spheres::body`] at the current positions.
    fn body_forces(&mut self) {
        let n = self.pos.len();
        self.body.clear();
        if !self.has_body_forces() {
            return;
        }
        match self.external.is_empty() {
            true => self.body.resize(n, Vector3::zeros()),
            false => self.body.extend_from_slice(&self.external),
        }
        if let Some(st) = self.contacts.steric {
            st.add_forces(
                &self.pos,
                &self.radii,
                self.boundary.periodic(),
                &mut self.body,
                n >= PARALLEL_SPHERES,
            );
        }
        self.boundary
            .geometry()
            .add_forces(&self.pos, &self.radii, &mut self.body);
    }

    /// The velocities the body forces alone give every sphere, M F^b, self drag included, into
    /// `out`; `false` (nothing written) when there are none or all are zero. The rigid-stroke
    /// model's constraints take them out of the tensions' right-hand side.
    pub(crate) fn body_velocities(&mut self, out: &mut Vec<Vector3<f64>>) -> bool {
        self.body_forces();
        // None, or all zero (no swimmer within the steric range, none near the wall): M·0 = 0
        // without a product.
        if self.body.iter().all(|b| *b == Vector3::zeros()) {
            return false;
        }
        std::mem::swap(&mut self.forces, &mut self.body);
        self.pair_velocities();
        std::mem::swap(&mut self.forces, &mut self.body);
        out.clear();
        out.extend(
            self.u
                .iter()
                .zip(&self.body)
                .zip(&self.radii)
                .map(|((u, f), a)| u + f * self_mobility(self.mu, *a)),
        );
        true
    }

    /// Add the Itô drift kT ∇·M to the velocities of the last [`Spheres::interact`], where the
    /// boundary's mobility varies with the positions (near a wall).
    pub(crate) fn add_thermal_drift(&mut self, kt: f64) {
        self.div.resize(self.pos.len(), Vector3::zeros());
        if self
            .operator
            .divergence(&self.pos, &self.radii, &mut self.div)
        {
            for (u, d) in self.u.iter_mut().zip(&self.div) {
                *u += d * kt;
            }
        }
    }

    /// H_αβ v for spheres α, β (α = β: the self block, Stokes drag included).
    pub(crate) fn block_apply(&self, alpha: usize, beta: usize, v: &Vector3<f64>) -> Vector3<f64> {
        let (ai, aj) = (self.radii[alpha], self.radii[beta]);
        let (xa, xb) = (&self.pos[alpha], &self.pos[beta]);
        self.operator.block(xa, xb, ai, aj, alpha == beta) * v
    }

    /// The full mobility matrix at the current positions.
    pub(crate) fn mobility_matrix(&self) -> nalgebra::DMatrix<f64> {
        self.operator.matrix(&self.pos, &self.radii)
    }

    /// Put force `f(σ)` on sphere 1 and −f(σ) on sphere 2 of every dumbbell (each dumbbell is
    /// force-free) and compute the interaction velocities u_α = Σ_{β≠α} H_αβ F_β.
    ///
    /// The body forces F^b (steric repulsion, the boundary's repulsion, external forces) join
    /// the others and u_α also carries their own drag F^b_α/(6πμa_α) (they are not force-free
    /// per dumbbell, so that part does not cancel).
    #[inline]
    pub(crate) fn interact(&mut self, f: impl Fn(usize) -> Vector3<f64>) {
        for s in 0..self.radii.len() / 2 {
            let fs = f(s);
            self.spring[s] = fs;
            self.forces[2 * s] = fs;
            self.forces[2 * s + 1] = -fs;
        }
        self.body_forces();
        for (f, b) in self.forces.iter_mut().zip(&self.body) {
            *f += b;
        }
        self.pair_velocities();
        for ((u, b), a) in self.u.iter_mut().zip(&self.body).zip(&self.radii) {
            *u += b * self_mobility(self.mu, *a);
        }
    }

    /// Velocities M·F for arbitrary sphere forces `f` (flat, 3 per sphere) at the current positions,
    /// self drag included, into `out`: the mobility as an operator (the Lanczos square root).
    pub(crate) fn apply_mobility(&mut self, f: &[f64], out: &mut [f64]) {
        for (a, force) in self.forces.iter_mut().enumerate() {
            *force = Vector3::new(f[3 * a], f[3 * a + 1], f[3 * a + 2]);
        }
        self.pair_velocities();
        for (a, (u, r)) in self.u.iter().zip(&self.radii).enumerate() {
            let v = u + self.forces[a] * self_mobility(self.mu, *r);
            out[3 * a..3 * a + 3].copy_from_slice(v.as_slice());
        }
    }

    /// u_α = (W F)_α for the forces set: every velocity beyond each sphere's Stokes drag.
    fn pair_velocities(&mut self) {
        self.operator
            .interaction_velocities(&self.pos, &self.radii, &self.forces, &mut self.u);
    }

    /// The force on sphere 1 of dumbbell `s` set by the last [`Spheres::interact`].
    #[inline]
    pub(crate) fn force(&self, s: usize) -> Vector3<f64> {
        self.spring[s]
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
    /// swimmers; with overlaps between swimmers allowed, only a dumbbell's own spheres count.
    pub(crate) fn first_overlap(&mut self) -> Option<Problem> {
        let owner = |a: usize| (a / 2, a % 2 + 1);
        let g = self.boundary.geometry();
        if let Some(p) = g.touching(&self.pos, &self.radii, &owner) {
            return Some(p);
        }
        if self.contacts.allow_overlap {
            return (0..self.pos.len() / 2).find_map(|s| {
                let gap = (self.pos[2 * s] - self.pos[2 * s + 1]).norm()
                    - self.radii[2 * s]
                    - self.radii[2 * s + 1];
                (gap <= 0.0).then(|| overlap_problem(gap, 2 * s, 2 * s + 1))
            });
        }
        if self.pos.len() >= FAST_KERNEL_SPHERES {
            self.soa.fill(&self.pos, &self.radii, None);
            let parallel = self.pos.len() >= PARALLEL_SPHERES;
            return super::gaps::closest_overlap(&self.soa, &self.radii, parallel)
                .map(|(gap, a, b)| overlap_problem(gap, a, b));
        }
        let (pos, radii) = (&self.pos, &self.radii);
        let n = pos.len();
        for a in 0..n {
            for b in (a + 1)..n {
                let gap = g.separation(pos[a] - pos[b]).norm() - radii[a] - radii[b];
                if gap <= 0.0 {
                    return Some(overlap_problem(gap, a, b));
                }
            }
        }
        None
    }
}

/// The guard's report of spheres `a` < `b` overlapping by −`gap`.
pub(crate) fn overlap_problem(gap: f64, a: usize, b: usize) -> Problem {
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
        hint: if sa == sb {
            "use a smaller time step (an explicit step above its stability limit collapses the spring), or a shorter stroke".into()
        } else {
            "start the swimmers further apart or take a smaller time step".into()
        },
        fixes: if sa == sb {
            Vec::new()
        } else {
            vec![
                crate::engine::error::Setting::AllowOverlaps,
                crate::engine::error::Setting::Steric,
            ]
        },
    }
}
