//! The mean-field operator (the kernel's transforms, the orientation rule, the wave vectors the
//! 2/3 rule keeps) and the distribution's ODE that it drives.

use super::kernel::{self, Component, Constants, Radial};
use super::sphere::{monomial, monomials, Sphere};
use crate::engine::fft3::{signed_mode, Fft3};
use crate::engine::integrators::{OdeSystem, Problem};
use crate::engine::parallel::{for_chunks_mut, map_indices, PARALLEL_GRID_POINTS};
use crate::engine::thermal::RigidDiffusion;
use rayon::prelude::*;
use rustfft::num_complex::Complex64;
use std::f64::consts::PI;
use std::sync::Arc;

/// Cells × coefficients × orientation nodes from which a right-hand side's loop over cells runs
/// on rayon's threads.
const PARALLEL_CELL_TERMS: usize = 1 << 17;

/// The mean-field operator's parts that do not change in a run.
pub(super) struct Operator {
    pub(super) sphere: Sphere,
    /// The kernel's components, and their transforms: [component][k], k in the transform's
    /// layout (z fastest); K̂ = value, times i for m = 4.
    pub(super) comps: Vec<Component>,
    pub(super) kernel: Vec<Vec<f64>>,
    /// Components grouped by (output, target monomial): (output, monomial values at the nodes,
    /// component indices).
    pub(super) groups: Vec<(usize, Vec<f64>, Vec<usize>)>,
    /// ∫ n^β Y_i dΩ for the six second moments β, at [β][i].
    pub(super) second: Vec<Vec<f64>>,
    /// ∫ n_a Y_i dΩ, at [a][i].
    pub(super) first: Vec<Vec<f64>>,
    /// Wave vectors (1/m) in the transform's layout, and whether each survives the 2/3 rule.
    pub(super) waves: Vec<[f64; 3]>,
    pub(super) keep: Vec<bool>,
    /// sin(φ_p − φ_q) at [p][q].
    pub(super) sin: Vec<Vec<f64>>,
    pub(super) diffusion: Option<RigidDiffusion>,
    /// ∫ Y_i n_a n_b Y_j dΩ for the anisotropic translational diffusion (with noise), at
    /// [ab][i·B + j], ab over xx, xy, xz, yy, yz, zz.
    pub(super) nn: Vec<Vec<f64>>,
    pub(super) fft: Fft3,
    pub(super) cells: usize,
    /// Whether a right-hand side's loops over groups and coefficients (a transform each) run on
    /// rayon's threads: the grid has [`PARALLEL_GRID_POINTS`] (a smaller one's transforms are
    /// too short to hand out).
    pub(super) parallel: bool,
    /// Whether its loop over cells (B coefficients at every node of the orientation rule in
    /// each) does: from [`PARALLEL_CELL_TERMS`] cells × B × nodes (at degree 4, 25 coefficients
    /// at 98 nodes, from 54 cells).
    pub(super) cells_parallel: bool,
    /// The core and cutoff (m) of the kernel.
    pub(super) core: f64,
    pub(super) cutoff: f64,
}

/// The distribution's ODE: state y[(p·B + i)·cells + cell] = c_{p,i}(x_cell), f_p = Σ_i c_{p,i} Y_i.
#[derive(Clone)]
pub(super) struct Kinetic {
    pub(super) op: Arc<Operator>,
    pub(super) pops: usize,
}

/// The pair kernel's range: its core and its cutoff (m).
#[derive(Debug, Clone, Copy)]
pub(super) struct KernelRange {
    pub(super) core: f64,
    pub(super) cutoff: f64,
}

