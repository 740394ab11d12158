//! The periodic RPY/Oseen mobility product by spectral Ewald summation (Lindbo & Tornberg, J.
//! Comput. Phys. 229, 8994 (2010); the same wave-space part as the positively split Ewald of
//! Fiore et al., J. Chem. Phys. 146, 124116 (2017)), for many spheres.
//!
//! Beenakker's splitting (see [`super`]) with the real-space sum cut at r_c ≤ L/2, so only
//! minimum images count and cell lists find them: O(N). The reciprocal sum
//! Σ_k W(k)(I − k̂k̂)[(1 − a_i²k²/6) C(k) − (k²/6) D(k)] e^{ik·x_i}, C = Σ_j F_j e^{−ik·x_j},
//! D = Σ_j a_j² F_j e^{−ik·x_j}, is taken on a grid:
//! - the forces are spread with a Gaussian g(x) = (α/π)^{3/2} e^{−α|x|²}, ĝ(k) = e^{−ηk²/8ξ²},
//!   α = 2ξ²/η, truncated to P points per axis (F in the real part, a²F in the imaginary part of
//!   one complex field per component, so three transforms carry six real fields);
//! - three forward FFTs give C and D, which are multiplied by the Ewald kernel over ĝ²;
//! - three inverse FFTs, and the same Gaussian gathers the velocities back at the spheres (the two
//!   output fields again packed as real and imaginary parts).
//!
//! Errors: the waves beyond the grid's are below the tolerance as in Beenakker's sum (the grid
//! holds every k up to k_c = 2pξ); the Gaussian's truncation error e^{−m²/2} and its aliasing
//! error e^{−π²P²/2m²} are balanced by m = 0.976√(πP) (Lindbo & Tornberg 2011), both ~e^{−πP/2}.
//! The cost per product is O(N P³ + G log G) for G grid points, G ∝ N at a fixed density.

use super::split::{truncation, Split};
use crate::engine::cells::CellGrid;
use crate::engine::error::{invalid, Result};
use crate::engine::fft3::{signed_mode, Fft3};
use crate::engine::parallel::PARALLEL_IMAGE_SPHERES;
use crate::engine::periodic::PeriodicBox;
use nalgebra::Vector3;
use rayon::prelude::*;
use rustfft::num_complex::Complex64;
use std::f64::consts::PI;

/// The largest grid (points) the method builds: 3 fields of 2^22 complex points and their
/// transposes take 400 MB.
pub const MAX_GRID_POINTS: usize = 1 << 22;

/// The Gaussian support P (points per axis) for tolerance `tol`: e^{−πP/2} a tenth of it, and
/// four points more: without them the errors against Beenakker's sum exceed `tol` at tight
/// tolerances (the measurement is in the book's design notes).
fn support_points(tol: f64) -> usize {
    ((2.0 / PI * (10.0 / tol).ln()).ceil() as usize + 4).clamp(6, 32)
}

/// The grid holds the waves up to this many times Beenakker's k_c: the RPY part carries an extra
/// k², and the Gaussian's errors grow towards the grid's Nyquist wave. At 1.3 the errors against
/// Beenakker's sum stay within `tol` over the tolerances, box shapes and kernels tried; at 1.0
/// they do not at tight tolerances (the measurement is in the book's design notes).
const OVERSAMPLE: f64 = 1.3;

/// A sphere's Gaussian support: per axis the first grid index (wrapped) and the P weights.
type Support = ([usize; 3], [[f64; 32]; 3]);

/// The smallest n ≥ `at_least` whose only prime factors are 2, 3 and 5 (fast FFT lengths).
fn smooth(at_least: usize) -> usize {
    (at_least.max(1)..)
        .find(|&n| {
            let mut m = n;
            for p in [2, 3, 5] {
                while m % p == 0 {
                    m /= p;
                }
            }
            m == 1
        })
        .unwrap_or(at_least)
}

