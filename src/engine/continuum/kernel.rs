//! The mean-field kernel: the averaged model's pair terms as polynomials in the two orientations,
//! and their Fourier transforms over the box's wave vectors.
//!
//! A partner ρ at separation D = x_σ − x_ρ adds to swimmer σ's rates (before the phase weight
//! sin(φσ − φρ) and the cutoff's switch S(D))
//!
//! v  = a_r v0 (9/64) (Λ/ℓ) ξ³ I(s,r,q) n + c_J v0 (9/64) ξ⁴ [n(2s + 4qr − 10sr²) + D̂ JK],
//! T  = a_n w0 (9/32) (Λ/ℓ) ξ⁴ JK D̂ + w0 (15/64) (Λ/ℓ) ξ⁵ L(s,r,q) D̂,    dn/dt = −(1 − nn)T,
//!
//! ξ = ℓ/D, s = D̂·n, r = D̂·n', q = n·n' (the brackets as `averaged` writes them). Every term is
//! a polynomial in n (odd or even, of degree ≤ 3) and an even polynomial in n' (degree ≤ 2), with
//! one power of D per term: the ξ³ terms move along n (odd in n), the ξ⁴ ones are even in n, the
//! ξ⁵ one odd. On unit vectors each folds into one homogeneous form (degree 3 if odd, 2 if even,
//! by n·n = 1) with coefficients C(D̂) polynomial in D̂ of degree ≤ 6:
//!
//! v_o(D, n, n') = D⁻ᵐ Σ_αβ C_oαβ(D̂) n^α n'^β,   n^α of degree 3 or 2, n'^β of degree 2.
//!
//! So a distribution acts on its partners through its second moments M_β(x) = ∫ n'^β f dn' alone
//! (density being their trace): the mean field of f is U_oα = K_oαβ ⊛ M_β with
//! K_oαβ(D) = H(D) D⁻ᵐ C_oαβ(D̂), H the core (no pair closer than D₀) times the switch.
//!
//! Its transform at a box wave vector, K̂(k) = ∫ K(D) e^{−ik·D} dD, follows from the plane-wave
//! expansion e^{−ik·D} = Σ_l (2l+1)(−i)^l j_l(kD) P_l(k̂·D̂): C has degree ≤ 6, so l ≤ 6 and an
//! angular product rule exact to degree 13 (7 × 14 directions) gives the angular integrals exactly;
//! the radial ∫ D^{2−m} H(D) j_l(kD) dD is Gauss-Legendre on panels. Terms even in D̂ (m = 3, 5)
//! have real transforms, odd ones (m = 4) imaginary: each component is stored as one real number
//! per wave vector.

use super::sphere::{gauss_legendre, monomial, monomials, product_rule};
use crate::engine::averaged::CutoffSwitch;
use std::collections::BTreeMap;
use std::sync::Mutex;

/// The averaged model's constants of one swimmer kind (`averaged::pair_constants`): A_R, c_J,
/// A_N, v0, w0, Λ/ℓ, ℓ.
#[derive(Debug, Clone, Copy)]
pub struct Constants {
    /// Weight of the I term, A_R.
    pub a_r: f64,
    /// Weight of the J term, c_J.
    pub c_j: f64,
    /// Weight of the K term, A_N.
    pub a_n: f64,
    /// Λω(λ/ℓ)² (m/s).
    pub v0: f64,
    /// ω(λ/ℓ)² (1/s).
    pub w0: f64,
    /// Λ/ℓ.
    pub big_l: f64,
    /// ℓ (m).
    pub ell: f64,
}

/// A polynomial in (n, n'): exponents of n_x, n_y, n_z, n'_x, n'_y, n'_z → coefficient.
#[derive(Debug, Clone, Default)]
struct Poly(BTreeMap<[u8; 6], f64>);

