//! The continuum theory of the averaged model (src/engine/continuum): its kernel is the pair
//! terms, its transform the direct integral, its solver conserves each population and keeps the
//! homogeneous states, its small perturbations follow the linearised operator whose eigenvalues
//! are the growth rates, and its mean-field rates are what particles sampled from the same
//! distribution feel on average, converging as their number grows.

use nalgebra::{DMatrix, DVector, Vector3};
use rustfft::num_complex::Complex64;
use std::f64::consts::PI;
use swimlab::engine::averaged::{AveragedSystem, Shortcuts};
use swimlab::engine::continuum::kernel::{self, Constants, Radial};
use swimlab::engine::continuum::sphere::{monomial, monomials, product_rule};
use swimlab::engine::continuum::{BaseState, Closure, Continuum, ContinuumSpec};
use swimlab::engine::fields::FieldKind;
use swimlab::engine::integrators::OdeSystem;
use swimlab::engine::{Coefficients, Dumbbell, Model, Scene};

/// The paper's asymmetric dumbbell of Figs 1-2: Λ = 0.15ℓ, a1 = 2a2.
fn asymmetric() -> Dumbbell {
    let d = Dumbbell::default();
    let lam = 0.15 * d.ell;
    Dumbbell {
        a1: 1.5 * lam,
        a2: 0.75 * lam,
        ..d
    }
}

fn constants(d: &Dumbbell) -> Constants {
    // The averaged model's constants as `averaged` computes them (paper coefficients).
    let (a1, a2) = (d.a1, d.a2);
    let eps2 = (d.lambda / d.ell).powi(2);
    let big_lambda = 2.0 * a1 * a2 / (a1 + a2);
    Constants {
        a_r: (a2 * a2 - a1 * a1) / (a1 * a1 + a2 * a2),
        c_j: 1.0,
        a_n: (a2 - a1) / (a1 + a2),
        v0: big_lambda * d.omega * eps2,
        w0: d.omega * eps2,
        big_l: big_lambda / d.ell,
        ell: d.ell,
    }
}

/// The engine's own rates of swimmer 0 (phase π/2) at separation `d` from swimmer 1 (phase 0):
/// sin(φ0 − φ1) = 1. (dR_H/dt, dN/dt) in one array.
struct PairProbe {
    sys: AveragedSystem,
    y: Vec<f64>,
    dy: Vec<f64>,
}

impl PairProbe {
    fn new(d: &Dumbbell, cutoff: Option<f64>) -> Self {
        let mut a = *d;
        a.phase = PI / 2.0;
        let mut b = *d;
        b.phase = 0.0;
        let base = vec![Vector3::zeros(); 2];
        let y = vec![
            10.0 * d.ell,
            0.0,
            0.0,
            1.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            1.0,
            0.0,
            0.0,
        ];
        let mut sys = AveragedSystem::with_shortcuts(
            &[a, b],
            &base,
            Coefficients::Paper,
            &y,
            Shortcuts::none(),
        );
        sys.set_cutoff(cutoff);
        PairProbe {
            sys,
            y,
            dy: vec![0.0; 12],
        }
    }

    fn rates(&mut self, d: [f64; 3], n: [f64; 3], np: [f64; 3]) -> [f64; 6] {
        self.y[..3].copy_from_slice(&d);
        self.y[3..6].copy_from_slice(&n);
        self.y[6..9].fill(0.0);
        self.y[9..12].copy_from_slice(&np);
        self.sys.rhs(0.0, &self.y, &mut self.dy);
        std::array::from_fn(|i| self.dy[i])
    }
}

fn unit(v: [f64; 3]) -> [f64; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    v.map(|x| x / n)
}

/// The engine's seeded generator, with the tests' draws.
struct Rng(swimlab::engine::build::Rng);
impl Rng {
    fn new(seed: u64) -> Self {
        Rng(swimlab::engine::build::Rng::new(seed))
    }
    fn uniform(&mut self) -> f64 {
        self.0.uniform()
    }
    fn direction(&mut self) -> [f64; 3] {
        let v = self.0.unit_vector();
        [v.x, v.y, v.z]
    }
}