impl Operator {
    pub(super) fn new(
        grid: [usize; 3],
        sides: [f64; 3],
        degree: usize,
        constants: &Constants,
        range: KernelRange,
        phases: &[f64],
        diffusion: Option<RigidDiffusion>,
    ) -> Operator {
        let KernelRange { core, cutoff } = range;
        let sphere = Sphere::new(degree);
        let comps = kernel::components(constants);
        let cells: usize = grid.iter().product();
        let [mx, my, mz] = grid;
        // The transform's layout: z fastest, then y, then x.
        let mut waves = vec![[0.0; 3]; cells];
        let mut keep = vec![false; cells];
        for x in 0..mx {
            for y in 0..my {
                for z in 0..mz {
                    let idx = z + mz * (y + my * x);
                    let s = [signed_mode(x, mx), signed_mode(y, my), signed_mode(z, mz)];
                    waves[idx] = std::array::from_fn(|d| 2.0 * PI * s[d] / sides[d]);
                    keep[idx] = (0..3).all(|d| 3.0 * s[d].abs() < grid[d] as f64);
                }
            }
        }
        let k_max = waves
            .iter()
            .map(|k| (k[0] * k[0] + k[1] * k[1] + k[2] * k[2]).sqrt())
            .fold(0.0, f64::max);
        let radial = Radial::new(core, cutoff, k_max);
        let (dirs, dir_w) = kernel::directions();
        // Transforms at the kept wave vectors (the others never meet a nonzero mode).
        let per_k: Vec<Vec<f64>> = waves
            .par_iter()
            .zip(keep.par_iter())
            .map_init(Vec::new, |scratch, (k, keep)| {
                let mut out = vec![0.0; comps.len()];
                if *keep {
                    kernel::transform_at(&comps, &radial, &dirs, &dir_w, *k, &mut out, scratch);
                }
                out
            })
            .collect();
        let kernel: Vec<Vec<f64>> = (0..comps.len())
            .map(|c| per_k.iter().map(|v| v[c]).collect())
            .collect();
        drop(per_k);
        let mut groups: Vec<(usize, Vec<f64>, Vec<usize>)> = Vec::new();
        for (ci, c) in comps.iter().enumerate() {
            let at = |g: &(usize, Vec<f64>, Vec<usize>)| {
                g.0 == c.output && comps[g.2[0]].alpha == c.alpha
            };
            match groups.iter_mut().find(|g| at(g)) {
                Some(g) => g.2.push(ci),
                None => groups.push((
                    c.output,
                    sphere.nodes.iter().map(|n| monomial(n, &c.alpha)).collect(),
                    vec![ci],
                )),
            }
        }
        let moment = |e: [usize; 3]| -> Vec<f64> {
            let at: Vec<f64> = sphere.nodes.iter().map(|n| monomial(n, &e)).collect();
            let mut out = vec![0.0; sphere.len()];
            sphere.project(&at, &mut out);
            out.iter_mut().for_each(|x| {
                if x.abs() < 1e-14 {
                    *x = 0.0
                }
            });
            out
        };
        let second = monomials(2).into_iter().map(moment).collect();
        let first = monomials(1).into_iter().map(moment).collect();
        let bsz = sphere.len();
        let nn = if diffusion.is_some() {
            monomials(2)
                .into_iter()
                .map(|e| {
                    let mut m = vec![0.0; bsz * bsz];
                    for i in 0..bsz {
                        for j in 0..bsz {
                            m[i * bsz + j] = (0..sphere.node_count())
                                .map(|q| {
                                    sphere.weights[q]
                                        * sphere.value(i, q)
                                        * sphere.value(j, q)
                                        * monomial(&sphere.nodes[q], &e)
                                })
                                .sum();
                        }
                    }
                    m
                })
                .collect()
        } else {
            Vec::new()
        };
        let sin = phases
            .iter()
            .map(|p| {
                phases
                    .iter()
                    .map(|q| {
                        let s = (p - q).sin();
                        if s.abs() < 1e-14 {
                            0.0
                        } else {
                            s
                        }
                    })
                    .collect()
            })
            .collect();
        let cells_parallel = cells * bsz * sphere.node_count() >= PARALLEL_CELL_TERMS;
        Operator {
            sphere,
            comps,
            kernel,
            groups,
            second,
            first,
            waves,
            keep,
            sin,
            diffusion,
            nn,
            fft: Fft3::new(grid),
            cells,
            parallel: cells >= PARALLEL_GRID_POINTS,
            cells_parallel,
            core,
            cutoff,
        }
    }

    /// The transformed second moments M̂_{q,β}(k) of every population of state `y`.
    pub(super) fn moments(&self, y: &[f64], pops: usize) -> Vec<Vec<Vec<Complex64>>> {
        let b = self.sphere.len();
        let cells = self.cells;
        (0..pops)
            .map(|q| {
                self.second
                    .iter()
                    .map(|w| {
                        let mut buf = vec![Complex64::default(); cells];
                        for (i, wi) in w.iter().enumerate() {
                            if *wi != 0.0 {
                                let c = &y[(q * b + i) * cells..(q * b + i + 1) * cells];
                                buf.iter_mut().zip(c).for_each(|(o, v)| o.re += wi * v);
                            }
                        }
                        let mut spare = vec![Complex64::default(); cells];
                        self.fft.forward(&mut buf, &mut spare);
                        buf
                    })
                    .collect()
            })
            .collect()
    }

    /// The mean-field terms U_g(x) of population `p` (one field per group), or `None` where no
    /// population acts on it (every sin(φ_p − φ_q) zero).
    pub(super) fn mean_field_terms(
        &self,
        y: &[f64],
        pops: usize,
        p: usize,
    ) -> Option<Vec<Vec<f64>>> {
        if self.sin[p].iter().all(|s| *s == 0.0) {
            return None;
        }
        let m = self.moments(y, pops);
        Some(self.terms_from_moments(&m, p))
    }