impl Poly {
    fn constant(c: f64) -> Self {
        Poly(BTreeMap::from([([0; 6], c)]))
    }
    fn var(i: usize) -> Self {
        let mut e = [0u8; 6];
        e[i] = 1;
        Poly(BTreeMap::from([(e, 1.0)]))
    }
    fn add(&self, o: &Poly) -> Poly {
        let mut m = self.0.clone();
        for (k, v) in &o.0 {
            *m.entry(*k).or_insert(0.0) += v;
        }
        Poly(m)
    }
    fn scale(&self, c: f64) -> Poly {
        Poly(self.0.iter().map(|(k, v)| (*k, v * c)).collect())
    }
    fn mul(&self, o: &Poly) -> Poly {
        let mut m = BTreeMap::new();
        for (ka, va) in &self.0 {
            for (kb, vb) in &o.0 {
                let k: [u8; 6] = std::array::from_fn(|i| ka[i] + kb[i]);
                *m.entry(k).or_insert(0.0) += va * vb;
            }
        }
        Poly(m)
    }
    /// Σ_i c_i p_i.
    fn sum(terms: &[(f64, &Poly)]) -> Poly {
        terms
            .iter()
            .fold(Poly::default(), |acc, (c, p)| acc.add(&p.scale(*c)))
    }
}

/// The pair terms at direction `dh` as polynomials, per radial power m: (m, output o, poly),
/// outputs 0-2 the velocity, 3-5 the torque-like T, each without the factor D⁻ᵐ.
fn pair_polys(c: &Constants, dh: [f64; 3]) -> Vec<(i32, usize, Poly)> {
    let n: [Poly; 3] = std::array::from_fn(Poly::var);
    let s = Poly::sum(&[(dh[0], &n[0]), (dh[1], &n[1]), (dh[2], &n[2])]);
    let np: [Poly; 3] = std::array::from_fn(|i| Poly::var(3 + i));
    let r = Poly::sum(&[(dh[0], &np[0]), (dh[1], &np[1]), (dh[2], &np[2])]);
    let q = n[0]
        .mul(&np[0])
        .add(&n[1].mul(&np[1]))
        .add(&n[2].mul(&np[2]));
    let one = Poly::constant(1.0);
    let (ss, rr, qq) = (s.mul(&s), r.mul(&r), q.mul(&q));
    let qsr = q.mul(&s).mul(&r);
    let ssrr = ss.mul(&rr);
    let jk = Poly::sum(&[
        (1.0, &one),
        (2.0, &qq),
        (-5.0, &ss),
        (-5.0, &rr),
        (-20.0, &qsr),
        (35.0, &ssrr),
    ]);
    let i_br = Poly::sum(&[
        (1.0, &one),
        (-3.0, &rr),
        (-3.0, &ss),
        (-6.0, &qsr),
        (15.0, &ssrr),
    ]);
    let j_n = Poly::sum(&[(2.0, &s), (4.0, &q.mul(&r)), (-10.0, &s.mul(&rr))]);
    let sss = ss.mul(&s);
    let l_br = Poly::sum(&[
        (3.0, &s),
        (6.0, &r.mul(&q)),
        (6.0, &s.mul(&qq)),
        (-7.0, &sss),
        (-21.0, &s.mul(&rr)),
        (-42.0, &q.mul(&ss).mul(&r)),
        (63.0, &sss.mul(&rr)),
    ]);
    let ell = c.ell;
    let a3 = c.a_r * c.v0 * 9.0 / 64.0 * c.big_l * ell.powi(3);
    let a4 = c.c_j * c.v0 * 9.0 / 64.0 * ell.powi(4);
    let b4 = c.a_n * c.w0 * 9.0 / 32.0 * c.big_l * ell.powi(4);
    let b5 = c.w0 * 15.0 / 64.0 * c.big_l * ell.powi(5);
    let mut out = Vec::new();
    for a in 0..3 {
        out.push((3, a, n[a].mul(&i_br).scale(a3)));
        out.push((4, a, n[a].mul(&j_n).add(&jk.scale(dh[a])).scale(a4)));
        out.push((4, 3 + a, jk.scale(dh[a] * b4)));
        out.push((5, 3 + a, l_br.scale(dh[a] * b5)));
    }
    out
}