/// The folded kernel at a direction of its rule, times D⁻ᵐ, with the turn projected: what the
/// continuum takes a partner at D with orientation n' to do to a swimmer with orientation n.
fn folded(comps: &[kernel::Component], j: usize, dist: f64, n: [f64; 3], np: [f64; 3]) -> [f64; 6] {
    let src = monomials(2);
    let mut r = [0.0; 6];
    for c in comps {
        r[c.output] +=
            c.at_dir(j) * dist.powi(-c.m) * monomial(&n, &c.alpha) * monomial(&np, &src[c.beta]);
    }
    let t = [r[3], r[4], r[5]];
    let along = t[0] * n[0] + t[1] * n[1] + t[2] * n[2];
    for d in 0..3 {
        r[3 + d] = -(t[d] - along * n[d]);
    }
    r
}

/// The folding of the I, J, K, L terms into polynomials in n and n' (degree 3 or 2 in n, 2 in
/// n', by n·n = 1) reproduces the engine's pair rates for random orientations at every direction
/// of the rule and several distances. Tolerance: the folding reorders sums of ~100 terms up to
/// ~60 times the result (the L bracket's 63 s³r²), 1e-11 relative to the largest rate of the pair.
#[test]
fn the_folded_kernel_is_the_pair_terms() {
    for d in [asymmetric(), Dumbbell::default()] {
        let comps = kernel::components(&constants(&d));
        let mut probe = PairProbe::new(&d, None);
        let (dirs, _) = kernel::directions();
        let mut rng = Rng::new(7);
        for (j, dh) in dirs.iter().enumerate() {
            for dist in [1.5 * d.ell, 4.0 * d.ell] {
                let (n, np) = (rng.direction(), rng.direction());
                let want = probe.rates(dh.map(|x| x * dist), n, np);
                let got = folded(&comps, j, dist, n, np);
                let scale = want.iter().fold(0.0f64, |a, x| a.max(x.abs()));
                for i in 0..6 {
                    assert!(
                        (got[i] - want[i]).abs() <= 1e-11 * scale,
                        "direction {j}, D = {dist:e}, output {i}: {} vs {}",
                        got[i],
                        want[i]
                    );
                }
            }
        }
    }
}

/// The kernel's transform at box wave vectors, from the partial-wave sum, against the direct
/// integral ∫ S(D) v(D, n, n') e^{−ik·D} dD over the shell core < D < cutoff of the engine's own
/// pair rates (composite Gauss-Legendre in D, 40 panels a length, and a product rule exact to
/// degree 39 in D̂, far beyond the integrand's content at kD ≤ 6). Tolerance 1e-8 of the largest
/// component: the direct sum's own quadrature error is below that (halving its panels changes
/// it by less than 1e-10 of it).
#[test]
fn the_kernel_transform_is_the_direct_integral() {
    let d = asymmetric();
    let ell = d.ell;
    let (core, cutoff, side) = (ell, 6.0 * ell, 12.0 * ell);
    let comps = kernel::components(&constants(&d));
    let (dirs, dir_w) = kernel::directions();
    let mut probe = PairProbe::new(&d, Some(cutoff));
    let (sdirs, sw) = product_rule(20);
    let (gx, gw) = swimlab::engine::continuum::sphere::gauss_legendre(10);
    let panels = 200;
    let src = monomials(2);
    let n = unit([0.3, -0.5, 0.8]);
    let np = unit([-0.7, 0.2, 0.4]);
    for mode in [[1.0, 0.0, 0.0], [1.0, 2.0, 0.0], [0.0, -1.0, 2.0]] {
        let k: [f64; 3] = mode.map(|m| 2.0 * PI * m / side);
        let kn = (k[0] * k[0] + k[1] * k[1] + k[2] * k[2]).sqrt();
        let radial = Radial::new(core, cutoff, kn);
        let mut vals = vec![0.0; comps.len()];
        let mut scratch = Vec::new();
        kernel::transform_at(&comps, &radial, &dirs, &dir_w, k, &mut vals, &mut scratch);
        let mut want = [Complex64::default(); 6];
        for c in 0..comps.len() {
            let v = vals[c] * monomial(&n, &comps[c].alpha) * monomial(&np, &src[comps[c].beta]);
            let kv = if comps[c].m == 4 {
                Complex64::new(0.0, v)
            } else {
                Complex64::new(v, 0.0)
            };
            want[comps[c].output] += kv;
        }
        // The continuum projects the turn at the target node: compare the unprojected T by
        // projecting the direct integral the same way (the projection is linear).
        let t = [want[3], want[4], want[5]];
        let along = t[0] * n[0] + t[1] * n[1] + t[2] * n[2];
        for q in 0..3 {
            want[3 + q] = -(t[q] - along * n[q]);
        }
        let mut got = [Complex64::default(); 6];
        let h = (cutoff - core) / panels as f64;
        for p in 0..panels {
            for (x, w) in gx.iter().zip(&gw) {
                let dist = core + h * (p as f64 + 0.5 + 0.5 * x);
                let wr = 0.5 * h * w * dist * dist;
                for (dh, wa) in sdirs.iter().zip(&sw) {
                    let dv = dh.map(|c| c * dist);
                    let r = probe.rates(dv, n, np);
                    let phase = -(k[0] * dv[0] + k[1] * dv[1] + k[2] * dv[2]);
                    let e = Complex64::from_polar(wr * wa, phase);
                    for q in 0..6 {
                        got[q] += e * r[q];
                    }
                }
            }
        }
        let scale = want.iter().fold(0.0f64, |a, x| a.max(x.norm()));
        for q in 0..6 {
            assert!(
                (got[q] - want[q]).norm() <= 1e-8 * scale,
                "mode {mode:?}, output {q}: direct {} vs transform {}",
                got[q],
                want[q]
            );
        }
    }
}

