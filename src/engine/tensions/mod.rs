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
//! beyond by the diagonal. Every iteration starts from the tensions of the last solves,
//! extrapolated in time to this one's ([`PastTensions`]); where it stalls, the blocks and elimination
//! take over. No route has an S³ term but the elimination of a few swimmers and that fallback.
//!
//! - `earlier.rs`: the earlier solves' tensions, extrapolated in time to an iteration's start;
//! - `fill.rs`: K from blocks, or from the pair coefficients in vector lanes;
//! - `lower.rs`: K's products from its part on and below the diagonal.

mod earlier;
mod fill;
mod lower;

use super::boundary::{Boundary, PairTerms};
use super::cg::{cg, CgVectors};
use super::mobility::self_mobility;
use super::spheres::Spheres;
use super::swimmer::Dumbbell;
use earlier::PastTensions;
use fill::{fill_blocks, fill_pairs};
use lower::lower_mul_to;
use nalgebra::{DMatrix, DVector, Vector3};

/// Up to this many swimmers outside a periodic box the tensions are eliminated densely: 4S²
/// blocks cost less there than filling K and iterating.
pub const ELIMINATE_UP_TO: usize = 8;

/// Up to this many swimmers outside a box K is held as a matrix (8 S² bytes: 32 MB at 2,048);
/// beyond, the iteration takes mobility products.
pub const DENSE_MATRIX_UP_TO: usize = 2048;

/// The tightest stopping rule of the iteration, the residual of K T = −L̇' as a fraction of
/// |L̇'|: ~1e4 times the rounding of one product. Runs whose integrator keeps no tolerance (fixed
/// steps) take it.
pub const TENSION_RTOL: f64 = 1e-12;

/// The loosest stopping rule: beyond it the iteration's error is no longer smooth enough in the
/// state for an adaptive step's error estimate.
pub const TENSION_RTOL_MAX: f64 = 1e-6;

/// The stopping rule of a run whose adaptive steps keep tolerance `tol`, relative to it. The
/// iteration's error is a bias the step's error estimate does not see, and it must stay smooth
/// in the state at the level that estimate reads. With Dormand-Prince at 1e-7 (`auto(1e-4)`'s
/// inner method): 16 swimmers in contact in open space gained 9, 0.36 and 0.09 times the run's
/// own error at residuals of 0.1, 0.01 and 1e-3 times `tol`; in a box 64 swimmers took 1.46
/// times the right-hand sides at 10 times `tol`, and none more below (the book, "The
/// rigid-stroke limit").
pub const TENSION_RTOL_PER_STEP_TOL: f64 = 1e-3;

/// The stopping rule for a run whose adaptive steps keep relative tolerance `step_tol` (`None`:
/// fixed steps): [`TENSION_RTOL_PER_STEP_TOL`] of it, within [`TENSION_RTOL`] and
/// [`TENSION_RTOL_MAX`].
pub fn tension_rtol_for(step_tol: Option<f64>) -> f64 {
    step_tol.map_or(TENSION_RTOL, |t| {
        (t * TENSION_RTOL_PER_STEP_TOL).clamp(TENSION_RTOL, TENSION_RTOL_MAX)
    })
}

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
    /// The route for `swimmers` dumbbells in `boundary`: over its mobility products where its
    /// pair coefficients do not give K exactly ([`PairTerms::exact`]) or K is too large to hold.
    pub fn for_scene(boundary: &Boundary, swimmers: usize) -> Self {
        if !boundary.geometry().pair_terms().exact() {
            Route::Products
        } else if swimmers <= ELIMINATE_UP_TO {
            Route::Eliminate
        } else if swimmers > DENSE_MATRIX_UP_TO {
            Route::Products
        } else {
            Route::Pairs
        }
    }
}

/// The solver with its scratch and the last tensions.
#[derive(Debug, Clone)]
pub struct Tensions {
    route: Route,
    k: DMatrix<f64>,
    /// The iteration's tensions: its start (extrapolated from `earlier`), then its solution.
    x: DVector<f64>,
    /// The last solves' tensions and times.
    earlier: PastTensions,
    forces: Vec<f64>,
    velocities: Vec<f64>,
    diag: DVector<f64>,
    /// The iteration's vectors.
    outer: CgVectors,
    /// How K's pair terms come from pair coefficients in the boundary: K itself on the pairs'
    /// route (open space, a wall's images), the preconditioner's on the products' (a box's
    /// minimum images).
    terms: PairTerms,
    /// Whether the products' iteration is preconditioned by open space's K (held in `k`),
    /// solved on the matrix, instead of the diagonal.
    open_space_preconditioner: bool,
    /// The preconditioner's inner iteration: its solution and vectors.
    inner_x: DVector<f64>,
    inner: CgVectors,
    products: usize,
    /// Whether the last solve ended in the elimination (on the elimination's route, always).
    eliminated: bool,
    /// The iteration's stopping rule: the residual's fraction of |L̇'|.
    rtol: f64,
}