/// The periodic mobility product by spectral Ewald summation in one box, its splitting, grid and
/// Gaussian fixed.
#[derive(Clone)]
pub struct SpectralEwald {
    periodic: PeriodicBox,
    split: Split,
    /// The real-space cutoff r_c ≤ L/2.
    rc: f64,
    /// Grid points per axis.
    m: [usize; 3],
    /// Grid spacing per axis.
    h: [f64; 3],
    /// Gaussian support points per axis.
    p: usize,
    /// Gaussian exponent α (1/m²).
    alpha: f64,
    /// Per grid point, in the transformed layout (z fastest, then y, then x): the kernel
    /// (norm·Vc)² W(k)/ĝ(k)² (Vc the grid cell's volume, the Gaussian's normalisation applied once
    /// for spreading and once for gathering; zero at k = 0 and at the Nyquist planes), units
    /// 1/(6πμ).
    kernel: Vec<f64>,
    /// Forward and inverse transforms per axis.
    fft: Fft3,
}

impl std::fmt::Debug for SpectralEwald {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SpectralEwald")
            .field("xi", &self.split.xi)
            .field("rc", &self.rc)
            .field("grid", &self.m)
            .field("support", &self.p)
            .finish()
    }
}

/// Measured costs (ns per core) of the method's parts, for the choice of ξ: a real-space pair
/// within r_c (erfc, exp), a pair scanned in the 27 cells around a sphere, a support point spread
/// and gathered (three components), a grid point's share of one transform per log2 of the grid
/// size. Only their ratios matter: they pick ξ.
const COST_PAIR: f64 = 60.0;
const COST_SCAN: f64 = 15.0;
const COST_SUPPORT: f64 = 6.0;
const COST_FFT: f64 = 2.0;

impl SpectralEwald {
    /// The periodic mobility of `split` (ξ replaced) in box `periodic` for `spheres` spheres,
    /// accurate to `tol`; `xi` (1/m) fixes the splitting, else it is chosen for speed.
    pub(super) fn new(
        periodic: PeriodicBox,
        split: Split,
        spheres: usize,
        tol: f64,
        xi: Option<f64>,
    ) -> Result<Self> {
        let p = truncation(tol);
        let support = support_points(tol);
        let l = periodic.sides();
        let lmin = periodic.shortest();
        // r_c = p/ξ ≤ L/2: only minimum images within r_c.
        let xi_min = 2.0 * p / lmin;
        let grid_for = |xi: f64| {
            l.map(|side| {
                smooth(((OVERSAMPLE * 2.0 * p * xi * side / PI).ceil() as usize + 1).max(support))
            })
        };
        let xi = match xi {
            Some(x) if x.is_finite() && x >= xi_min => x,
            Some(x) => {
                return Err(invalid!(
                    "the spectral Ewald splitting must be at least 2p/L = {xi_min:e} 1/m (its real-space sum takes minimum images only), got {x:e}"
                ))
            }
            None => {
                let n = spheres.max(1) as f64;
                let density = n / periodic.volume();
                let cost = |xi: f64| {
                    let rc = p / xi;
                    let pairs = n * density * 4.0 * PI / 3.0 * rc.powi(3);
                    let cells = l.map(|side| (side / rc).floor().max(1.0));
                    let scanned = n * (density * periodic.volume() / cells.iter().product::<f64>()
                        * cells.iter().map(|&c| c.min(3.0)).product::<f64>())
                    .min(n);
                    let g = grid_for(xi).iter().product::<usize>() as f64;
                    COST_PAIR * pairs
                        + COST_SCAN * scanned
                        + COST_SUPPORT * n * (support as f64).powi(3)
                        + COST_FFT * 6.0 * g * g.log2()
                };
                (0..=60)
                    .map(|i| xi_min * 10f64.powf(i as f64 / 40.0))
                    .filter(|&x| grid_for(x).iter().product::<usize>() <= MAX_GRID_POINTS)
                    .min_by(|a, b| cost(*a).total_cmp(&cost(*b)))
                    .unwrap_or(xi_min)
            }
        };
        let m = grid_for(xi);
        let points: usize = m.iter().product();
        if points > MAX_GRID_POINTS {
            return Err(invalid!(
                "the spectral Ewald grid would need {}×{}×{} points (at most {MAX_GRID_POINTS}); loosen the Ewald tolerance, make the box less elongated, or sum by Beenakker's method (Ewald method \"beenakker\")",
                m[0],
                m[1],
                m[2]
            ));
        }
        let h = [0, 1, 2].map(|a| l[a] / m[a] as f64);
        let hmin = h.iter().copied().fold(f64::INFINITY, f64::min);
        // Lindbo & Tornberg's shape: support half-width w = P h/2, m = 0.976√(πP), η = (2wξ/m)².
        let shape = 0.976 * (PI * support as f64).sqrt();
        let eta = (support as f64 * hmin * xi / shape).powi(2);
        let alpha = 2.0 * xi * xi / eta;
        let norm = (alpha / PI).powf(1.5);
        let cell = h[0] * h[1] * h[2];
        let volume = periodic.volume();
        // The Nyquist planes of even grids are left out (their waves have no ± partner).
        let mode =
            |i: usize, n: usize| (!(n.is_multiple_of(2) && i == n / 2)).then(|| signed_mode(i, n));
        let mut kernel = vec![0.0; points];
        kernel
            .par_chunks_mut(m[2] * m[1])
            .enumerate()
            .for_each(|(x, plane)| {
                for y in 0..m[1] {
                    for z in 0..m[2] {
                        let (Some(nx), Some(ny), Some(nz)) =
                            (mode(x, m[0]), mode(y, m[1]), mode(z, m[2]))
                        else {
                            continue;
                        };
                        let k = Vector3::new(
                            2.0 * PI * nx / l[0],
                            2.0 * PI * ny / l[1],
                            2.0 * PI * nz / l[2],
                        );
                        let k2 = k.norm_squared();
                        if k2 == 0.0 {
                            continue;
                        }
                        let q = k2 / (4.0 * xi * xi);
                        let w = 6.0 * PI / volume * (1.0 + q + 2.0 * q * q) * (-q).exp() / k2;
                        plane[z + m[2] * y] = (norm * cell).powi(2) * w * (eta * q).exp();
                    }
                }
            });
        let fft = Fft3::new(m);
        Ok(SpectralEwald {
            periodic,
            split: Split { xi, ..split },
            rc: p / xi,
            m,
            h,
            p: support,
            alpha,
            kernel,
            fft,
        })
    }