/// A box of `count` asymmetric averaged swimmers, half at phase 0 and half at π/2, at random.
fn two_populations(count: usize, side: f64, seed: u64) -> Scene {
    let mut s = Scene::new();
    s.set_model(Model::Averaged);
    s.set_box(Some([side; 3])).unwrap();
    let mut rng = Rng::new(seed);
    let d = asymmetric();
    let mut i = 0;
    while i < count {
        let c = Vector3::new(
            rng.uniform() - 0.5,
            rng.uniform() - 0.5,
            rng.uniform() - 0.5,
        ) * side;
        let n = rng.direction();
        let mut a = d;
        a.phase = if i % 2 == 0 { 0.0 } else { PI / 2.0 };
        // Places where the spheres would touch another swimmer's are drawn again.
        if s.add(a, c, Vector3::from(n)).is_ok() {
            i += 1;
        }
    }
    s
}

/// Each population's number is conserved to round-off over a long run of a structured state (the
/// k = 0 mode of the density coefficient has zero rate, and the turns never touch Y_0): 1e-12
/// relative over 2,000 periods. The homogeneous isotropic and polar states do not move: neither
/// makes a mean field (the pair terms averaged over an isotropic second moment vanish), so their
/// rates are round-off, 1e-12 of the state.
#[test]
fn populations_are_conserved_and_homogeneous_states_stay() {
    let side = 20.0 * asymmetric().ell;
    let s = two_populations(300, side, 3);
    let spec = ContinuumSpec {
        grid: [8, 8, 8],
        width: Some(2.0 * asymmetric().ell),
        ..Default::default()
    };
    let mut c = Continuum::of(&s, &spec).unwrap();
    let before = c.counts();
    assert!(
        (before[0] - 150.0).abs() < 1e-9 && (before[1] - 150.0).abs() < 1e-9,
        "{before:?}"
    );
    c.run_periods(2000.0).unwrap();
    let after = c.counts();
    for (a, b) in before.iter().zip(&after) {
        assert!((a - b).abs() <= 1e-12 * a, "{before:?} -> {after:?}");
    }
    assert!(c.stats().steps > 0);
    for base in [BaseState::Isotropic, BaseState::Polar([0.0, 0.1, 0.3])] {
        c.perturb(
            &base,
            FieldKind::Density,
            [1.0, 0.0, 0.0],
            [1, 0, 0],
            0.0,
            None,
        )
        .unwrap();
        let start = c.state().to_vec();
        c.run_periods(1e4).unwrap();
        let scale = start.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let moved = c
            .state()
            .iter()
            .zip(&start)
            .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
        assert!(
            moved <= 1e-12 * scale,
            "{base:?} moved by {moved:e} of {scale:e}"
        );
    }
}

