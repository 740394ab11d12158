//! Linear stability of homogeneous states: growth rates σ(k) of plane-wave perturbations
//! δf_p = δc_{p,i} Y_i(n) e^{ik·x}, the eigenvalues of the operator linearised about a state
//! f̄_p(n) uniform in space, in the same Galerkin basis and quadrature as the solver:
//!
//! dδc_{p,i}/dt = ∫ [−i(k·v̄_p) δf_p − i(k·δv_p) f̄_p] Y_i + [ṅ̄_p δf_p + δṅ_p f̄_p]·∇Y_i dΩ
//!              − D_r l(l+1) δc_{p,i} − ∫ Y_i (k·D(n)·k) δf_p dΩ,
//!
//! v̄, ṅ̄ the base's own mean field (the kernel at k = 0) and δv, δṅ the perturbation's (at k).
//! The mean field reads only second moments, so for a base that does not move itself (v̄ = ṅ̄ = 0:
//! the isotropic state and the polar state ρ(1 + 3P·n)/4π, whose second moment is isotropic) and
//! without noise the harmonics of degree ≤ 2 form a closed system: its eigenvalues are exact at
//! any L ≥ 2, and those of degree > 2 are 0 (they are carried along, never fed back).

use super::kernel::{self, Radial};
use super::operator::Operator;
use super::spec::Population;
use super::state::Continuum;
use crate::engine::error::{invalid, Result};
use nalgebra::DMatrix;
use rustfft::num_complex::Complex64;
use std::f64::consts::PI;

/// A homogeneous state to linearise about.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BaseState {
    /// Uniform and isotropic: f_p = ρ_p/4π.
    Isotropic,
    /// Uniform and polar with polarization P (|P| ≤ 1/3): f_p = ρ_p(1 + 3P·n)/4π.
    Polar([f64; 3]),
}

/// One eigenvalue σ = rate + i·frequency (1/s) of the linearised operator, with the harmonic
/// degree and the population that carry most of its eigenvector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mode {
    /// Re σ (1/s): growth where positive.
    pub rate: f64,
    /// Im σ (1/s).
    pub frequency: f64,
    /// The harmonic degree l with most of the eigenvector (0 density, 1 polarization, 2 nematic).
    pub degree: usize,
    /// The population with most of the eigenvector.
    pub population: usize,
}

/// The Galerkin coefficients [p·B + i] of `base` at each population's density `dens` (1/m³).
pub(super) fn base_coefficients(op: &Operator, dens: &[f64], base: &BaseState) -> Result<Vec<f64>> {
    let b = op.sphere.len();
    let mut out = vec![0.0; dens.len() * b];
    let pol = match base {
        BaseState::Isotropic => [0.0; 3],
        BaseState::Polar(p) => *p,
    };
    let size = (pol[0] * pol[0] + pol[1] * pol[1] + pol[2] * pol[2]).sqrt();
    if !(size.is_finite() && size <= 1.0 / 3.0 + 1e-12) {
        return Err(invalid!(
            "the polar state rho(1 + 3P.n)/4pi is a distribution only for |P| <= 1/3, got |P| = {size}; give a smaller polarization"
        ));
    }
    for (p, rho) in dens.iter().enumerate() {
        let at: Vec<f64> = op
            .sphere
            .nodes
            .iter()
            .map(|n| {
                rho / (4.0 * PI) * (1.0 + 3.0 * (pol[0] * n[0] + pol[1] * n[1] + pol[2] * n[2]))
            })
            .collect();
        op.sphere.project(&at, &mut out[p * b..(p + 1) * b]);
    }
    Ok(out)
}

/// The mean field (velocity, T) at every node of a population with moment sources `w` (6 second
/// moments, already weighted by the phase sines) through kernel values `kv` (one per component;
/// times i for m = 4): [node][output].
fn nodal_field(op: &Operator, kv: &[f64], w: &[Complex64; 6]) -> Vec<[Complex64; 6]> {
    let nn = op.sphere.node_count();
    let mut out = vec![[Complex64::default(); 6]; nn];
    for (o, at, comps) in &op.groups {
        let mut u = Complex64::default();
        for &c in comps {
            let comp = &op.comps[c];
            let k = if comp.m == 4 {
                Complex64::new(0.0, kv[c])
            } else {
                Complex64::new(kv[c], 0.0)
            };
            u += k * w[comp.beta];
        }
        for (r, a) in out.iter_mut().zip(at) {
            r[*o] += u * a;
        }
    }
    out
}

/// The turn rate −(1 − nn)T at node `n` from the output's T components.
fn turn(n: &[f64; 3], r: &[Complex64; 6]) -> [Complex64; 3] {
    let t = [r[3], r[4], r[5]];
    let along = t[0] * n[0] + t[1] * n[1] + t[2] * n[2];
    std::array::from_fn(|d| -(t[d] - along * n[d]))
}