    pub(super) fn terms_from_moments(&self, m: &[Vec<Vec<Complex64>>], p: usize) -> Vec<Vec<f64>> {
        let cells = self.cells;
        // Ŵ_β = Σ_q sin(φ_p − φ_q) M̂_{q,β}.
        let w: Vec<Vec<Complex64>> = (0..6)
            .map(|beta| {
                let mut acc = vec![Complex64::default(); cells];
                for (q, mq) in m.iter().enumerate() {
                    let s = self.sin[p][q];
                    if s != 0.0 {
                        acc.iter_mut().zip(&mq[beta]).for_each(|(a, v)| *a += s * v);
                    }
                }
                acc
            })
            .collect();
        let inv = 1.0 / cells as f64;
        map_indices(
            self.groups.len(),
            self.parallel,
            || (),
            |_, g| {
                let comps = &self.groups[g].2;
                let mut buf = vec![Complex64::default(); cells];
                for &c in comps {
                    let comp = &self.comps[c];
                    let ker = &self.kernel[c];
                    let src = &w[comp.beta];
                    if comp.m == 4 {
                        for ((o, k), s) in buf.iter_mut().zip(ker).zip(src) {
                            *o += Complex64::new(-k * s.im, k * s.re);
                        }
                    } else {
                        for ((o, k), s) in buf.iter_mut().zip(ker).zip(src) {
                            *o += k * s;
                        }
                    }
                }
                let mut spare = vec![Complex64::default(); cells];
                self.fft.inverse(&mut buf, &mut spare);
                buf.iter().map(|v| v.re * inv).collect()
            },
        )
    }
}