/// Small perturbations follow the linearised operator: a nematic wave of relative amplitude 1e-6
/// in one population about the polar state (a nematic one, since the mean field reads second
/// moments only: a polarization wave alone makes none), run by the nonlinear solver, has at box mode k the amplitudes
/// exp(A t) δc(0) that the operator A of `growth_rates` predicts (A's exponential by scaling and
/// squaring). Tolerance 1e-4 of the amplitude: the nonlinear terms are 1e-6 of the
/// linear ones and the solver's tolerance 1e-9 of the structure; 1e-4 leaves room for the
/// growth of both over σt ≈ 2.
#[test]
fn small_perturbations_follow_the_linearised_operator() {
    let d = asymmetric();
    let side = 20.0 * d.ell;
    let s = two_populations(300, side, 5);
    let spec = ContinuumSpec {
        grid: [8, 8, 8],
        tol: 1e-9,
        ..Default::default()
    };
    let mut c = Continuum::of(&s, &spec).unwrap();
    let base = BaseState::Polar([0.0, 0.0, 0.3]);
    let mode = [0i64, 0, 1];
    let k = [0.0, 0.0, 2.0 * PI / side];
    c.perturb(
        &base,
        FieldKind::Nematic,
        [1.0, 0.0, 1.0],
        mode,
        1e-6,
        Some(1),
    )
    .unwrap();
    let a0 = c.amplitudes(mode);
    let a = c.linear_operator(&base, k).unwrap();
    let rates = c.growth_rates(&base, k).unwrap();
    let sigma = rates[0].rate;
    assert!(
        sigma > 0.0,
        "the polar state is unstable at this k: {:?}",
        &rates[..3]
    );
    let t = 2.0 / sigma;
    c.run(t).unwrap();
    let got = c.amplitudes(mode);
    let want = expm_times(&a, t, &DVector::from_vec(a0.clone()));
    let scale = want.iter().fold(0.0f64, |m, x| m.max(x.norm()));
    let start = a0.iter().fold(0.0f64, |m, x| m.max(x.norm()));
    assert!(scale > 2.0 * start, "the mode grew: {start:e} -> {scale:e}");
    let worst = got
        .iter()
        .zip(want.iter())
        .fold(0.0f64, |m, (g, w)| m.max((g - w).norm()));
    eprintln!(
        "growth {:.3}x, solver against exp(At): {:.2e} of the amplitude",
        scale / start,
        worst / scale
    );
    assert!(
        worst <= 1e-4 * scale,
        "solver vs exp(At): {worst:e} of {scale:e}"
    );
}

/// exp(A t) v by scaling and squaring of a Taylor series (A small after scaling).
fn expm_times(a: &DMatrix<Complex64>, t: f64, v: &DVector<Complex64>) -> DVector<Complex64> {
    let norm = a.iter().map(|x| x.norm()).sum::<f64>() * t;
    let squarings = (norm.max(1.0).log2().ceil() as u32) + 4;
    let h = t / 2f64.powi(squarings as i32);
    let m = a * Complex64::new(h, 0.0);
    let dim = a.nrows();
    let mut e = DMatrix::<Complex64>::identity(dim, dim);
    let mut term = DMatrix::<Complex64>::identity(dim, dim);
    for j in 1..30 {
        term = &term * &m / Complex64::new(j as f64, 0.0);
        e += &term;
    }
    for _ in 0..squarings {
        e = &e * &e;
    }
    e * v
}

/// Population 0 (phase 0) of a continuum holding a density wave with nematic order, f = ρ(1 +
/// ½cos kx)(1 + 0.9 P2(n·e))/4π, population 1 (phase π/2) empty: the continuum, its probe
/// positions (cell centres) and orientations, and f.
#[allow(clippy::type_complexity)]
fn nematic_wave() -> (
    Continuum,
    Vec<[f64; 3]>,
    Box<dyn Fn([f64; 3], [f64; 3]) -> f64>,
) {
    let d = asymmetric();
    let ell = d.ell;
    let side = 12.0 * ell;
    let s = two_populations(2, side, 9);
    let spec = ContinuumSpec {
        grid: [8, 8, 8],
        degree: 2,
        ..Default::default()
    };
    let mut c = Continuum::of(&s, &spec).unwrap();
    let rho = 1.0 / ell.powi(3);
    let e = unit([0.3, 0.2, 1.0]);
    let kx = 2.0 * PI / side;
    let f = move |x: [f64; 3], n: [f64; 3]| {
        let c = e[0] * n[0] + e[1] * n[1] + e[2] * n[2];
        rho / (4.0 * PI) * (1.0 + 0.5 * (kx * x[0]).cos()) * (1.0 + 0.9 * 0.5 * (3.0 * c * c - 1.0))
    };
    c.set_distribution(0, f).unwrap();
    c.set_distribution(1, |_, _| 0.0).unwrap();
    let orientations = vec![unit([1.0, 0.0, 0.0]), unit([0.2, 0.9, -0.3]), e];
    (c, orientations, Box::new(f))
}

