//! The rigid-stroke model's constraint tensions: the S×S system K T = −L̇' of its dumbbells, solved
//! at every right-hand side.
//!
//! With tension T_τ on dumbbell τ (force +T N on sphere 1, −T N on sphere 2), B T the sphere
//! forces and M the mobility, K = BᵀMB: K_στ = N_σ·(H_{1σ,1τ} − H_{1σ,2τ} − H_{2σ,1τ} + H_{2σ,2τ})N_τ,
//! symmetric positive definite wherever M is. The right side L̇' is each stroke's length rate less
//! what the body forces' velocities already give it.
//!
//! How K is met depends on what a block costs ([`Route`]):
//! - a few swimmers outside a box: K from the boundary's blocks, Gaussian elimination;
//! - open space and above a wall: K from the pair coefficients (above a wall, open space's and
//!   the image's, of the spheres lifted and damped as the wall's mobility takes them), contracted
//!   with the orientations as it is filled, its part on and below the diagonal alone (K is
//!   symmetric: S²/2 entries of four sphere pairs each, about the cost of one mobility product),
//!   then conjugate gradients on the matrix, whose products read that part alone;
//! - a periodic box (whose blocks are whole Ewald sums) and beyond [`DENSE_MATRIX_UP_TO`]
//!   swimmers: conjugate gradients over mobility products (K T is one product), no matrix of K
//!   itself.
//!
//! The iteration on a matrix is preconditioned by each dumbbell's own K_σσ; the iteration over
//! products (up to [`DENSE_MATRIX_UP_TO`] swimmers) by open space's K at the minimum images,
//! filled as above and solved on the matrix (an inner iteration, hence the flexible β), and
//! beyond by the diagonal. Every iteration starts from the last solve's tensions; where it
//! stalls, the blocks and elimination take over. No route has an S³ term but the
//! elimination of a few swimmers and that fallback.

use super::boundary::Boundary;
use super::cg::{cg, CgVectors};
use super::mobility::self_mobility;
use super::parallel::{map_indices, PARALLEL_IMAGE_SPHERES, PARALLEL_SPHERES};
use super::periodic::{separation, PeriodicBox};
use super::simd::{lane_sum, vector_dispatch, LANES};
use super::spheres::Spheres;
use super::swimmer::Dumbbell;
use super::wall::{image_coefficients, Wall};
use nalgebra::{DMatrix, DVector, Vector3};
use rayon::prelude::*;

/// Up to this many swimmers outside a periodic box the tensions are eliminated densely: 4S²
/// blocks cost less there than filling K and iterating.
pub const ELIMINATE_UP_TO: usize = 8;

/// Up to this many swimmers outside a box K is held as a matrix (8 S² bytes: 32 MB at 2,048);
/// beyond, the iteration takes mobility products.
pub const DENSE_MATRIX_UP_TO: usize = 2048;

/// The iteration stops when the residual of K T = −L̇' is this fraction of |L̇'|: far below any
/// integrator tolerance the tensions feed (a relative tension error ε moves a centre by about ε
/// times its stroke-scale oscillation, 1e-6 of which is the drift per period), and ~1e4 times
/// the rounding of one product.
pub const TENSION_RTOL: f64 = 1e-12;

/// The preconditioner's inner iteration stops at this fraction of its right side: tight enough
/// that the outer iteration sees nearly one linear map, loose enough to cost few matrix products.
const INNER_RTOL: f64 = 1e-10;

/// Iterations before the elimination takes over (CG ends in S in exact arithmetic; at the
/// densities the model holds it takes tens).
const MAX_ITERATIONS: usize = 500;

/// How K is met.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Route {
    /// From blocks, eliminated.
    Eliminate,
    /// Filled from the pair coefficients (open space's, and above a wall its image's too),
    /// iterated on the matrix.
    Pairs,
    /// Iterated over mobility products.
    Products,
}

impl Route {
    /// The route for `swimmers` dumbbells in `boundary`.
    pub fn for_scene(boundary: &Boundary, swimmers: usize) -> Self {
        match boundary {
            Boundary::Periodic(_) => Route::Products,
            _ if swimmers <= ELIMINATE_UP_TO => Route::Eliminate,
            _ if swimmers > DENSE_MATRIX_UP_TO => Route::Products,
            Boundary::Open | Boundary::Wall(_) => Route::Pairs,
        }
    }
}

/// The solver with its scratch and the last tensions.
#[derive(Debug, Clone)]
pub struct Tensions {
    route: Route,
    k: DMatrix<f64>,
    /// The last tensions (the next iteration's start), when `warm`.
    last: DVector<f64>,
    warm: bool,
    forces: Vec<f64>,
    velocities: Vec<f64>,
    diag: DVector<f64>,
    /// The iteration's vectors.
    outer: CgVectors,
    /// The box, whose minimum images the open-space K of the preconditioner takes.
    periodic: Option<PeriodicBox>,
    /// The wall, whose image terms K filled from pairs takes.
    wall: Option<Wall>,
    /// Whether the products' iteration is preconditioned by open space's K (held in `k`),
    /// solved on the matrix, instead of the diagonal.
    near: bool,
    /// The preconditioner's inner iteration: its solution and vectors.
    inner_x: DVector<f64>,
    inner: CgVectors,
    products: usize,
    /// Whether the last solve ended in the elimination (on the elimination's route, always).
    eliminated: bool,
}