    /// The splitting parameter ξ (1/m).
    pub fn splitting(&self) -> f64 {
        self.split.xi
    }

    /// Grid points per axis.
    pub fn grid(&self) -> [usize; 3] {
        self.m
    }

    /// The Gaussian's support at `x`: per axis the first grid index (wrapped) and the P weights.
    fn support(&self, x: &Vector3<f64>) -> Support {
        let l = self.periodic.sides();
        let mut start = [0; 3];
        let mut w = [[0.0; 32]; 3];
        for a in 0..3 {
            let u = (x[a] / l[a] + 0.5).rem_euclid(1.0) * self.m[a] as f64;
            let first = (u - self.p as f64 / 2.0).ceil();
            for (t, wt) in w[a].iter_mut().take(self.p).enumerate() {
                let d = (first + t as f64 - u) * self.h[a];
                *wt = (-self.alpha * d * d).exp();
            }
            start[a] = (first as i64).rem_euclid(self.m[a] as i64) as usize;
        }
        (start, w)
    }

    /// u_i = Σ_j M_ij F_j − F_i/(6πμa_i) for every sphere (the Stokes drag of each sphere's own
    /// force left out), as [`super::Ewald::interaction_velocities`].
    pub fn interaction_velocities(
        &self,
        pos: &[Vector3<f64>],
        radii: &[f64],
        forces: &[Vector3<f64>],
        out: &mut [Vector3<f64>],
    ) {
        let unit = 1.0 / (6.0 * PI * self.split.mu);
        // a²/a_ref², so that the real and imaginary parts packed in one transform are of one size
        // (else the smaller part keeps only the digits the larger leaves it).
        let aref2 = radii.iter().map(|a| a * a).fold(0.0, f64::max);
        let a2: Vec<f64> = radii
            .iter()
            .map(|a| {
                if self.split.finite_size {
                    a * a / aref2
                } else {
                    0.0
                }
            })
            .collect();
        let supports: Vec<Support> = pos.iter().map(|x| self.support(x)).collect();
        let mut grid = self.spread(&supports, &a2, forces);
        let mut spare: [Vec<Complex64>; 3] =
            std::array::from_fn(|_| vec![Complex64::default(); grid[0].len()]);
        self.forward(&mut grid, &mut spare);
        // The transformed fields are now in `grid`; the kernel writes the output into `spare`.
        self.apply_kernel(&grid, &mut spare, aref2);
        self.inverse(&mut spare, &mut grid);
        let wave = &spare;
        self.real_space(pos, radii, forces, out);
        let gather = |(i, u): (usize, &mut Vector3<f64>)| {
            let (start, w) = &supports[i];
            let mut re = [0.0; 3];
            let mut im = [0.0; 3];
            let [mx, my, mz] = self.m;
            let (segs, count) = x_runs(start[0], self.p, mx);
            for (tz, wz) in w[2].iter().take(self.p).enumerate() {
                let z = (start[2] + tz) % mz;
                for (ty, wy) in w[1].iter().take(self.p).enumerate() {
                    let row = mx * ((start[1] + ty) % my + my * z);
                    let wyz = wy * wz;
                    for &(gx, t0, len) in &segs[..count] {
                        let wx = &w[0][t0..t0 + len];
                        for q in 0..3 {
                            let (mut sr, mut si) = (0.0, 0.0);
                            for (v, c) in wave[q][row + gx..row + gx + len].iter().zip(wx) {
                                sr += v.re * c;
                                si += v.im * c;
                            }
                            re[q] += wyz * sr;
                            im[q] += wyz * si;
                        }
                    }
                }
            }
            let scale = unit;
            for q in 0..3 {
                u[q] += scale * (re[q] - a2[i] * im[q]);
            }
        };
        if pos.len() >= PARALLEL_IMAGE_SPHERES {
            out.par_iter_mut().enumerate().for_each(gather);
        } else {
            out.iter_mut().enumerate().for_each(gather);
        }
    }