/// The mean field at probe cells and orientations, [orientation][probe] → (v, ṅ) as six values.
fn mean_fields(c: &Continuum, orientations: &[[f64; 3]], probes: &[usize]) -> Vec<Vec<[f64; 6]>> {
    orientations
        .iter()
        .map(|n| {
            let mf = c.mean_field(1, *n).unwrap();
            probes
                .iter()
                .map(|&cell| {
                    let (v, w) = mf[cell];
                    [v[0], v[1], v[2], w[0], w[1], w[2]]
                })
                .collect()
        })
        .collect()
}

/// The mean-field rates are the pair rates integrated over the distribution: at probe cells and
/// orientations, the continuum's rates (moments, FFT convolution with the kernel's transform)
/// equal the direct integral ∫∫ f(x − D, n') v(D, n, n') dD dn' of the engine's own pair rates
/// over core < |D| < cutoff (composite Gauss-Legendre in |D| on panels of 0.2ℓ, split at the
/// switch; a product rule exact to degree 23 in D̂, for kD ≤ π; one exact to degree 5 in n', the
/// integrand's degree being 4). Tolerance 1e-10 of the largest rate: the direct quadrature's own
/// error is below that (both sides are exact but for rounding; they agree to ~1e-13).
#[test]
fn mean_field_rates_are_the_pair_rates_integrated_over_the_distribution() {
    let d = asymmetric();
    let (c, orientations, f) = nematic_wave();
    let (core, cutoff) = (c.core(), c.cutoff());
    let side = c.sides()[0];
    let centres = c.cell_centres();
    let probes = [0usize, 203, 455];
    let want = mean_fields(&c, &orientations[..2], &probes);
    let mut probe = PairProbe::new(&d, Some(cutoff));
    let (sdirs, sw) = product_rule(12);
    let (odirs, ow) = product_rule(3);
    let (gx, gw) = swimlab::engine::continuum::sphere::gauss_legendre(8);
    let inner = 0.9 * cutoff;
    let mut edges = vec![core];
    for (a, b) in [(core, inner), (inner, cutoff)] {
        let n = ((b - a) / (0.2 * d.ell)).ceil() as usize;
        edges.extend((1..=n).map(|j| a + (b - a) * j as f64 / n as f64));
    }
    let mut worst: f64 = 0.0;
    let mut largest: f64 = 0.0;
    for (oi, n) in orientations[..2].iter().enumerate() {
        for (pi, &cell) in probes.iter().enumerate() {
            let x = centres[cell];
            let mut got = [0.0; 6];
            for e in edges.windows(2) {
                for (gxi, gwi) in gx.iter().zip(&gw) {
                    let dist = 0.5 * (e[0] + e[1]) + 0.5 * (e[1] - e[0]) * gxi;
                    let wr = 0.5 * (e[1] - e[0]) * gwi * dist * dist;
                    for (dh, wa) in sdirs.iter().zip(&sw) {
                        let dv = dh.map(|c| c * dist);
                        let xs: [f64; 3] = std::array::from_fn(|a| {
                            let v = x[a] - dv[a];
                            v - side * (v / side).round()
                        });
                        for (np, wo) in odirs.iter().zip(&ow) {
                            let r = probe.rates(dv, *n, *np);
                            let w = wr * wa * wo * f(xs, *np);
                            (0..6).for_each(|q| got[q] += w * r[q]);
                        }
                    }
                }
            }
            for q in 0..6 {
                worst = worst.max((got[q] - want[oi][pi][q]).abs());
                largest = largest.max(want[oi][pi][q].abs());
            }
        }
    }
    eprintln!("largest mean-field rate {largest:e}, worst deviation {worst:e}");
    assert!(
        largest > 0.0 && worst <= 1e-10 * largest,
        "{worst:e} of {largest:e}"
    );
}