impl Tensions {
    /// A solver for `swimmers` dumbbells in `boundary`.
    pub fn new(boundary: &Boundary, swimmers: usize) -> Self {
        let mut t = Self::by(Route::for_scene(boundary, swimmers), swimmers);
        match boundary {
            Boundary::Periodic(b) => t.periodic = Some(*b),
            Boundary::Wall(w) => t.wall = Some(*w),
            Boundary::Open => {}
        }
        t
    }

    /// A solver for `swimmers` dumbbells that takes `route`.
    pub fn by(route: Route, swimmers: usize) -> Self {
        // The products' iteration holds open space's K as its preconditioner where a matrix fits.
        let near = route == Route::Products && swimmers <= DENSE_MATRIX_UP_TO;
        let held = route != Route::Products || near;
        let zeros = || DVector::zeros(swimmers);
        Tensions {
            route,
            k: if held {
                DMatrix::zeros(swimmers, swimmers)
            } else {
                DMatrix::zeros(0, 0)
            },
            last: zeros(),
            warm: false,
            forces: vec![0.0; 6 * swimmers],
            velocities: vec![0.0; 6 * swimmers],
            diag: zeros(),
            outer: CgVectors::zeros(swimmers),
            periodic: None,
            wall: None,
            near,
            inner_x: zeros(),
            inner: CgVectors::zeros(swimmers),
            products: 0,
            eliminated: false,
        }
    }

    /// The route taken.
    pub fn route(&self) -> Route {
        self.route
    }

    /// Mobility products the last solve took (0 on the matrix routes).
    pub fn products(&self) -> usize {
        self.products
    }

    /// Whether the last solve's iteration stalled and the blocks and elimination took over.
    pub fn fell_back(&self) -> bool {
        self.eliminated && self.route != Route::Eliminate
    }

    /// Replace `rate` (L̇' per dumbbell) by the tensions (N), for the spheres placed in `spheres`
    /// at time `t` with orientations `n`; NaN where K is singular.
    pub(crate) fn solve(
        &mut self,
        spheres: &mut Spheres,
        swimmers: &[Dumbbell],
        n: &[Vector3<f64>],
        t: f64,
        rate: &mut DVector<f64>,
    ) {
        self.products = 0;
        let solved = match self.route {
            Route::Eliminate => false,
            Route::Pairs => {
                fill_pairs(spheres, n, Fill::of(None, self.wall.as_ref()), &mut self.k);
                self.iterate(spheres, swimmers, n, t, rate)
            }
            Route::Products => {
                if self.near {
                    let fill = Fill::of(self.periodic.as_ref(), None);
                    fill_pairs(spheres, n, fill, &mut self.k);
                }
                self.iterate(spheres, swimmers, n, t, rate)
            }
        };
        self.eliminated = !solved;
        if !solved {
            eliminate(spheres, n, &mut self.k, rate);
            self.last.copy_from(rate);
            self.warm = true;
        }
    }