    /// The real-space and self parts into `out` (overwritten), minimum images within r_c (and
    /// the overlap correction of overlapping pairs) found through cell lists.
    fn real_space(
        &self,
        pos: &[Vector3<f64>],
        radii: &[f64],
        forces: &[Vector3<f64>],
        out: &mut [Vector3<f64>],
    ) {
        let unit = 1.0 / (6.0 * PI * self.split.mu);
        let amax = radii.iter().copied().fold(0.0, f64::max);
        let reach = self.rc.max(2.0 * amax);
        let rc2 = self.rc * self.rc;
        let x: Vec<f64> = pos.iter().map(|p| p[0]).collect();
        let y: Vec<f64> = pos.iter().map(|p| p[1]).collect();
        let z: Vec<f64> = pos.iter().map(|p| p[2]).collect();
        let cells = CellGrid::build_in(&x, &y, &z, reach, Some(&self.periodic));
        let row = |runs: &mut Vec<(u32, u32)>, (i, u): (usize, &mut Vector3<f64>)| {
            cells.neighbour_runs(x[i], y[i], z[i], runs);
            let mut v = self.split.self_excess(radii[i]) * forces[i];
            for &(s, e) in runs.iter() {
                for &j in &cells.order[s as usize..e as usize] {
                    let j = j as usize;
                    if j == i {
                        continue;
                    }
                    let r = self.periodic.min_image(pos[i] - pos[j]);
                    let r2 = r.norm_squared();
                    if r2 <= rc2 && r2 > 0.0 {
                        let (ci, crr) =
                            self.split.real(r2.sqrt(), self.split.s(radii[i], radii[j]));
                        v += ci * forces[j] + r * (crr * r.dot(&forces[j]) / r2);
                    }
                    v += self.split.overlap_apply(&r, radii[i], radii[j], &forces[j]) / unit;
                }
            }
            *u = v * unit;
        };
        if pos.len() >= PARALLEL_IMAGE_SPHERES {
            out.par_iter_mut().enumerate().for_each_init(Vec::new, row);
        } else {
            let mut runs = Vec::new();
            out.iter_mut().enumerate().for_each(|iu| row(&mut runs, iu));
        }
    }

