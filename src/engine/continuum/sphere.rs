//! Orientation space of the continuum: a Gauss product rule on the unit sphere and an
//! orthonormal basis of the real spherical harmonics up to degree L, held as polynomials in the
//! components of n so that their surface gradients are exact.

use std::f64::consts::PI;

/// The highest harmonic degree the continuum takes (its product rule then has 11 × 22 nodes).
pub const MAX_DEGREE: usize = 8;

/// Gauss-Legendre nodes and weights on [−1, 1] (`n` points, exact for degree 2n − 1), by Newton's
/// iteration on P_n from Chebyshev starting points.
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n {
        let mut z = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * z * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            let pn = if n == 0 { 1.0 } else { p1 };
            let pm = if n == 1 { 1.0 } else { p0 };
            dp = n as f64 * (z * pn - pm) / (z * z - 1.0);
            let dz = pn / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        x[i] = z;
        w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
    }
    (x, w)
}

/// A product rule on the unit sphere: `n` Gauss-Legendre nodes in cos θ times 2n equally spaced
/// azimuths, exact for every polynomial in n of degree ≤ 2n − 1; the weights add up to 4π.
pub fn product_rule(n: usize) -> (Vec<[f64; 3]>, Vec<f64>) {
    let (mu, wm) = gauss_legendre(n);
    let m = 2 * n;
    let mut nodes = Vec::with_capacity(n * m);
    let mut weights = Vec::with_capacity(n * m);
    for (&c, &wc) in mu.iter().zip(&wm) {
        let s = (1.0 - c * c).max(0.0).sqrt();
        for j in 0..m {
            let phi = 2.0 * PI * (j as f64 + 0.5) / m as f64;
            nodes.push([s * phi.cos(), s * phi.sin(), c]);
            weights.push(wc * 2.0 * PI / m as f64);
        }
    }
    (nodes, weights)
}

/// Exponents (a, b, c) of the monomials n_x^a n_y^b n_z^c of degree exactly `d`.
pub fn monomials(d: usize) -> Vec<[usize; 3]> {
    let mut out = Vec::new();
    for a in (0..=d).rev() {
        for b in (0..=d - a).rev() {
            out.push([a, b, d - a - b]);
        }
    }
    out
}

/// n^e for exponents `e`.
pub fn monomial(n: &[f64; 3], e: &[usize; 3]) -> f64 {
    n[0].powi(e[0] as i32) * n[1].powi(e[1] as i32) * n[2].powi(e[2] as i32)
}

/// ∇(n^e) in R³.
fn monomial_gradient(n: &[f64; 3], e: &[usize; 3]) -> [f64; 3] {
    std::array::from_fn(|d| {
        if e[d] == 0 {
            0.0
        } else {
            let mut f = *e;
            f[d] -= 1;
            e[d] as f64 * monomial(n, &f)
        }
    })
}

/// Orientation space to harmonic degree L: the product rule with L + 3 latitudes (exact for the
/// degree 2L + 4 that the Galerkin integrals reach) and the basis Y_i, i < (L+1)², orthonormal
/// (∫ Y_i Y_j dΩ = δ_ij), Y_0 = 1/√(4π), ordered by degree: the first (l+1)² span the harmonics of
/// degree ≤ l, so each Y_i is a harmonic of one degree [`Sphere::degree_of`].
#[derive(Debug, Clone)]
pub struct Sphere {
    degree: usize,
    /// Quadrature nodes (unit vectors) and weights (sum 4π).
    pub nodes: Vec<[f64; 3]>,
    /// The rule's weights, one per node.
    pub weights: Vec<f64>,
    /// Y_i(n_j) at [i · nodes + j].
    pub values: Vec<f64>,
    /// The surface gradient (1 − nn)∇Y_i at n_j, at [i · nodes + j].
    pub gradients: Vec<[f64; 3]>,
    degree_of: Vec<usize>,
    /// Each Y_i as monomials with coefficients.
    coefs: Vec<Vec<([usize; 3], f64)>>,
}

impl Sphere {
    /// The rule and basis to degree `degree` (≤ [`MAX_DEGREE`]).
    pub fn new(degree: usize) -> Self {
        let (nodes, weights) = product_rule(degree + 3);
        let nn = nodes.len();
        // Gram-Schmidt (twice) of the monomials of degree ≤ L, by degree, in the rule's inner
        // product: on the sphere they are dependent (n·n = 1), and a monomial left with no norm
        // is dropped, which leaves (L+1)² functions.
        let mut values: Vec<Vec<f64>> = Vec::new();
        let mut coefs: Vec<Vec<([usize; 3], f64)>> = Vec::new();
        let mut degree_of = Vec::new();
        let dot = |a: &[f64], b: &[f64]| -> f64 {
            a.iter()
                .zip(b)
                .zip(&weights)
                .map(|((x, y), w)| x * y * w)
                .sum()
        };
        for d in 0..=degree {
            for e in monomials(d) {
                let mut v: Vec<f64> = nodes.iter().map(|n| monomial(n, &e)).collect();
                let mut c = vec![(e, 1.0)];
                let norm0 = dot(&v, &v).sqrt();
                for _ in 0..2 {
                    for (u, cu) in values.iter().zip(&coefs) {
                        let p = dot(u, &v);
                        v.iter_mut().zip(u).for_each(|(x, y)| *x -= p * y);
                        c.extend(cu.iter().map(|&(f, a)| (f, -p * a)));
                    }
                }
                let norm = dot(&v, &v).sqrt();
                if norm > 1e-8 * norm0 {
                    v.iter_mut().for_each(|x| *x /= norm);
                    c.iter_mut().for_each(|x| x.1 /= norm);
                    values.push(v);
                    coefs.push(merge(c));
                    degree_of.push(d);
                }
            }
        }
        debug_assert_eq!(values.len(), (degree + 1) * (degree + 1));
        let gradients = coefs
            .iter()
            .flat_map(|c| {
                nodes.iter().map(move |n| {
                    let mut g = [0.0; 3];
                    for (e, a) in c {
                        let m = monomial_gradient(n, e);
                        (0..3).for_each(|d| g[d] += a * m[d]);
                    }
                    let along = g[0] * n[0] + g[1] * n[1] + g[2] * n[2];
                    std::array::from_fn(|d| g[d] - along * n[d])
                })
            })
            .collect();
        let _ = nn;
        Sphere {
            degree,
            nodes,
            weights,
            values: values.concat(),
            gradients,
            degree_of,
            coefs,
        }
    }