    /// Conjugate gradients for K T = −rate from the last tensions, preconditioned by open
    /// space's K where it is held for the products' iteration, else by the diagonal; the tensions
    /// in `rate`. False (rate untouched) if the residual did not fall to [`TENSION_RTOL`].
    fn iterate(
        &mut self,
        spheres: &mut Spheres,
        swimmers: &[Dumbbell],
        n: &[Vector3<f64>],
        t: f64,
        rate: &mut DVector<f64>,
    ) -> bool {
        let b_norm = rate.norm();
        if b_norm == 0.0 {
            self.last.fill(0.0);
            self.warm = true;
            return true;
        }
        let Tensions {
            route,
            k,
            last: x,
            warm,
            forces,
            velocities,
            diag,
            outer,
            near,
            inner_x,
            inner,
            products,
            ..
        } = self;
        // Jacobi: each dumbbell's own K_σσ, K's own where it is filled from pairs (above a wall
        // it holds the image's terms), else open space's, 1/(6πμa1) + 1/(6πμa2) − 2 N·H₁₂N.
        let (mu, mobility) = (spheres.mu, spheres.mobility);
        for (s, d) in swimmers.iter().enumerate() {
            diag[s] = if *route == Route::Pairs {
                k[(s, s)]
            } else {
                let (ci, crr) = mobility.pair_coefficients(mu, d.rest_length(t), d.a1, d.a2);
                self_mobility(mu, d.a1) + self_mobility(mu, d.a2) - 2.0 * (ci + crr)
            };
        }
        if !(*warm && x.iter().all(|v| v.is_finite())) {
            x.zip_apply(rate, |xs, b| *xs = -b);
            x.component_div_assign(diag);
        }
        // q = K p, by the matrix or by one mobility product (forces +p N on sphere 1, −p N on
        // sphere 2; then N·(u₁ − u₂) per dumbbell).
        let by_products = *route == Route::Products;
        let k = &*k;
        let mut apply = |p: &DVector<f64>, q: &mut DVector<f64>| {
            if !by_products {
                lower_mul_to(k, p, q);
                return;
            }
            for (s, ns) in n.iter().enumerate() {
                let v = p[s] * ns;
                forces[6 * s..6 * s + 3].copy_from_slice(v.as_slice());
                forces[6 * s + 3..6 * s + 6].copy_from_slice((-v).as_slice());
            }
            spheres.apply_mobility(forces, velocities);
            for (s, ns) in n.iter().enumerate() {
                let u = &velocities[6 * s..6 * s + 6];
                q[s] = ns.dot(&Vector3::new(u[0] - u[3], u[1] - u[4], u[2] - u[5]));
            }
            *products += 1;
        };
        // z = P⁻¹ r: open space's K solved on the matrix (Jacobi CG to INNER_RTOL) where it is
        // held, else (or where that stalls) the diagonal.
        let near = *near;
        let precondition = |r: &DVector<f64>, z: &mut DVector<f64>| {
            if near {
                inner_x.fill(0.0);
                inner.r.copy_from(r);
                let goal = INNER_RTOL * r.norm();
                let solved = cg(
                    inner_x,
                    inner,
                    goal,
                    MAX_ITERATIONS.min(r.len() + 50),
                    |p, q| lower_mul_to(k, p, q),
                    // Jacobi on K's own diagonal, read in place.
                    |r, z| {
                        for (s, (zs, rs)) in z.iter_mut().zip(r.iter()).enumerate() {
                            *zs = rs / k[(s, s)];
                        }
                    },
                );
                if solved {
                    z.copy_from(inner_x);
                    return;
                }
            }
            z.zip_zip_apply(r, diag, |zs, rs, d| *zs = rs / d);
        };
        // r = b − K x with b = −rate.
        apply(x, &mut outer.q);
        outer
            .r
            .zip_zip_apply(rate, &outer.q, |rs, b, q| *rs = -b - q);
        let max = MAX_ITERATIONS.min(swimmers.len() + 50);
        if !cg(x, outer, TENSION_RTOL * b_norm, max, apply, precondition) {
            *warm = false;
            return false;
        }
        rate.copy_from(x);
        *warm = true;
        true
    }
}

/// K_στ from the boundary's blocks: 4 per pair of dumbbells.
fn k_entry(spheres: &Spheres, n: &[Vector3<f64>], sg: usize, tau: usize) -> f64 {
    let (i1, i2, j1, j2) = (2 * sg, 2 * sg + 1, 2 * tau, 2 * tau + 1);
    let nt = n[tau];
    let h = |a, b| spheres.block_apply(a, b, &nt);
    n[sg].dot(&((h(i1, j1) - h(i2, j1)) - (h(i1, j2) - h(i2, j2))))
}

/// K filled from the boundary's blocks.
fn fill_blocks(spheres: &Spheres, n: &[Vector3<f64>], k: &mut DMatrix<f64>) {
    let count = n.len();
    for tau in 0..count {
        for sg in 0..=tau {
            let v = k_entry(spheres, n, sg, tau);
            k[(sg, tau)] = v;
            k[(tau, sg)] = v;
        }
    }
}