    /// The forces (real parts) and a²·forces (imaginary parts) spread on the grid, one field per
    /// component, x fastest. The spheres are taken by slabs of P planes along z (a sphere writes P
    /// planes from its own slab's first): the even slabs in parallel, each within its own 2P
    /// planes, then the odd ones; writes past the last plane wrap to the first planes after each
    /// pass. Each plane is written in a fixed order, so the sums do not depend on the thread count.
    fn spread(
        &self,
        supports: &[Support],
        a2: &[f64],
        forces: &[Vector3<f64>],
    ) -> [Vec<Complex64>; 3] {
        let [mx, my, mz] = self.m;
        let plane = mx * my;
        let thick = self.p;
        let mut members = vec![Vec::new(); mz.div_ceil(thick)];
        for (j, (start, _)) in supports.iter().enumerate() {
            members[start[2] / thick].push(j);
        }
        // Within a slab, by row: neighbours in the list share grid rows in the caches.
        for list in &mut members {
            list.sort_by_key(|&j| (supports[j].0[1], supports[j].0[0], j));
        }
        let mut grid: [Vec<Complex64>; 3] =
            std::array::from_fn(|_| vec![Complex64::default(); plane * mz]);
        // One sphere into `f` (planes from `first`, absolute), wrapped planes into `over`.
        let put =
            |j: usize, first: usize, f: &mut [&mut [Complex64]; 3], over: &mut Vec<Complex64>| {
                let (start, w) = &supports[j];
                let c: [Complex64; 3] =
                    std::array::from_fn(|q| Complex64::new(forces[j][q], a2[j] * forces[j][q]));
                let (segs, count) = x_runs(start[0], self.p, mx);
                let planes = f[0].len() / plane;
                for (tz, wz) in w[2].iter().take(self.p).enumerate() {
                    let gz = start[2] + tz;
                    // Past the last plane: into `over`, wrapped later.
                    let inside = gz - first < planes;
                    if !inside && over.is_empty() {
                        over.resize(3 * thick * plane, Complex64::default());
                    }
                    for (ty, wy) in w[1].iter().take(self.p).enumerate() {
                        let row = mx * ((start[1] + ty) % my);
                        let wyz = wy * wz;
                        for &(gx, t0, len) in &segs[..count] {
                            let wx = &w[0][t0..t0 + len];
                            for (q, cq) in c.iter().enumerate() {
                                let cq = cq * wyz;
                                let dst = if inside {
                                    let at = (gz - first) * plane + row + gx;
                                    &mut f[q][at..at + len]
                                } else {
                                    let at = (q * thick + gz - mz) * plane + row + gx;
                                    &mut over[at..at + len]
                                };
                                for (d, x) in dst.iter_mut().zip(wx) {
                                    *d += cq * *x;
                                }
                            }
                        }
                    }
                }
            };
        for parity in 0..2 {
            let offset = parity * thick * plane;
            let [g0, g1, g2] = &mut grid;
            let overflow: Vec<Vec<Complex64>> = g0[offset..]
                .par_chunks_mut(2 * thick * plane)
                .zip(g1[offset..].par_chunks_mut(2 * thick * plane))
                .zip(g2[offset..].par_chunks_mut(2 * thick * plane))
                .enumerate()
                .map(|(c, ((f0, f1), f2))| {
                    let slab = 2 * c + parity;
                    let mut over = Vec::new();
                    let mut f = [f0, f1, f2];
                    for &j in members.get(slab).into_iter().flatten() {
                        put(j, slab * thick, &mut f, &mut over);
                    }
                    over
                })
                .collect();
            for over in overflow.iter().filter(|o| !o.is_empty()) {
                for (q, field) in grid.iter_mut().enumerate() {
                    let src = &over[q * thick * plane..(q + 1) * thick * plane];
                    for (d, s) in field.iter_mut().zip(src) {
                        *d += s;
                    }
                }
            }
        }
        grid
    }

    /// Forward transforms of the three fields: x rows, then (transposed) y rows, then z rows. The
    /// result is in `grid` with z fastest, then y, then x.
    fn forward(&self, grid: &mut [Vec<Complex64>; 3], spare: &mut [Vec<Complex64>; 3]) {
        for (g, s) in grid.iter_mut().zip(spare.iter_mut()) {
            self.fft.forward(g, s);
        }
    }

    /// Inverse transforms of the three fields in `grid` (z fastest), back to x fastest in `grid`.
    fn inverse(&self, grid: &mut [Vec<Complex64>; 3], spare: &mut [Vec<Complex64>; 3]) {
        for (g, s) in grid.iter_mut().zip(spare.iter_mut()) {
            self.fft.inverse(g, s);
        }
    }