/// Particles sampled from the distribution feel the mean field on average. N partners drawn from
/// f (rejection), each standing for ρV/N swimmers; each probe's rate is the engine's pair rates
/// summed over the partners beyond the core (minimum image). The mean field is a small residue
/// of large pair rates that cancel over orientations, so at these N the sampling error exceeds
/// it: the test is that the deviations are that sampling error. Over 8 cells × 3 orientations × 6
/// rates, the RMS of (particle − mean field)/(standard error from the sample's own variance) lies
/// in [0.6, 1.6] at every N (1 if the mean is right; a wrong mean field of the size of the true
/// one would not show at these N, which the quadrature test above covers), and the RMS deviation
/// falls as N^-1/2: its fitted exponent within 0.15 of −1/2.
#[test]
fn particles_sampled_from_the_distribution_feel_the_mean_field_on_average() {
    let d = asymmetric();
    let (c, orientations, f) = nematic_wave();
    let (core, cutoff) = (c.core(), c.cutoff());
    let side = c.sides()[0];
    let rho = 1.0 / d.ell.powi(3);
    let centres = c.cell_centres();
    let probes: Vec<usize> = (0..8).map(|i| i * 67 % centres.len()).collect();
    let want = mean_fields(&c, &orientations, &probes);
    let mut probe = PairProbe::new(&d, Some(cutoff));
    let fmax = rho / (4.0 * PI) * 1.5 * 1.9;
    let mut rng = Rng::new(11);
    let (mut deviations, mut zs) = (Vec::new(), Vec::new());
    let sizes = [500usize, 2000, 8000];
    let outputs = (orientations.len() * probes.len() * 6) as f64;
    let mut counted = 0.0;
    for &n_part in &sizes {
        let mut parts = Vec::with_capacity(n_part);
        while parts.len() < n_part {
            let x = [0, 1, 2].map(|_| (rng.uniform() - 0.5) * side);
            let n = rng.direction();
            if rng.uniform() * fmax <= f(x, n) {
                parts.push((x, n));
            }
        }
        let weight = rho * side.powi(3) / n_part as f64;
        let (mut sq, mut z2) = (0.0, 0.0);
        for (oi, n) in orientations.iter().enumerate() {
            for (pi, &cell) in probes.iter().enumerate() {
                let x = centres[cell];
                let (mut sum, mut sum2) = ([0.0; 6], [0.0; 6]);
                for (xp, np) in &parts {
                    let dv: [f64; 3] = std::array::from_fn(|a| {
                        let v = x[a] - xp[a];
                        v - side * (v / side).round()
                    });
                    let dist = (dv[0] * dv[0] + dv[1] * dv[1] + dv[2] * dv[2]).sqrt();
                    if dist < core || dist >= cutoff {
                        continue;
                    }
                    let p = probe.rates(dv, *n, *np);
                    for q in 0..6 {
                        sum[q] += p[q];
                        sum2[q] += p[q] * p[q];
                    }
                }
                for q in 0..6 {
                    if sum2[q] == 0.0 {
                        // A turn rate's component along n is zero for every partner.
                        continue;
                    }
                    let nf = n_part as f64;
                    let mean = sum[q] / nf;
                    let var = sum2[q] / nf - mean * mean;
                    let se = weight * (nf * var).sqrt();
                    let dev = weight * sum[q] - want[oi][pi][q];
                    sq += dev * dev;
                    z2 += (dev / se).powi(2);
                    counted += 1.0;
                }
            }
        }
        deviations.push((sq / counted).sqrt());
        zs.push((z2 / counted).sqrt());
        counted = 0.0;
    }
    let scale = (want
        .iter()
        .flatten()
        .flat_map(|r| r.iter())
        .map(|x| x * x)
        .sum::<f64>()
        / outputs)
        .sqrt();
    let relative: Vec<f64> = deviations.iter().map(|x| x / scale).collect();
    let slope = (deviations[2] / deviations[0]).ln() / (sizes[2] as f64 / sizes[0] as f64).ln();
    eprintln!("RMS deviation / RMS mean field {relative:?}, exponent {slope:.3}, RMS z {zs:?}");
    assert!(
        (slope + 0.5).abs() < 0.15,
        "deviations {deviations:?} fall as N^{slope}"
    );
    for z in &zs {
        assert!((0.6..=1.6).contains(z), "RMS z-scores {zs:?}");
    }
}