/// Where the pairs of a K filled from pair coefficients lie.
#[derive(Debug, Clone, Copy)]
enum Fill<'a> {
    /// Open space.
    Open,
    /// Open space at the box's minimum images (the preconditioner of a box's iteration).
    MinimumImages(&'a PeriodicBox),
    /// Above a wall: open space's pairs and the wall's image terms, of the spheres lifted and
    /// damped as the wall's mobility takes them ([`Wall::lift`]).
    Wall(&'a Wall),
}

impl<'a> Fill<'a> {
    fn of(periodic: Option<&'a PeriodicBox>, wall: Option<&'a Wall>) -> Self {
        match (periodic, wall) {
            (Some(b), _) => Fill::MinimumImages(b),
            (None, Some(w)) => Fill::Wall(w),
            (None, None) => Fill::Open,
        }
    }
}

/// The dumbbells as a K fill reads them: sphere centres (above a wall: relative to it, lifted),
/// radii, squared radii, damping factors (1 off a wall) and orientations in lanes, and the
/// constants of the pair tensor.
struct KLanes {
    p1: [Vec<f64>; 3],
    p2: [Vec<f64>; 3],
    n: [Vec<f64>; 3],
    a1: Vec<f64>,
    a2: Vec<f64>,
    q1: Vec<f64>,
    q2: Vec<f64>,
    d1: Vec<f64>,
    d2: Vec<f64>,
    /// 1/(8πμ).
    c8: f64,
    /// 1/3 for RPY (its a² term), 0 for Oseen.
    finite: f64,
    /// Whether the image radii are the radii (RPY; Oseen's image is a point force's).
    images_sized: bool,
    /// The box's sides and their inverses for minimum images (zeros elsewhere).
    l: [f64; 3],
    inv_l: [f64; 3],
}

/// A sphere as [`k_term`] reads it: its centre, radius, squared radius and damping factor.
type KSphere = ([f64; 3], f64, f64, f64);

/// One sphere pair's term of a K entry, N_σ·H_ab N_τ (with `WALL` the image term and the
/// damping), for sphere `a` of σ (whose velocity the row takes) and `b` of τ (whose force the
/// column applies), orientations `ns`, `nt` (`nn` their product); and d² − (a_a + a_b)².
#[inline(always)]
fn k_term<const WALL: bool>(
    l: &KLanes,
    ns: [f64; 3],
    nt: [f64; 3],
    nn: f64,
    (a, aa, qa, da): KSphere,
    (b, ab, qb, db): KSphere,
) -> (f64, f64) {
    let c8 = l.c8;
    // The minimum image (zeros outside a box); a tie between two images takes either, and the
    // term is even in r. `round_ties_even` is one vector instruction, `round` a call.
    let mut r = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    for d in 0..3 {
        r[d] -= l.l[d] * (r[d] * l.inv_l[d]).round_ties_even();
    }
    let d2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    let inv_d2 = 1.0 / d2;
    let o = c8 * inv_d2.sqrt();
    let f = l.finite * (qa + qb) * inv_d2 * o;
    let nsr = ns[0] * r[0] + ns[1] * r[1] + ns[2] * r[2];
    let ntr = nt[0] * r[0] + nt[1] * r[1] + nt[2] * r[2];
    let mut value = (o + f) * nn + (o - 3.0 * f) * nsr * ntr * inv_d2;
    if WALL {
        // R = x_a − x_b*: the in-plane separation, and the heights' sum.
        let sized = if l.images_sized { 1.0 } else { 0.0 };
        let r3 = a[2] + b[2];
        let q = 1.0 / (r[0] * r[0] + r[1] * r[1] + r3 * r3).sqrt();
        let (ca, cb, cc, cd, ce) = image_coefficients(r3, b[2], sized * qa, sized * qb, q);
        let rs = ns[0] * r[0] + ns[1] * r[1];
        let rt = nt[0] * r[0] + nt[1] * r[1];
        let w = ca * (ns[0] * nt[0] + ns[1] * nt[1])
            + rs * (cb * rt + cc * nt[2])
            + ns[2] * (cd * rt + ce * nt[2]);
        value = (value + c8 * w) * (da * db);
    }
    let sum = aa + ab;
    (value, d2 - sum * sum)
}

/// Column τ of K for σ = τ, τ + 1, … (its part on and below the diagonal, `col[0]` the
/// diagonal) by the far-apart pair tensor (c_I = o + f, c_rr = o − 3f with o = 1/(8πμd),
/// f = (a_i² + a_j²) o/(3d²)), with `WALL` the wall's image term W_ab (its coefficients
/// [`image_coefficients`]) added and each sphere pair's term damped by d_a d_b; and in `margin`
/// the least d² − (a_i + a_j)² of the four sphere pairs (≤ 0 where a pair overlaps and the far
/// form does not hold).
#[inline(always)]
fn k_column_impl<const WALL: bool>(l: &KLanes, tau: usize, col: &mut [f64], margin: &mut [f64]) {
    let t1 = [l.p1[0][tau], l.p1[1][tau], l.p1[2][tau]];
    let t2 = [l.p2[0][tau], l.p2[1][tau], l.p2[2][tau]];
    let nt = [l.n[0][tau], l.n[1][tau], l.n[2][tau]];
    let (ta1, ta2, tq1, tq2) = (l.a1[tau], l.a2[tau], l.q1[tau], l.q2[tau]);
    let (td1, td2) = (l.d1[tau], l.d2[tau]);
    for (row, (entry, least)) in col.iter_mut().zip(margin.iter_mut()).enumerate() {
        let sg = tau + row;
        let ns = [l.n[0][sg], l.n[1][sg], l.n[2][sg]];
        let nn = ns[0] * nt[0] + ns[1] * nt[1] + ns[2] * nt[2];
        let s1 = [l.p1[0][sg], l.p1[1][sg], l.p1[2][sg]];
        let s2 = [l.p2[0][sg], l.p2[1][sg], l.p2[2][sg]];
        let (sa1, sa2, sq1, sq2) = (l.a1[sg], l.a2[sg], l.q1[sg], l.q2[sg]);
        let (sd1, sd2) = (l.d1[sg], l.d2[sg]);
        let (u1, u2) = ((s1, sa1, sq1, sd1), (s2, sa2, sq2, sd2));
        let (v1, v2) = ((t1, ta1, tq1, td1), (t2, ta2, tq2, td2));
        let (k11, m11) = k_term::<WALL>(l, ns, nt, nn, u1, v1);
        let (k12, m12) = k_term::<WALL>(l, ns, nt, nn, u1, v2);
        let (k21, m21) = k_term::<WALL>(l, ns, nt, nn, u2, v1);
        let (k22, m22) = k_term::<WALL>(l, ns, nt, nn, u2, v2);
        *entry = (k11 - k12) - (k21 - k22);
        *least = m11.min(m12).min(m21).min(m22);
    }
}

/// [`k_column_impl`] in open space (or at minimum images).
#[inline(always)]
fn k_column_body(l: &KLanes, tau: usize, col: &mut [f64], margin: &mut [f64]) {
    k_column_impl::<false>(l, tau, col, margin);
}

/// [`k_column_impl`] above a wall.
#[inline(always)]
fn k_wall_column_body(l: &KLanes, tau: usize, col: &mut [f64], margin: &mut [f64]) {
    k_column_impl::<true>(l, tau, col, margin);
}

vector_dispatch! {
    /// [`k_column_body`] in the widest vector unit present.
    fn k_column(l: &KLanes, tau: usize, col: &mut [f64], margin: &mut [f64]) = k_column_body;
}

vector_dispatch! {
    /// [`k_wall_column_body`] in the widest vector unit present.
    fn k_wall_column(l: &KLanes, tau: usize, col: &mut [f64], margin: &mut [f64]) = k_wall_column_body;
}

/// K filled from the pair coefficients, each sphere pair's tensor contracted with the two
/// orientations as it is made: N_σ·H N_τ = c_I N_σ·N_τ + c_rr (N_σ·r)(N_τ·r)/r² (and above a
/// wall N_σ·W N_τ, damped). Column by column in vector lanes (in parallel for many spheres); the
/// diagonal and any entry with overlapping spheres again exactly: by the pair coefficients, and
/// above a wall by the wall mobility's own blocks.
fn fill_pairs(spheres: &Spheres, n: &[Vector3<f64>], fill: Fill, k: &mut DMatrix<f64>) {
    let periodic = match fill {
        Fill::MinimumImages(b) => Some(b),
        _ => None,
    };
    let l = periodic.map_or([0.0; 3], |b| b.sides());
    let inv_l = l.map(|v| if v > 0.0 { 1.0 / v } else { 0.0 });
    let count = n.len();
    let (mu, mobility) = (spheres.mu, spheres.mobility);
    let (pos, radii) = (&spheres.pos, &spheres.radii);
    // Each sphere as the fill reads it: lifted above a wall, with its damping factor.
    let placed = |i: usize| match fill {
        Fill::Wall(w) => w.lift(&pos[i], radii[i]),
        _ => (pos[i], 1.0),
    };
    let lane = |f: &dyn Fn(usize) -> f64| (0..count).map(f).collect::<Vec<f64>>();
    let lanes = KLanes {
        p1: [0, 1, 2].map(|c| lane(&|s| placed(2 * s).0[c])),
        p2: [0, 1, 2].map(|c| lane(&|s| placed(2 * s + 1).0[c])),
        n: [0, 1, 2].map(|c| lane(&|s| n[s][c])),
        a1: lane(&|s| radii[2 * s]),
        a2: lane(&|s| radii[2 * s + 1]),
        q1: lane(&|s| radii[2 * s] * radii[2 * s]),
        q2: lane(&|s| radii[2 * s + 1] * radii[2 * s + 1]),
        d1: lane(&|s| placed(2 * s).1),
        d2: lane(&|s| placed(2 * s + 1).1),
        c8: 1.0 / (8.0 * std::f64::consts::PI * mu),
        finite: if mobility == super::mobility::Mobility::Rpy {
            1.0 / 3.0
        } else {
            0.0
        },
        images_sized: mobility == super::mobility::Mobility::Rpy,
        l,
        inv_l,
    };
    let exact = |sg: usize, tau: usize| {
        if let Fill::Wall(_) = fill {
            return k_entry(spheres, n, sg, tau);
        }
        let (ns, nt) = (n[sg], n[tau]);
        let nn = ns.dot(&nt);
        let mut sum = 0.0;
        for (a, sign_a) in [(2 * sg, 1.0), (2 * sg + 1, -1.0)] {
            for (b, sign_b) in [(2 * tau, 1.0), (2 * tau + 1, -1.0)] {
                let term = if a == b {
                    self_mobility(mu, radii[a]) * nn
                } else {
                    let r = separation(periodic, pos[a] - pos[b]);
                    let d2 = r.norm_squared();
                    let (ci, crr) = mobility.pair_coefficients(mu, d2.sqrt(), radii[a], radii[b]);
                    ci * nn + crr * ns.dot(&r) * nt.dot(&r) / d2
                };
                sum += sign_a * sign_b * term;
            }
        }
        sum
    };
    let wall = matches!(fill, Fill::Wall(_));
    // Only the part on and below the diagonal: K is symmetric, and its products read that part
    // alone ([`lower_mul_to`]).
    let column = |tau: usize, col: &mut [f64], margin: &mut Vec<f64>| {
        let lower = &mut col[tau..];
        margin.resize(lower.len(), 0.0);
        if wall {
            k_wall_column(&lanes, tau, lower, margin);
        } else {
            k_column(&lanes, tau, lower, margin);
        }
        for (row, (entry, m)) in lower.iter_mut().zip(margin.iter()).enumerate() {
            if row == 0 || m.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                *entry = exact(tau + row, tau);
            }
        }
    };
    let data = k.as_mut_slice();
    // The fill has the 2S² sphere pairs of a product of 2S spheres; above a wall each carries
    // the image's terms too, so it goes to rayon's threads where the wall's product does.
    let parallel_from = if wall {
        PARALLEL_IMAGE_SPHERES
    } else {
        PARALLEL_SPHERES
    };
    if 2 * count >= parallel_from {
        data.par_chunks_mut(count)
            .enumerate()
            .for_each_init(Vec::new, |margin, (tau, col)| column(tau, col, margin));
    } else {
        let mut margin = Vec::new();
        for (tau, col) in data.chunks_mut(count).enumerate() {
            column(tau, col, &mut margin);
        }
    }
}