    /// Y(k) = kernel · (I − k̂k̂)[C − (k²/6) D] + i kernel · (I − k̂k̂)(k²/6) C from the packed
    /// transforms Z = C + iD (C, D the transforms of real fields: C(k) = (Z(k) + Z(−k)*)/2,
    /// D(k) = (Z(k) − Z(−k)*)/2i), z fastest, into `out`.
    fn apply_kernel(&self, z: &[Vec<Complex64>; 3], out: &mut [Vec<Complex64>; 3], aref2: f64) {
        let [mx, my, mz] = self.m;
        let l = self.periodic.sides();
        let wavenumber = |i: usize, n: usize, side: f64| 2.0 * PI * signed_mode(i, n) / side;
        let finite = self.split.finite_size;
        let [o0, o1, o2] = out;
        o0.par_chunks_mut(mz * my)
            .zip(o1.par_chunks_mut(mz * my))
            .zip(o2.par_chunks_mut(mz * my))
            .enumerate()
            .for_each(|(x, ((c0, c1), c2))| {
                let xm = (mx - x) % mx;
                let kx = wavenumber(x, mx, l[0]);
                for y in 0..my {
                    let ym = (my - y) % my;
                    let ky = wavenumber(y, my, l[1]);
                    for zi in 0..mz {
                        let local = zi + mz * y;
                        let idx = local + mz * my * x;
                        let g = self.kernel[idx];
                        if g == 0.0 {
                            c0[local] = Complex64::default();
                            c1[local] = Complex64::default();
                            c2[local] = Complex64::default();
                            continue;
                        }
                        let mirror = (mz - zi) % mz + mz * (ym + my * xm);
                        let k = [kx, ky, wavenumber(zi, mz, l[2])];
                        let k2 = k[0] * k[0] + k[1] * k[1] + k[2] * k[2];
                        let mut cc = [Complex64::default(); 3];
                        let mut dd = [Complex64::default(); 3];
                        for q in 0..3 {
                            let (a, b) = (z[q][idx], z[q][mirror].conj());
                            cc[q] = (a + b) * 0.5;
                            dd[q] = (a - b) * Complex64::new(0.0, -0.5);
                        }
                        let c6 = aref2 * k2 / 6.0;
                        let (mut first, mut second) =
                            ([Complex64::default(); 3], [Complex64::default(); 3]);
                        for q in 0..3 {
                            first[q] = if finite { cc[q] - dd[q] * c6 } else { cc[q] };
                            second[q] = if finite {
                                cc[q] * c6
                            } else {
                                Complex64::default()
                            };
                        }
                        let project = |v: &mut [Complex64; 3]| {
                            let kv = (v[0] * k[0] + v[1] * k[1] + v[2] * k[2]) / k2;
                            for q in 0..3 {
                                v[q] = (v[q] - kv * k[q]) * g;
                            }
                        };
                        project(&mut first);
                        project(&mut second);
                        let i = Complex64::new(0.0, 1.0);
                        c0[local] = first[0] + i * second[0];
                        c1[local] = first[1] + i * second[1];
                        c2[local] = first[2] + i * second[2];
                    }
                }
            });
    }
}

/// The support's P points along x from grid index `start` in a row of `m` points, as at most two
/// runs (grid index, first weight, length): the second one after the wrap.
fn x_runs(start: usize, p: usize, m: usize) -> ([(usize, usize, usize); 2], usize) {
    if start + p <= m {
        ([(start, 0, p), (0, 0, 0)], 1)
    } else {
        let first = m - start;
        ([(start, 0, first), (0, first, p - first)], 2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fft_lengths_are_smooth() {
        assert_eq!(smooth(1), 1);
        assert_eq!(smooth(7), 8);
        assert_eq!(smooth(49), 50);
        assert_eq!(smooth(53), 54);
        assert_eq!(smooth(121), 125);
    }

    #[test]
    fn the_support_wraps_in_at_most_two_runs() {
        assert_eq!(x_runs(3, 5, 10), ([(3, 0, 5), (0, 0, 0)], 1));
        assert_eq!(x_runs(5, 5, 10), ([(5, 0, 5), (0, 0, 0)], 1));
        assert_eq!(x_runs(8, 5, 10), ([(8, 0, 2), (0, 2, 3)], 2));
    }

    /// More waves and more support points as the tolerance tightens, within the weight arrays.
    #[test]
    fn support_grows_with_the_tolerance() {
        let p: Vec<usize> = [1e-2, 1e-6, 1e-10, 1e-15].map(support_points).to_vec();
        assert!(p.windows(2).all(|w| w[0] < w[1]), "{p:?}");
        assert!(p[3] <= 32);
    }
}