impl Tensions {
    /// A solver for `swimmers` dumbbells in `boundary`.
    pub fn new(boundary: &Boundary, swimmers: usize) -> Self {
        Tensions {
            terms: boundary.geometry().pair_terms(),
            ..Self::by(Route::for_scene(boundary, swimmers), swimmers)
        }
    }

    /// A solver for `swimmers` dumbbells that takes `route`.
    pub fn by(route: Route, swimmers: usize) -> Self {
        // The products' iteration holds open space's K as its preconditioner where a matrix fits.
        let open_space_preconditioner = route == Route::Products && swimmers <= DENSE_MATRIX_UP_TO;
        let held = route != Route::Products || open_space_preconditioner;
        let zeros = || DVector::zeros(swimmers);
        Tensions {
            route,
            k: if held {
                DMatrix::zeros(swimmers, swimmers)
            } else {
                DMatrix::zeros(0, 0)
            },
            x: zeros(),
            earlier: PastTensions::default(),
            forces: vec![0.0; 6 * swimmers],
            velocities: vec![0.0; 6 * swimmers],
            diag: zeros(),
            outer: CgVectors::zeros(swimmers),
            terms: PairTerms::Open,
            open_space_preconditioner,
            inner_x: zeros(),
            inner: CgVectors::zeros(swimmers),
            products: 0,
            eliminated: false,
            rtol: TENSION_RTOL,
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

    /// Stop the iteration at residual `rtol` of |L̇'| ([`tension_rtol_for`] a run's tolerance).
    pub fn set_rtol(&mut self, rtol: f64) {
        self.rtol = rtol;
    }

    /// The iteration's stopping rule.
    pub fn rtol(&self) -> f64 {
        self.rtol
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
                fill_pairs(spheres, n, &self.terms, &mut self.k);
                self.iterate(spheres, swimmers, n, t, rate)
            }
            Route::Products => {
                if self.open_space_preconditioner {
                    fill_pairs(spheres, n, &self.terms, &mut self.k);
                }
                self.iterate(spheres, swimmers, n, t, rate)
            }
        };
        self.eliminated = !solved;

        if !solved {
            eliminate(spheres, n, &mut self.k, rate);
        }
        if rate.iter().all(|v| v.is_finite()) {
            self.earlier.push(t, rate);
        } else {
            self.earlier.clear();
        }
    }

    /// Conjugate gradients for K T = −rate from the earlier tensions, preconditioned by open
    /// space's K where it is held for the products' iteration, else by the diagonal; the tensions
    /// in `rate`. False (rate untouched) if the residual did not fall to the stopping rule.
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
            return true;
        }
        let Tensions {
            route,
            k,
            x,
            earlier,
            forces,
            velocities,
            diag,
            outer,
            open_space_preconditioner,
            inner_x,
            inner,
            products,
            rtol,
            ..
        } = self;
        let rtol = *rtol;
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
        if !(earlier.extrapolate(t, x) && x.iter().all(|v| v.is_finite())) {
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
        let open_space_preconditioner = *open_space_preconditioner;
        let precondition = |r: &DVector<f64>, z: &mut DVector<f64>| {
            if open_space_preconditioner {
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
        if !cg(x, outer, rtol * b_norm, max, apply, precondition) {
            earlier.clear();
            return false;
        }
        rate.copy_from(x);
        true
    }
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
    use crate::engine::rng::Rng;

    /// The product from K's lower part equals the full matrix's, whatever lies above the
    /// diagonal, serially and in runs of columns (two runs at 600 rows, three at 700): to the
    /// rounding of sums of a few hundred terms of either sign.
    #[test]
    fn the_lower_product_is_the_symmetric_matrix_applied() {
        let mut rng = Rng::new(0x2545_f491_4f6c_dd1d);
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

    /// `count` asymmetric dumbbells at random in a cube of side `side` (spheres may come close:
    /// the test wants off-diagonal weight), with their orientations and stroke rates.
    fn dumbbells(
        count: usize,
        side: f64,
        mobility: Mobility,
    ) -> (Spheres, Vec<Dumbbell>, Vec<Vector3<f64>>, DVector<f64>) {
        let mut rng = Rng::new(0x9e37_79b9_7f4a_7c15);
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