/// q = K p for a symmetric K of which only the part on and below the diagonal is read (the part
/// above may hold anything): each column's lower part once, as a dot product for q_τ and an axpy
/// for the rows below it.
///
/// A large K is taken in runs of columns of about [`LOWER_PRODUCT_RUN`] entries each, on rayon's
/// threads, each into a vector of its own, and those are added in order: how many runs there are
/// depends on S alone, so the result does not depend on the threads.
fn lower_mul_to(k: &DMatrix<f64>, p: &DVector<f64>, q: &mut DVector<f64>) {
    let count = p.len();
    let (k, p, q) = (k.as_slice(), p.as_slice(), q.as_mut_slice());
    let entries = count * (count + 1) / 2;
    let runs = (entries / LOWER_PRODUCT_RUN).clamp(1, 16);
    if runs == 1 {
        return lower_product(k, p, q, 0..count);
    }
    // Column boundaries that give each run about an equal share of the entries.
    let mut bounds = vec![0];
    let mut taken = 0;
    for tau in 0..count {
        taken += count - tau;
        if taken * runs >= entries * bounds.len() && bounds.len() < runs {
            bounds.push(tau + 1);
        }
    }
    bounds.push(count);
    let parts = map_indices(
        bounds.len() - 1,
        true,
        || (),
        |_, r| {
            let mut part = vec![0.0; count];
            lower_product(k, p, &mut part, bounds[r]..bounds[r + 1]);
            part
        },
    );
    q.fill(0.0);
    for part in &parts {
        for (qs, v) in q.iter_mut().zip(part) {
            *qs += v;
        }
    }
}