/// The eigenvalues of the operator linearised about `base` at each population's mean density
/// `dens`, at wave vector `k` (1/m), fastest growing first.
pub(super) fn growth_rates(
    op: &Operator,
    pops: &[Population],
    dens: &[f64],
    base: &BaseState,
    k: [f64; 3],
) -> Result<Vec<Mode>> {
    let a = linear_operator(op, pops, dens, base, k)?;
    let dim = a.nrows();
    let bsz = op.sphere.len();
    let schur = nalgebra::Schur::try_new(a.clone(), 1e-15, 100_000).ok_or_else(|| {
        invalid!("the linearised operator's eigenvalues did not converge; try fewer orientations")
    })?;
    let (_, t) = schur.unpack();
    let mut modes: Vec<Mode> = (0..dim)
        .map(|e| {
            let lambda = t[(e, e)];
            let (degree, population) = character(&a, lambda, bsz, |i| op.sphere.degree_of(i));
            Mode {
                rate: lambda.re,
                frequency: lambda.im,
                degree,
                population,
            }
        })
        .collect();
    modes.sort_by(|x, y| y.rate.total_cmp(&x.rate));
    Ok(modes)
}

/// The operator linearised about `base` at each population's density `dens` at wave vector `k`
/// (1/m): dδc/dt = A δc for δc_{p,i} at [p·B + i].
pub(super) fn linear_operator(
    op: &Operator,
    pops: &[Population],
    dens: &[f64],
    base: &BaseState,
    k: [f64; 3],
) -> Result<DMatrix<Complex64>> {
    if matches!(base, BaseState::Polar(_))
        && op.diffusion.as_ref().is_some_and(|d| d.rotation > 0.0)
    {
        return Err(invalid!(
            "with rotational diffusion (thermal noise, or a closure's rotation) the polar state is not stationary (its polarization decays at 2 D_r), so it has no growth rates; linearise about the isotropic state, or build the continuum at temperature 0 without a closure's rotation"
        ));
    }
    if k.iter().any(|x| !x.is_finite()) {
        return Err(invalid!(
            "a wave vector needs three finite components in 1/m"
        ));
    }
    let bsz = op.sphere.len();
    let np = pops.len();
    let nn = op.sphere.node_count();
    let cbar = base_coefficients(op, dens, base)?;
    let kn = (k[0] * k[0] + k[1] * k[1] + k[2] * k[2]).sqrt();
    let k_max = 128.0 * PI / op.core;
    if kn > k_max {
        return Err(invalid!(
            "the wave vector's length {kn:e} 1/m is beyond what the kernel resolves, {k_max:.3e} 1/m (64 waves across the core); the continuum describes waves longer than the core"
        ));
    }
    let radial = Radial::new(op.core, op.cutoff, kn.max(1.0 / op.cutoff));
    let (dirs, dir_w) = kernel::directions();
    let mut scratch = Vec::new();
    let mut k_at = vec![0.0; op.comps.len()];
    kernel::transform_at(
        &op.comps,
        &radial,
        &dirs,
        &dir_w,
        k,
        &mut k_at,
        &mut scratch,
    );
    let mut k_zero = vec![0.0; op.comps.len()];
    kernel::transform_at(
        &op.comps,
        &radial,
        &dirs,
        &dir_w,
        [0.0; 3],
        &mut k_zero,
        &mut scratch,
    );
    // The base at the nodes, its second moments and its own mean field.
    let fbar: Vec<Vec<f64>> = (0..np)
        .map(|p| {
            let mut f = vec![0.0; nn];
            op.sphere.evaluate(&cbar[p * bsz..(p + 1) * bsz], &mut f);
            f
        })
        .collect();
    let moments = |c: &[f64]| -> [f64; 6] {
        std::array::from_fn(|b| op.second[b].iter().zip(c).map(|(w, x)| w * x).sum())
    };
    let mbar: Vec<[f64; 6]> = (0..np)
        .map(|p| moments(&cbar[p * bsz..(p + 1) * bsz]))
        .collect();
    let own: Vec<Vec<[Complex64; 6]>> = (0..np)
        .map(|p| {
            let w: [Complex64; 6] = std::array::from_fn(|b| {
                Complex64::new((0..np).map(|q| op.sin[p][q] * mbar[q][b]).sum(), 0.0)
            });
            nodal_field(op, &k_zero, &w)
        })
        .collect();
    let dim = np * bsz;
    let mut a = DMatrix::<Complex64>::zeros(dim, dim);
    let ik = |v: &[Complex64; 6]| {
        let kv = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
        Complex64::new(-kv.im, kv.re)
    };
    for q in 0..np {
        for ip in 0..bsz {
            let col = q * bsz + ip;
            let dm: [f64; 6] = std::array::from_fn(|b| op.second[b][ip]);
            for p in 0..np {
                let s = op.sin[p][q];
                let field = (s != 0.0).then(|| {
                    let w: [Complex64; 6] = std::array::from_fn(|b| Complex64::new(s * dm[b], 0.0));
                    nodal_field(op, &k_at, &w)
                });
                for i in 0..bsz {
                    let mut sum = Complex64::default();
                    for j in 0..nn {
                        let n = &op.sphere.nodes[j];
                        let w = op.sphere.weights[j];
                        let yi = op.sphere.value(i, j);
                        let g = op.sphere.gradients[i * nn + j];
                        if p == q {
                            let df = op.sphere.value(ip, j);
                            let r = &own[p][j];
                            let t = turn(n, r);
                            sum += w * df * (-ik(r) * yi + t[0] * g[0] + t[1] * g[1] + t[2] * g[2]);
                        }
                        if let Some(fl) = &field {
                            let r = &fl[j];
                            let t = turn(n, r);
                            sum += w
                                * fbar[p][j]
                                * (-ik(r) * yi + t[0] * g[0] + t[1] * g[1] + t[2] * g[2]);
                        }
                    }
                    if p == q {
                        if let Some(d) = &op.diffusion {
                            let l = op.sphere.degree_of(i) as f64;
                            let k2 = kn * kn;
                            let mut aniso = 0.0;
                            for j in 0..nn {
                                let n = &op.sphere.nodes[j];
                                let kdotn = k[0] * n[0] + k[1] * n[1] + k[2] * n[2];
                                aniso += op.sphere.weights[j]
                                    * op.sphere.value(i, j)
                                    * op.sphere.value(ip, j)
                                    * kdotn
                                    * kdotn;
                            }
                            let diag = if i == ip {
                                d.rotation * l * (l + 1.0) + d.perpendicular * k2
                            } else {
                                0.0
                            };
                            sum -= diag + (d.parallel - d.perpendicular) * aniso;
                        }
                    }
                    a[(p * bsz + i, col)] = sum;
                }
            }
        }
    }
    Ok(a)
}