/// (n·n)^j expanded, as exponents of n_x, n_y, n_z with coefficients.
fn norm_power(j: usize) -> Vec<([usize; 3], f64)> {
    let mut terms = vec![([0usize; 3], 1.0)];
    for _ in 0..j {
        let mut next: BTreeMap<[usize; 3], f64> = BTreeMap::new();
        for (e, c) in &terms {
            for d in 0..3 {
                let mut f = *e;
                f[d] += 2;
                *next.entry(f).or_insert(0.0) += c;
            }
        }
        terms = next.into_iter().collect();
    }
    terms
}

/// The homogeneous degree the target side of radial power `m` folds into: 3 for the odd (m = 3,
/// 5), 2 for the even (m = 4).
pub fn target_degree(m: i32) -> usize {
    if m == 4 {
        2
    } else {
        3
    }
}

/// One kernel component K_oαβ: output o, radial power m, target monomial α (of degree
/// [`target_degree`]`(m)`), source monomial β (index into `monomials(2)`).
#[derive(Debug, Clone)]
pub struct Component {
    /// 0-2: the velocity, 3-5: T.
    pub output: usize,
    /// The power of 1/D.
    pub m: i32,
    /// Exponents of the target monomial n^α.
    pub alpha: [usize; 3],
    /// Index of the source monomial n'^β in `monomials(2)`.
    pub beta: usize,
    /// C_oαβ at each direction of [`directions`].
    at_dirs: Vec<f64>,
}

/// The angular rule for D̂: exact to degree 13.
pub fn directions() -> (Vec<[f64; 3]>, Vec<f64>) {
    product_rule(7)
}

/// The folded components of the pair terms of swimmers with constants `c`, those not zero.
/// They depend on `c` alone and take ~10 ms to fold, so the last few are kept (a script or a
/// sweep builds many continua of the same swimmers).
pub fn components(c: &Constants) -> Vec<Component> {
    const KEPT: usize = 8;
    type Memo = Vec<([u64; 7], Vec<Component>)>;
    static MEMO: Mutex<Memo> = Mutex::new(Vec::new());
    // A poisoned memo only ever holds finished entries.
    let memo = || MEMO.lock().unwrap_or_else(|e| e.into_inner());
    let key = [c.a_r, c.c_j, c.a_n, c.v0, c.w0, c.big_l, c.ell].map(f64::to_bits);
    if let Some((_, v)) = memo().iter().find(|(k, _)| *k == key) {
        return v.clone();
    }
    let v = fold_components(c);
    let mut m = memo();
    if m.len() == KEPT {
        m.remove(0);
    }
    m.push((key, v.clone()));
    v
}

fn fold_components(c: &Constants) -> Vec<Component> {
    let (dirs, _) = directions();
    let src = monomials(2);
    let mut map: BTreeMap<(usize, i32, [usize; 3], usize), Vec<f64>> = BTreeMap::new();
    for (j, dh) in dirs.iter().enumerate() {
        for (m, o, p) in pair_polys(c, *dh) {
            let td = target_degree(m);
            for (e, v) in &p.0 {
                let ea = [e[0] as usize, e[1] as usize, e[2] as usize];
                let eb = [e[3] as usize, e[4] as usize, e[5] as usize];
                let (da, db) = (ea.iter().sum::<usize>(), eb.iter().sum::<usize>());
                debug_assert!(
                    da <= td && (td - da).is_multiple_of(2) && db <= 2 && db.is_multiple_of(2)
                );
                for (fa, ca) in norm_power((td - da) / 2) {
                    for (fb, cb) in norm_power((2 - db) / 2) {
                        let alpha = std::array::from_fn(|d| ea[d] + fa[d]);
                        let b: [usize; 3] = std::array::from_fn(|d| eb[d] + fb[d]);
                        let beta = src.iter().position(|x| *x == b).expect("degree 2");
                        map.entry((o, m, alpha, beta))
                            .or_insert_with(|| vec![0.0; dirs.len()])[j] += v * ca * cb;
                    }
                }
            }
        }
    }
    let largest = map
        .values()
        .flat_map(|v| v.iter())
        .fold(0.0f64, |a, x| a.max(x.abs()));
    map.into_iter()
        .filter(|(_, v)| v.iter().any(|x| x.abs() > 1e-13 * largest))
        .map(|((output, m, alpha, beta), at_dirs)| Component {
            output,
            m,
            alpha,
            beta,
            at_dirs,
        })
        .collect()
}