/// Entries of K's lower part per run of columns in [`lower_mul_to`] (runs from 512 rows): a run
/// reads 512 kB, tens of µs, far more than handing it to rayon's pool costs.
const LOWER_PRODUCT_RUN: usize = 1 << 16;

/// q = the columns `columns` of [`lower_mul_to`]'s product on the column-major entries `k` of an
/// S×S matrix (q is zeroed first).
#[inline(always)]
fn lower_product_body(k: &[f64], p: &[f64], q: &mut [f64], columns: std::ops::Range<usize>) {
    let count = p.len();
    q.fill(0.0);
    for tau in columns {
        let col = &k[tau * count..(tau + 1) * count];
        let (diag, below, rest) = (col[tau], &col[tau + 1..], &p[tau + 1..]);
        let pt = p[tau];
        for (qs, ks) in q[tau + 1..].iter_mut().zip(below) {
            *qs += ks * pt;
        }
        // The dot product in lanes (separate sums, so that it vectorises), then the tail.
        let mut lanes = [0.0; LANES];
        let (blocks, tail) = below.split_at(below.len() / LANES * LANES);
        for (kb, pb) in blocks.chunks_exact(LANES).zip(rest.chunks_exact(LANES)) {
            for l in 0..LANES {
                lanes[l] += kb[l] * pb[l];
            }
        }
        let mut dot = diag * pt + lane_sum(&lanes);
        for (ks, ps) in tail.iter().zip(&rest[blocks.len()..]) {
            dot += ks * ps;
        }
        q[tau] += dot;
    }
}

vector_dispatch! {
    /// [`lower_product_body`] in the widest vector unit present.
    fn lower_product(k: &[f64], p: &[f64], q: &mut [f64], columns: std::ops::Range<usize>) = lower_product_body;
}

/// The tensions by Gaussian elimination of K (from blocks) against −rate, into `rate`; NaN where
/// K is singular.
/// `k` is the solver's matrix, overwritten (made S×S where the route held none).
fn eliminate(spheres: &Spheres, n: &[Vector3<f64>], k: &mut DMatrix<f64>, rate: &mut DVector<f64>) {
    let count = n.len();
    if k.nrows() != count {
        *k = DMatrix::zeros(count, count);
    }
    fill_blocks(spheres, n, k);
    rate.neg_mut();
    if !solve_in_place(k, rate) {
        rate.fill(f64::NAN);
    }
}