    /// The harmonic degree L.
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// Number of basis functions, (L+1)².
    pub fn len(&self) -> usize {
        self.degree_of.len()
    }

    /// Whether the basis is empty (never: Y_0 is always there).
    pub fn is_empty(&self) -> bool {
        self.degree_of.is_empty()
    }

    /// The harmonic degree l of basis function `i`.
    pub fn degree_of(&self, i: usize) -> usize {
        self.degree_of[i]
    }

    /// Every Y_i at an arbitrary unit vector `n`.
    pub fn basis_at(&self, n: &[f64; 3]) -> Vec<f64> {
        self.coefs
            .iter()
            .map(|c| c.iter().map(|(e, a)| a * monomial(n, e)).sum())
            .collect()
    }

    /// Number of quadrature nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Y_i(n_j).
    #[inline]
    pub fn value(&self, i: usize, j: usize) -> f64 {
        self.values[i * self.nodes.len() + j]
    }

    /// The Galerkin coefficients c_i = ∫ Y_i f dΩ of a function given at the nodes.
    pub fn project(&self, at_nodes: &[f64], out: &mut [f64]) {
        let nn = self.nodes.len();
        for (i, o) in out.iter_mut().enumerate() {
            let y = &self.values[i * nn..(i + 1) * nn];
            *o = y
                .iter()
                .zip(at_nodes)
                .zip(&self.weights)
                .map(|((y, f), w)| y * f * w)
                .sum();
        }
    }

    /// The coefficients of f(n) = Σ_i c_i Y_i(n) evaluated at every node, into `out`.
    pub fn evaluate(&self, c: &[f64], out: &mut [f64]) {
        let nn = self.nodes.len();
        out.fill(0.0);
        for (i, &ci) in c.iter().enumerate() {
            if ci != 0.0 {
                let y = &self.values[i * nn..(i + 1) * nn];
                out.iter_mut().zip(y).for_each(|(o, y)| *o += ci * y);
            }
        }
    }
}

/// Sum the coefficients of equal monomials.
fn merge(mut c: Vec<([usize; 3], f64)>) -> Vec<([usize; 3], f64)> {
    c.sort_by_key(|a| a.0);
    let mut out: Vec<([usize; 3], f64)> = Vec::new();
    for (e, a) in c {
        match out.last_mut() {
            Some(last) if last.0 == e => last.1 += a,
            _ => out.push((e, a)),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rule_integrates_polynomials_of_its_degree() {
        // ∫ n_z^{2k} dΩ = 4π/(2k + 1); ∫ n_x² n_y² dΩ = 4π/15.
        let (nodes, w) = product_rule(5);
        for k in 0..5 {
            let s: f64 = nodes
                .iter()
                .zip(&w)
                .map(|(n, w)| w * n[2].powi(2 * k))
                .sum();
            assert!(
                (s - 4.0 * PI / (2 * k + 1) as f64).abs() < 1e-13,
                "{k}: {s}"
            );
        }
        let s: f64 = nodes
            .iter()
            .zip(&w)
            .map(|(n, w)| w * n[0] * n[0] * n[1] * n[1])
            .sum();
        assert!((s - 4.0 * PI / 15.0).abs() < 1e-13);
    }

    #[test]
    fn the_basis_is_orthonormal_harmonics_of_one_degree_each() {
        let s = Sphere::new(4);
        assert_eq!(s.len(), 25);
        let nn = s.node_count();
        for i in 0..s.len() {
            for j in 0..s.len() {
                let g: f64 = (0..nn)
                    .map(|q| s.weights[q] * s.value(i, q) * s.value(j, q))
                    .sum();
                assert!((g - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12);
                // ∫ ∇Y_i·∇Y_j = l(l+1) δ_ij: each is a harmonic of degree l.
                let h: f64 = (0..nn)
                    .map(|q| {
                        let (a, b) = (s.gradients[i * nn + q], s.gradients[j * nn + q]);
                        s.weights[q] * (a[0] * b[0] + a[1] * b[1] + a[2] * b[2])
                    })
                    .sum();
                let l = s.degree_of(i) as f64;
                let want = if i == j { l * (l + 1.0) } else { 0.0 };
                assert!((h - want).abs() < 1e-10, "{i} {j}: {h} vs {want}");
            }
        }
    }
}