impl Component {
    /// C_oαβ at direction `j` of [`directions`].
    pub fn at_dir(&self, j: usize) -> f64 {
        self.at_dirs[j]
    }
}

/// Core, cutoff and radial quadrature of the kernel's transform.
#[derive(Debug, Clone)]
pub struct Radial {
    /// Nodes D_i (m) and, per m = 3, 4, 5, the weights w_i D_i^{2−m} S(D_i).
    nodes: Vec<f64>,
    weights: [Vec<f64>; 3],
}

impl Radial {
    /// Pairs from `core` to `cutoff` (m) with the cutoff's switch, resolved for wave numbers up
    /// to `k_max` (1/m): Gauss-Legendre panels no wider than a quarter of their distance (the
    /// integrand's D^{2−m} changes on the scale D) nor than 1/k_max (j_l(kD) oscillates on that
    /// scale), split at the switch. Their number grows with log(cutoff/core) near the core and
    /// with k_max·cutoff beyond, so the cost does not follow the core down.
    pub fn new(core: f64, cutoff: f64, k_max: f64) -> Self {
        let switch = CutoffSwitch::new(Some(cutoff));
        let (x, w) = gauss_legendre(8);
        let step = 1.0 / k_max.max(1e-300);
        let mut edges = vec![core];
        for (a, b) in [
            (core, switch.inner().max(core)),
            (switch.inner().max(core), cutoff),
        ] {
            if b > a {
                edges.extend(panel_edges(a, b, step));
            }
        }
        let mut nodes = Vec::new();
        let mut weights: [Vec<f64>; 3] = Default::default();
        for e in edges.windows(2) {
            let (a, b) = (e[0], e[1]);
            for (xi, wi) in x.iter().zip(&w) {
                let d = 0.5 * (a + b) + 0.5 * (b - a) * xi;
                let base = 0.5 * (b - a) * wi * switch.at(d);
                nodes.push(d);
                for (k, m) in [3, 4, 5].iter().enumerate() {
                    weights[k].push(base * d.powi(2 - m));
                }
            }
        }
        Radial { nodes, weights }
    }

    /// The number of quadrature nodes (8 per panel).
    pub fn nodes(&self) -> usize {
        self.nodes.len()
    }

    /// R_lm(k) = ∫ D^{2−m} H(D) j_l(kD) dD for l = 0..=6, m = 3, 4, 5 (index m − 3).
    pub fn integrals(&self, k: f64) -> [[f64; 7]; 3] {
        let mut r = [[0.0; 7]; 3];
        for (i, &d) in self.nodes.iter().enumerate() {
            let j = spherical_bessel(k * d);
            for (m, row) in r.iter_mut().enumerate() {
                let w = self.weights[m][i];
                for l in 0..7 {
                    row[l] += w * j[l];
                }
            }
        }
        r
    }
}

/// The panel ends after `a` up to `b` (m), `b` last: panels growing by a quarter of their
/// start while that is below `step`, then equal ones no wider than `step`.
fn panel_edges(a: f64, b: f64, step: f64) -> Vec<f64> {
    let mut out = Vec::new();
    let mut e = a;
    while e > 0.0 && 0.25 * e < step && 1.25 * e < b {
        e *= 1.25;
        out.push(e);
    }
    let panels = ((b - e) / step).ceil().max(1.0) as usize;
    out.extend((1..=panels).map(|p| e + (b - e) * p as f64 / panels as f64));
    *out.last_mut().expect("one panel at least") = b;
    out
}