/// One asymmetric swimmer of the averaged model in a box of 40ℓ: one population, no mean field.
fn one_swimmer_in_a_box() -> (Scene, f64) {
    let d = asymmetric();
    let side = 40.0 * d.ell;
    let mut s = Scene::new();
    s.set_model(Model::Averaged);
    s.set_box(Some([side; 3])).unwrap();
    s.add(d, Vector3::zeros(), Vector3::x()).unwrap();
    (s, side)
}

/// With thermal noise, one population (no mean field) in the isotropic state relaxes by diffusion
/// alone: the slowest mode at small k is the density's, −D_t k² with D_t = (D∥ + 2D⊥)/3 of the
/// rigid dumbbell, up to the anisotropy's coupling to the nematic mode, a relative
/// O((D∥ − D⊥)k²/D_r) = 1e-4 here (tolerance 1e-3); the next are the polarization's at
/// −2D_r − D_t k² and the nematic's at −6D_r (to the same order). The solver agrees: a density
/// wave's amplitude after one relaxation time is e^{σt} of its start to 1e-6.
#[test]
fn thermal_modes_decay_at_the_dumbbells_diffusion_rates() {
    let (mut s, side) = one_swimmer_in_a_box();
    s.set_temperature(300.0).unwrap();
    let diff = s.rigid_diffusion(0).unwrap();
    let spec = ContinuumSpec {
        grid: [8, 8, 8],
        tol: 1e-10,
        ..Default::default()
    };
    let mut c = Continuum::of(&s, &spec).unwrap();
    let k = [2.0 * PI / side, 0.0, 0.0];
    let k2 = k[0] * k[0];
    let modes = c.growth_rates(&BaseState::Isotropic, k).unwrap();
    let dt = diff.translation();
    assert!(
        (modes[0].rate + dt * k2).abs() <= 1e-3 * dt * k2,
        "{:?} vs {}",
        modes[0],
        -dt * k2
    );
    assert_eq!(modes[0].degree, 0);
    let pol = modes.iter().find(|m| m.degree == 1).unwrap();
    assert!(
        (pol.rate + 2.0 * diff.rotation + dt * k2).abs() <= 1e-3 * 2.0 * diff.rotation,
        "{pol:?}"
    );
    let nem = modes.iter().find(|m| m.degree == 2).unwrap();
    assert!(
        (nem.rate + 6.0 * diff.rotation).abs() <= 1e-2 * 6.0 * diff.rotation,
        "{nem:?}"
    );
    assert!(BaseState::Polar([0.0, 0.0, 0.1]) != BaseState::Isotropic);
    assert!(c
        .growth_rates(&BaseState::Polar([0.0, 0.0, 0.1]), k)
        .is_err());
    c.perturb(
        &BaseState::Isotropic,
        FieldKind::Density,
        [1.0, 0.0, 0.0],
        [1, 0, 0],
        0.1,
        None,
    )
    .unwrap();
    let a0 = c.mode(FieldKind::Density, None, [1, 0, 0]).unwrap()[0];
    let t = 1.0 / (dt * k2);
    c.run(t).unwrap();
    let a1 = c.mode(FieldKind::Density, None, [1, 0, 0]).unwrap()[0];
    let want = (modes[0].rate * t).exp();
    assert!(((a1 / a0).re - want).abs() <= 1e-6, "{} vs {want}", a1 / a0);
}