/// The harmonic degree and population carrying most of the eigenvector of `a` at `lambda`, by
/// two steps of inverse iteration from a fixed start.
fn character(
    a: &DMatrix<Complex64>,
    lambda: Complex64,
    bsz: usize,
    degree_of: impl Fn(usize) -> usize,
) -> (usize, usize) {
    let dim = a.nrows();
    let scale = a.iter().map(|x| x.norm()).fold(0.0, f64::max).max(1e-300);
    let shift = lambda + Complex64::new(1e-10 * scale, 1e-10 * scale);
    let m = a - DMatrix::<Complex64>::identity(dim, dim) * shift;
    let lu = m.lu();
    let mut x = nalgebra::DVector::<Complex64>::from_fn(dim, |i, _| {
        Complex64::new(1.0 + 0.1 * i as f64, 0.3)
    });
    for _ in 0..2 {
        if let Some(y) = lu.solve(&x) {
            let norm = y.norm().max(1e-300);
            x = y / Complex64::new(norm, 0.0);
        }
    }
    let mut weight = std::collections::BTreeMap::<(usize, usize), f64>::new();
    for (idx, v) in x.iter().enumerate() {
        *weight
            .entry((idx / bsz, degree_of(idx % bsz)))
            .or_insert(0.0) += v.norm_sqr();
    }
    let best = weight
        .iter()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map(|(k, _)| *k)
        .unwrap_or((0, 0));
    (best.1, best.0)
}

impl Continuum {
    /// Growth rates about a homogeneous state at wave vector `k` (1/m), fastest first: the
    /// eigenvalues of the linearised operator ([`Continuum::linear_operator`]).
    pub fn growth_rates(&self, base: &BaseState, k: [f64; 3]) -> Result<Vec<Mode>> {
        let mean = self.mean_densities();
        growth_rates(&self.kinetic.op, &self.populations, &mean, base, k)
    }

    /// The operator linearised about `base` at wave vector `k` (1/m): dδc/dt = A δc, δc_{p,i} the
    /// complex amplitude of c_{p,i} at e^{ik·x}, at [p·B + i].
    pub fn linear_operator(
        &self,
        base: &BaseState,
        k: [f64; 3],
    ) -> Result<nalgebra::DMatrix<Complex64>> {
        let mean = self.mean_densities();
        linear_operator(&self.kinetic.op, &self.populations, &mean, base, k)
    }

    /// The state of a homogeneous `base` at each population's mean density, [p·B + i].
    pub fn base_coefficients(&self, base: &BaseState) -> Result<Vec<f64>> {
        base_coefficients(&self.kinetic.op, &self.mean_densities(), base)
    }
}