/// j_0..j_6 at x ≥ 0: the power series below x = 8 (all terms kept until they no longer change
/// the sum), upward recurrence from sin and cos above (stable there for l ≤ 6).
pub fn spherical_bessel(x: f64) -> [f64; 7] {
    let mut j = [0.0; 7];
    if x < 8.0 {
        let y = -0.5 * x * x;
        let mut lead = 1.0; // x^l/(2l+1)!!
        for (l, jl) in j.iter_mut().enumerate() {
            if l > 0 {
                lead *= x / (2 * l + 1) as f64;
            }
            let (mut term, mut sum) = (1.0, 1.0);
            for k in 1..60 {
                term *= y / (k as f64 * (2 * (l + k) + 1) as f64);
                sum += term;
                if term.abs() < 1e-17 * sum.abs() {
                    break;
                }
            }
            *jl = lead * sum;
        }
    } else {
        let (s, c) = x.sin_cos();
        j[0] = s / x;
        j[1] = s / (x * x) - c / x;
        for l in 1..6 {
            j[l + 1] = (2 * l + 1) as f64 / x * j[l] - j[l - 1];
        }
    }
    j
}

/// P_0..P_6 at `mu`.
fn legendre(mu: f64) -> [f64; 7] {
    let mut p = [0.0; 7];
    p[0] = 1.0;
    p[1] = mu;
    for l in 1..6 {
        p[l + 1] = ((2 * l + 1) as f64 * mu * p[l] - l as f64 * p[l - 1]) / (l + 1) as f64;
    }
    p
}

/// The transform of every component at wave vector `k` (1/m) into `out` (one per component):
/// K̂ = out for m = 3, 5 and K̂ = i·out for m = 4. `scratch` holds one value per direction and m.
pub fn transform_at(
    comps: &[Component],
    radial: &Radial,
    dirs: &[[f64; 3]],
    weights: &[f64],
    k: [f64; 3],
    out: &mut [f64],
    scratch: &mut Vec<f64>,
) {
    let kn = (k[0] * k[0] + k[1] * k[1] + k[2] * k[2]).sqrt();
    let r = radial.integrals(kn);
    let nd = dirs.len();
    scratch.resize(3 * nd, 0.0);
    for (j, (d, w)) in dirs.iter().zip(weights).enumerate() {
        let mu = if kn > 0.0 {
            (k[0] * d[0] + k[1] * d[1] + k[2] * d[2]) / kn
        } else {
            0.0
        };
        let p = legendre(mu);
        // (2l+1)(−i)^l: real for even l (signs + − + −), −i, +i, −i for l = 1, 3, 5 (their
        // imaginary parts kept).
        let even = |row: &[f64; 7]| {
            row[0] * p[0] - 5.0 * row[2] * p[2] + 9.0 * row[4] * p[4] - 13.0 * row[6] * p[6]
        };
        let odd =
            |row: &[f64; 7]| -3.0 * row[1] * p[1] + 7.0 * row[3] * p[3] - 11.0 * row[5] * p[5];
        scratch[j] = w * even(&r[0]);
        scratch[nd + j] = w * odd(&r[1]);
        scratch[2 * nd + j] = w * even(&r[2]);
    }
    for (o, c) in out.iter_mut().zip(comps) {
        let g = &scratch[(c.m as usize - 3) * nd..(c.m as usize - 2) * nd];
        *o = c.at_dirs.iter().zip(g).map(|(a, b)| a * b).sum();
    }
}

/// The n-monomial of a component at orientation `n`.
pub fn target_value(c: &Component, n: &[f64; 3]) -> f64 {
    monomial(n, &c.alpha)
}