/// A closure's effective diffusion is diffusion: at temperature 0, one population (no mean field)
/// relaxes at exactly its rates, the density at −D_t k², the polarization at −2D_r − D_t k², the
/// nematic order at −6D_r − D_t k² (isotropic D_t couples no harmonics: exact to the eigen-solver's
/// rounding, 1e-9 here); with noise as well, the closure adds to the dumbbell's own rates.
/// Nonsense is refused with what a closure takes.
#[test]
fn a_closure_adds_its_diffusion() {
    let (mut s, side) = one_swimmer_in_a_box();
    let (dr, dt) = (0.03, 2e-13);
    let spec = |closure: Option<Closure>| ContinuumSpec {
        grid: [8, 8, 8],
        closure,
        ..Default::default()
    };
    let closure = Closure::new(dr, dt, "a test's numbers").unwrap();
    let k = [2.0 * PI / side, 0.0, 0.0];
    let k2 = k[0] * k[0];
    let rates = |c: &Continuum| {
        let modes = c.growth_rates(&BaseState::Isotropic, k).unwrap();
        [0, 1, 2].map(|l| modes.iter().find(|m| m.degree == l).unwrap().rate)
    };
    let c = Continuum::of(&s, &spec(Some(closure.clone()))).unwrap();
    assert_eq!(c.closure(), Some(&closure));
    let got = rates(&c);
    let want = [-dt * k2, -2.0 * dr - dt * k2, -6.0 * dr - dt * k2];
    for (g, w) in got.iter().zip(&want) {
        assert!((g - w).abs() <= 1e-9 * w.abs(), "{got:?} vs {want:?}");
    }
    // Without a closure and without noise nothing relaxes.
    let none = Continuum::of(&s, &spec(None))
        .unwrap()
        .growth_rates(&BaseState::Isotropic, k)
        .unwrap();
    assert!(none.iter().all(|m| m.rate.abs() <= 1e-12 * dr), "{none:?}");
    // With noise the rates add: the dumbbell's own plus the closure's.
    s.set_temperature(300.0).unwrap();
    let thermal = rates(&Continuum::of(&s, &spec(None)).unwrap());
    let both = rates(&Continuum::of(&s, &spec(Some(closure))).unwrap());
    for l in 0..3 {
        let add = want[l];
        assert!(
            (both[l] - thermal[l] - add).abs() <= 1e-6 * add.abs(),
            "degree {l}: {both:?} = {thermal:?} + {want:?}?"
        );
    }
    assert!(Closure::new(-1.0, 0.0, "x").is_err());
    assert!(Closure::new(0.1, f64::NAN, "x").is_err());
    assert!(Closure::new(0.1, 0.0, " ").is_err());
}

/// A continuum's runs take a scene's run control: the progress is told the time after every
/// step, rising to the run's end; an interrupt stops a run between steps with `Interrupted` at
/// the last step's time, keeping what that step left, and the next run goes on from there.
#[test]
fn continuum_runs_report_progress_and_stop_on_an_interrupt() {
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::{Arc, Mutex};
    use swimlab::engine::EngineError;
    let side = 20.0 * asymmetric().ell;
    let s = two_populations(100, side, 11);
    let spec = ContinuumSpec {
        grid: [8, 8, 8],
        width: Some(2.0 * asymmetric().ell),
        ..Default::default()
    };
    let mut c = Continuum::of(&s, &spec).unwrap();
    let times = Arc::new(Mutex::new(Vec::new()));
    let told = times.clone();
    c.set_progress(Some(Arc::new(move |t| told.lock().unwrap().push(t))));
    let end = c.time() + 20.0 * c.period();
    c.run_periods(20.0).unwrap();
    let seen = std::mem::take(&mut *times.lock().unwrap());
    assert!(!seen.is_empty());
    assert!(seen.windows(2).all(|w| w[0] < w[1]), "{seen:?}");
    assert_eq!(*seen.last().unwrap(), c.time());
    assert!(
        (c.time() - end).abs() <= 1e-12 * end,
        "{} of {end}",
        c.time()
    );

    // The interrupt is asked before every step: the fourth question stops the run (a run of 1e6
    // periods takes more than three steps: each step grows the last one by a bounded factor).
    let asked = Arc::new(AtomicUsize::new(0));
    let count = asked.clone();
    c.set_interrupt(Some(Arc::new(move || {
        count.fetch_add(1, Ordering::SeqCst) >= 3
    })));
    let start = c.time();
    match c.run_periods(1e6) {
        Err(EngineError::Interrupted { time }) => assert_eq!(time, c.time()),
        other => panic!("not interrupted: {other:?}"),
    }
    let seen = std::mem::take(&mut *times.lock().unwrap());
    assert_eq!(seen.len(), 3, "{seen:?}");
    assert_eq!(*seen.last().unwrap(), c.time());
    assert!(c.time() > start);
    let stopped = c.time();
    c.set_interrupt(None);
    c.run_periods(1.0).unwrap();
    assert!(c.time() > stopped);
}