/// Solve A x = b in place (x overwrites b) by Gaussian elimination with partial pivoting.
/// Returns false if A is singular.
fn solve_in_place(a: &mut DMatrix<f64>, b: &mut DVector<f64>) -> bool {
    let n = b.len();
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&i, &j| a[(i, col)].abs().total_cmp(&a[(j, col)].abs()))
            .unwrap_or(col);
        if a[(pivot, col)] == 0.0 || !a[(pivot, col)].is_finite() {
            return false;
        }
        if pivot != col {
            a.swap_rows(pivot, col);
            b.swap_rows(pivot, col);
        }
        for row in (col + 1)..n {
            let f = a[(row, col)] / a[(col, col)];
            for k in col..n {
                a[(row, k)] -= f * a[(col, k)];
            }
            b[row] -= f * b[col];
        }
    }
    for row in (0..n).rev() {
        let mut acc = b[row];
        for k in (row + 1)..n {
            acc -= a[(row, k)] * b[k];
        }
        b[row] = acc / a[(row, row)];
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::contacts::Contacts;
    use crate::engine::ewald::Ewald;
    use crate::engine::mobility::Mobility;
    use crate::engine::periodic::PeriodicBox;

    /// The product from K's lower part equals the full matrix's, whatever lies above the
    /// diagonal, serially and in runs of columns (two runs at 600 rows, three at 700): to the
    /// rounding of sums of a few hundred terms of either sign.
    #[test]
    fn the_lower_product_is_the_symmetric_matrix_applied() {
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        for count in [1, 7, 8, 9, 300, 600, 700] {
            let mut k = DMatrix::from_fn(count, count, |_, _| rng.uniform() - 0.5);
            k = &k + k.transpose();
            let p = DVector::from_fn(count, |_, _| rng.uniform() - 0.5);
            let want = &k * &p;
            for col in 1..count {
                for row in 0..col {
                    k[(row, col)] = f64::NAN;
                }
            }
            let mut got = DVector::zeros(count);
            lower_mul_to(&k, &p, &mut got);
            let err = (&got - &want).amax();
            assert!(
                got.iter().all(|v| v.is_finite()) && err < 1e-12,
                "{count} rows: error {err:e}"
            );
        }
    }

    #[test]
    fn elimination_solves_a_pivoting_system() {
        let mut a = DMatrix::from_row_slice(3, 3, &[0.0, 2.0, 1.0, 1.0, 1.0, 1.0, 2.0, 1.0, 3.0]);
        let x = DVector::from_vec(vec![1.0, -2.0, 0.5]);
        let mut b = &a * &x;
        assert!(solve_in_place(&mut a, &mut b));
        assert!((b - x).amax() < 1e-14);
    }

    /// A small generator of uniform numbers in [0, 1) (xorshift).
    struct Rng(u64);

    impl Rng {
        fn uniform(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }

        fn unit_vector(&mut self) -> Vector3<f64> {
            let z = 2.0 * self.uniform() - 1.0;
            let phi = 2.0 * std::f64::consts::PI * self.uniform();
            let rho = (1.0 - z * z).sqrt();
            Vector3::new(rho * phi.cos(), rho * phi.sin(), z)
        }
    }

    /// `count` asymmetric dumbbells at random in a cube of side `side` (spheres may come close:
    /// the test wants off-diagonal weight), with their orientations and stroke rates.
    fn dumbbells(
        count: usize,
        side: f64,
        mobility: Mobility,
    ) -> (Spheres, Vec<Dumbbell>, Vec<Vector3<f64>>, DVector<f64>) {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let mut d = Dumbbell::default();
        (d.a1, d.a2) = (0.225 * d.ell, 0.1125 * d.ell);
        let swimmers: Vec<Dumbbell> = (0..count)
            .map(|_| {
                let mut e = d;
                e.phase = std::f64::consts::TAU * rng.uniform();
                e
            })
            .collect();
        let contacts = Contacts {
            allow_overlap: true,
            steric: None,
        };
        let mut spheres = Spheres::new(&swimmers, 1e-3, mobility, contacts);
        let mut n = Vec::new();
        for (s, e) in swimmers.iter().enumerate() {
            let c =
                Vector3::new(rng.uniform(), rng.uniform(), rng.uniform()).add_scalar(-0.5) * side;
            let dir = rng.unit_vector();
            let (x1, x2) = e.sphere_positions(c, dir, e.rest_length(0.0));
            spheres.pos[2 * s] = x1;
            spheres.pos[2 * s + 1] = x2;
            n.push(dir);
        }
        let rate = DVector::from_iterator(
            count,
            swimmers.iter().map(|e| e.lambda * e.omega * e.phase.cos()),
        );
        (spheres, swimmers, n, rate)
    }

    /// Every route gives the eliminated tensions, each without falling back to them: to 1e-9 of
    /// the largest, the iteration's 1e-12 residual times K's condition number (tens here, where
    /// spheres come within a diameter) times at most √S between the 2-norm and the largest
    /// entry (23 at 520 swimmers); measured up to 1.5e-12.
    #[test]
    fn every_route_gives_the_eliminated_tensions() {
        // 520 swimmers at the same density: K filled on rayon's threads (from 128) and its
        // products in runs of columns (from 512).
        for (count, side) in [(40, 40e-6), (520, 94e-6)] {
            for mobility in [Mobility::Rpy, Mobility::Oseen] {
                routes_agree(count, side, mobility);
            }
        }
    }

    fn routes_agree(count: usize, side: f64, mobility: Mobility) {
        let (mut spheres, swimmers, n, rate) = dumbbells(count, side, mobility);
        let mut want = rate.clone();
        Tensions::by(Route::Eliminate, count).solve(&mut spheres, &swimmers, &n, 0.0, &mut want);
        for route in [Route::Pairs, Route::Products] {
            let mut solver = Tensions::by(route, count);
            // Twice: the second solve starts from the first's tensions.
            for _ in 0..2 {
                let mut got = rate.clone();
                solver.solve(&mut spheres, &swimmers, &n, 0.0, &mut got);
                assert!(
                    !solver.fell_back(),
                    "{count} swimmers, {route:?}: fell back"
                );
                let err = (&got - &want).amax() / want.amax();
                assert!(
                    err < 1e-9,
                    "{count} swimmers, {mobility:?} {route:?}: relative error {err:e}"
                );
            }
            assert_eq!(solver.route(), route);
        }
    }

    /// `count` dumbbells in a cube of side `side` within `boundary` (its mobility `operator`):
    /// the products' iteration gives the tensions the blocks eliminate, to 1e-9 as above, and
    /// takes more than one product.
    fn products_match_elimination(
        count: usize,
        side: f64,
        boundary: Boundary,
        operator: Box<dyn crate::engine::mobility::MobilityOperator>,
    ) {
        let (mut spheres, swimmers, n, rate) = dumbbells(count, side, Mobility::Rpy);
        spheres.set_boundary(boundary, operator);
        let mut want = rate.clone();
        Tensions::by(Route::Eliminate, count).solve(&mut spheres, &swimmers, &n, 0.0, &mut want);
        let mut solver = Tensions::new(&boundary, count);
        assert_eq!(solver.route(), Route::Products);
        let mut got = rate.clone();
        solver.solve(&mut spheres, &swimmers, &n, 0.0, &mut got);
        assert!(solver.products() > 1 && !solver.fell_back());
        let err = (&got - &want).amax() / want.amax();
        assert!(err < 1e-9, "{boundary:?}: relative error {err:e}");
    }

    /// Above a wall, K filled from pairs (open space's and the image's in lanes, a sphere in the
    /// damped layer lifted; 40 swimmers, so filled on rayon's threads) and the iteration over the
    /// wall's products both give the tensions the blocks (the scalar Rotne-Prager-Blake terms)
    /// eliminate, RPY and Oseen, twice from the last tensions, each without falling back: to
    /// 1e-9, as in open space.
    #[test]
    fn wall_routes_give_the_eliminated_tensions() {
        use crate::engine::wall::{Wall, WallMobility};
        let count = 40;
        for mobility in [Mobility::Rpy, Mobility::Oseen] {
            let (mut spheres, swimmers, n, rate) = dumbbells(count, 40e-6, mobility);
            // Half a radius below the lowest centre: that sphere lies in the damped layer.
            let lowest = (0..spheres.pos.len())
                .min_by(|&a, &b| spheres.pos[a].z.total_cmp(&spheres.pos[b].z))
                .unwrap();
            let wall = Wall::at(spheres.pos[lowest].z - 0.5 * spheres.radii[lowest]).unwrap();
            let boundary = Boundary::Wall(wall);
            spheres.set_boundary(boundary, Box::new(WallMobility::new(1e-3, mobility, wall)));
            let mut want = rate.clone();
            Tensions::by(Route::Eliminate, count).solve(
                &mut spheres,
                &swimmers,
                &n,
                0.0,
                &mut want,
            );
            assert_eq!(Tensions::new(&boundary, count).route(), Route::Pairs);
            for mut solver in [
                Tensions::new(&boundary, count),
                Tensions::by(Route::Products, count),
            ] {
                for _ in 0..2 {
                    let mut got = rate.clone();
                    solver.solve(&mut spheres, &swimmers, &n, 0.0, &mut got);
                    assert!(
                        !solver.fell_back(),
                        "{mobility:?} {:?}: fell back",
                        solver.route()
                    );
                    let err = (&got - &want).amax() / want.amax();
                    let route = solver.route();
                    assert!(err < 1e-9, "{mobility:?} {route:?}: relative error {err:e}");
                }
            }
        }
    }

    /// In a periodic box the products (Ewald sums) give the tensions the blocks eliminate.
    #[test]
    fn boxed_products_give_the_eliminated_tensions() {
        let side = 30e-6;
        let b = PeriodicBox::new([side; 3]).unwrap();
        let ewald = Ewald::new(b, 1e-3, Mobility::Rpy, 24, 1e-13, None).unwrap();
        products_match_elimination(12, side, Boundary::Periodic(b), Box::new(ewald));
    }
}