impl OdeSystem for Kinetic {
    fn dim(&self) -> usize {
        self.pops * self.op.sphere.len() * self.op.cells
    }

    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) {
        let op = &self.op;
        let b = op.sphere.len();
        let cells = op.cells;
        let nn = op.sphere.node_count();
        let moments = op.moments(y, self.pops);
        for p in 0..self.pops {
            let terms = if op.sin[p].iter().all(|s| *s == 0.0) {
                None
            } else {
                Some(op.terms_from_moments(&moments, p))
            };
            let block = |i: usize| &y[(p * b + i) * cells..(p * b + i + 1) * cells];
            // Fluxes F_{i,a} = ∫ Y_i v_a f and turns R_i = ∫ f ṅ·∇Y_i at every cell, at
            // [cell·4B + i·4 + a] (a cell's terms together, written by one thread).
            let width = 4 * b;
            let mut flux = vec![0.0; width * cells];
            if let Some(u) = &terms {
                for_chunks_mut(
                    &mut flux,
                    width,
                    op.cells_parallel,
                    || (vec![0.0; nn], vec![[0.0; 6]; nn], vec![0.0; b]),
                    |(f, rates, coef), cell, out| {
                        coef.iter_mut()
                            .enumerate()
                            .for_each(|(i, c)| *c = block(i)[cell]);
                        op.sphere.evaluate(coef, f);
                        rates.iter_mut().for_each(|r| *r = [0.0; 6]);
                        for (g, (o, at, _)) in op.groups.iter().enumerate() {
                            let uv = u[g][cell];
                            if uv != 0.0 {
                                for (r, a) in rates.iter_mut().zip(at) {
                                    r[*o] += uv * a;
                                }
                            }
                        }
                        for (j, (r, fj)) in rates.iter().zip(f.iter()).enumerate() {
                            let n = op.sphere.nodes[j];
                            let t = [r[3], r[4], r[5]];
                            let along = t[0] * n[0] + t[1] * n[1] + t[2] * n[2];
                            let turn: [f64; 3] = std::array::from_fn(|d| -(t[d] - along * n[d]));
                            let wf = op.sphere.weights[j] * fj;
                            for i in 0..b {
                                let yv = op.sphere.value(i, j) * wf;
                                let g = op.sphere.gradients[i * nn + j];
                                out[4 * i] += yv * r[0];
                                out[4 * i + 1] += yv * r[1];
                                out[4 * i + 2] += yv * r[2];
                                out[4 * i + 3] +=
                                    wf * (turn[0] * g[0] + turn[1] * g[1] + turn[2] * g[2]);
                            }
                        }
                    },
                );
            }
            // With noise: every coefficient's transform, for the diffusion terms.
            let hats: Option<Vec<Vec<Complex64>>> = op.diffusion.as_ref().map(|_| {
                map_indices(
                    b,
                    op.parallel,
                    || (),
                    |_, i| {
                        let mut spare = vec![Complex64::default(); cells];
                        let mut buf: Vec<Complex64> =
                            block(i).iter().map(|x| Complex64::new(*x, 0.0)).collect();
                        op.fft.forward(&mut buf, &mut spare);
                        buf
                    },
                )
            });
            let out: Vec<Vec<f64>> = map_indices(
                b,
                op.parallel,
                || (),
                |_, i| {
                    let mut spare = vec![Complex64::default(); cells];
                    // Flux term q of every cell, transformed.
                    let to_k = |q: usize, spare: &mut Vec<Complex64>| {
                        let mut buf: Vec<Complex64> = flux[q..]
                            .iter()
                            .step_by(width)
                            .map(|x| Complex64::new(*x, 0.0))
                            .collect();
                        op.fft.forward(&mut buf, spare);
                        buf
                    };
                    let mut acc = vec![Complex64::default(); cells];
                    if terms.is_some() {
                        let fx = to_k(4 * i, &mut spare);
                        let fy = to_k(4 * i + 1, &mut spare);
                        let fz = to_k(4 * i + 2, &mut spare);
                        let r = to_k(4 * i + 3, &mut spare);
                        for (k, a) in acc.iter_mut().enumerate() {
                            let w = op.waves[k];
                            let div = w[0] * fx[k] + w[1] * fy[k] + w[2] * fz[k];
                            *a = r[k] - Complex64::new(-div.im, div.re);
                        }
                    }
                    if let (Some(d), Some(hats)) = (&op.diffusion, &hats) {
                        let l = op.sphere.degree_of(i) as f64;
                        let own = &hats[i];
                        // −k·D(n)·k: D⊥ k² on c_i, (D∥ − D⊥) Σ_j ∫ Y_i (k·n)² Y_j c_j.
                        let kk = [[0, 1, 2], [1, 3, 4], [2, 4, 5]];
                        let others: Vec<usize> = (0..b)
                            .filter(|j| op.nn.iter().any(|m| m[i * b + j].abs() > 1e-14))
                            .collect();
                        for (k, a) in acc.iter_mut().enumerate() {
                            let w = op.waves[k];
                            let k2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
                            *a -= (d.rotation * l * (l + 1.0) + d.perpendicular * k2) * own[k];
                            let mut s = Complex64::default();
                            for &j in &others {
                                let mut q = 0.0;
                                for x in 0..3 {
                                    for z in 0..3 {
                                        q += w[x] * w[z] * op.nn[kk[x][z]][i * b + j];
                                    }
                                }
                                s += q * hats[j][k];
                            }
                            *a -= (d.parallel - d.perpendicular) * s;
                        }
                    }
                    for (a, keep) in acc.iter_mut().zip(&op.keep) {
                        if !keep {
                            *a = Complex64::default();
                        }
                    }
                    op.fft.inverse(&mut acc, &mut spare);
                    let inv = 1.0 / cells as f64;
                    acc.iter().map(|v| v.re * inv).collect()
                },
            );
            for (i, v) in out.into_iter().enumerate() {
                dy[(p * b + i) * cells..(p * b + i + 1) * cells].copy_from_slice(&v);
            }
        }
    }

    /// Per population, the RMS of its state's deviation from its spatial mean (the structure),
    /// floored at 1e-9 of the mean density's coefficient: the tolerance is relative to that.
    fn error_scale(&self, y: &[f64], scale: &mut [f64]) {
        let b = self.op.sphere.len();
        let cells = self.op.cells;
        for p in 0..self.pops {
            let span = p * b * cells..(p + 1) * b * cells;
            let mut dev = 0.0;
            for block in y[span.clone()].chunks(cells) {
                let mean = block.iter().sum::<f64>() / cells as f64;
                dev += block.iter().map(|x| (x - mean).powi(2)).sum::<f64>();
            }
            let rms = (dev / (b * cells) as f64).sqrt();
            let c0 = y[p * b * cells..(p * b + 1) * cells]
                .iter()
                .map(|x| x.abs())
                .sum::<f64>()
                / cells as f64;
            scale[span].fill(rms.max(1e-9 * c0).max(f64::MIN_POSITIVE));
        }
    }

    fn check(&mut self, _t: f64, y: &[f64]) -> std::result::Result<(), Problem> {
        if y.iter().all(|x| x.is_finite()) {
            Ok(())
        } else {
            Err(Problem {
                swimmer: None,
                cause: "the distribution is no longer finite".into(),
                hint: "use a finer tolerance".into(),
                fixes: Vec::new(),
            })
        }
    }

    fn autonomous(&self) -> bool {
        true
    }
}
