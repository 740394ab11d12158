//! The periodic Rotne-Prager-Yamakawa mobility by Ewald summation (Beenakker, J. Chem. Phys. 85,
//! 1581 (1986)), for unequal radii.
//!
//! The RPY pair tensor is (1 + (a_i² + a_j²)/6 ∇²)G, G the Oseen tensor: every term of Beenakker's
//! equal-radius sum is linear in a², so unequal radii take s = (a_i² + a_j²)/2 where his form has
//! a² (the Oseen part carries a⁰, the finite-size part a²). With ξ the splitting
//! parameter (1/m), E = e^{−ξ²r²}/√π and everything in units of 1/(6πμ):
//! - real space, over every image r = x_i − x_j + nL (the particle's own r = 0 left out):
//!   c_I = erfc(ξr)(3/(4r) + s/(2r³)) + E(3ξ³r² − 9ξ/2 + s(4ξ⁷r⁴ − 20ξ⁵r² + 14ξ³ + ξ/r²)),
//!   c_rr = erfc(ξr)(3/(4r) − 3s/(2r³)) + E(−3ξ³r² + 3ξ/2 + s(−4ξ⁷r⁴ + 16ξ⁵r² − 2ξ³ − 3ξ/r²));
//! - reciprocal space, over k = 2π(n_x/L_x, n_y/L_y, n_z/L_z) ≠ 0 (the k = 0 mode left out: no net
//!   flow through the box): (6π/V)(1 − s k²/3)(1 + k²/4ξ² + k⁴/8ξ⁴) e^{−k²/4ξ²} cos(k·r)(I − k̂k̂)/k²;
//! - self: 1/a_i − 6ξ/√π + (40/3) ξ³ a_i²/√π.
//!
//! Overlapping spheres (r < a_i + a_j, nearest image) get the difference between the overlapping
//! form of Zuk et al. and Mazur's at that image (both are exact pair terms; only the nearest image
//! can overlap in a box longer than twice the largest sphere). The Oseen mobility is the same sum
//! with s = 0.
//!
//! Truncation: both sums fall as e^{−p²} times a polynomial in p, with p = ξ r_c = k_c/(2ξ); p is
//! chosen so that e^{−p²}(1 + p⁴) is the tolerance, and ξ to minimise the work for the number of
//! spheres (all pairs times the images within r_c, against the spheres times the waves within k_c).
//! The result does not depend on ξ beyond that tolerance (tests/periodic.rs).

use super::choice::{self, Choice, Named};
use super::error::{invalid, unsupported, Result, Setting};
use super::mobility::{self_mobility, Mobility, MobilityOperator};
use super::parallel::PARALLEL_IMAGE_SPHERES;
use super::periodic::{PeriodicBox, WavePhases};
use nalgebra::{DMatrix, Matrix3, Vector3};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
pub use spectral::SpectralEwald;
use std::f64::consts::PI;

pub mod spectral;

/// How the box's mobility products are summed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EwaldMethod {
    /// Beenakker's sums below [`SPECTRAL_FROM_SPHERES`] spheres, the spectral method from there.
    #[default]
    Auto,
    /// Beenakker's sums over images and waves: O(N²) per product.
    Beenakker,
    /// Spectral Ewald on an FFT grid: O(N log N) per product.
    Spectral,
}

/// From this many spheres "auto" takes the spectral method: within the crossover that
/// `swimlab bench ewald` measures (the book, "Suspensions, boxes and fields"; the figures are in
/// its design notes).
pub const SPECTRAL_FROM_SPHERES: usize = 700;

impl Named for EwaldMethod {
    const KIND: &'static str = "Ewald method";
    const CHOICES: &'static [Choice<Self>] = &[
        Choice {
            value: EwaldMethod::Auto,
            name: "auto",
            about: "Beenakker for few spheres, spectral for many, default",
        },
        Choice {
            value: EwaldMethod::Beenakker,
            name: "beenakker",
            about: "sums over images and waves, O(N^2) per product",
        },
        Choice {
            value: EwaldMethod::Spectral,
            name: "spectral",
            about: "spectral Ewald on an FFT grid, O(N log N) per product",
        },
    ];
}

choice::inherent_names!(EwaldMethod);

impl EwaldMethod {
    /// Beenakker or spectral for `spheres` spheres.
    pub fn resolve(self, spheres: usize) -> Self {
        match self {
            EwaldMethod::Auto if spheres >= SPECTRAL_FROM_SPHERES => EwaldMethod::Spectral,
            EwaldMethod::Auto => EwaldMethod::Beenakker,
            m => m,
        }
    }
}

/// The default tolerance of the Ewald sums (relative to the spheres' Stokes mobility).
pub const DEFAULT_EWALD_TOL: f64 = 1e-10;

/// One reciprocal vector of the half space (its partner −k adds the same real part).
#[derive(Debug, Clone, Copy)]
struct Wave {
    n: [i64; 3],
    k: Vector3<f64>,
    k2: f64,
    /// 2 (6π/V)(1 + k²/4ξ² + k⁴/8ξ⁴) e^{−k²/4ξ²}/k², in units of 1/(6πμ).
    g: f64,
}

/// The periodic mobility of spheres in one box, with its splitting and truncation fixed.
#[derive(Debug, Clone)]
pub struct Ewald {
    periodic: PeriodicBox,
    split: Split,
    rc2: f64,
    /// Lattice vectors nL that can bring a minimum image within r_c (n = 0 included), by length.
    shifts: Vec<Vector3<f64>>,
    /// Their lengths, ascending.
    shift_norms: Vec<f64>,
    /// r_c.
    rc: f64,
    waves: Vec<Wave>,
    /// Largest |n| per axis among the waves.
    n_max: [usize; 3],
    /// Products by the spectral method (blocks and the matrix stay Beenakker's).
    spectral: Option<SpectralEwald>,
}

/// What both methods share: the viscosity, RPY or Oseen, and the splitting ξ; the real-space,
/// self and overlap terms.
#[derive(Debug, Clone, Copy)]
struct Split {
    mu: f64,
    /// RPY (finite size) or Oseen (s = 0).
    finite_size: bool,
    xi: f64,
}

/// Truncation parameter p for tolerance `tol`: e^{−p²}(1 + p⁴) = tol.
fn truncation(tol: f64) -> f64 {
    let target = -tol.ln();
    let mut p = target.sqrt();
    for _ in 0..8 {
        p = (target + (1.0 + p.powi(4)).ln()).sqrt();
    }
    p
}

impl Split {
    /// s for a pair of radii: (a_i² + a_j²)/2 for RPY, 0 for Oseen.
    #[inline]
    fn s(&self, ai: f64, aj: f64) -> f64 {
        if self.finite_size {
            0.5 * (ai * ai + aj * aj)
        } else {
            0.0
        }
    }

    /// Real-space coefficients (c_I, c_rr) at distance `r` > 0, units 1/(6πμ).
    #[inline]
    fn real(&self, r: f64, s: f64) -> (f64, f64) {
        let xi = self.xi;
        let (x2, r2) = (xi * xi, r * r);
        let erfc = libm::erfc(xi * r);
        let e = (-x2 * r2).exp() / PI.sqrt();
        let (x3, x5, x7) = (x2 * xi, x2 * x2 * xi, x2 * x2 * x2 * xi);
        let ci = erfc * (0.75 / r + 0.5 * s / (r2 * r))
            + e * (3.0 * x3 * r2 - 4.5 * xi
                + s * (4.0 * x7 * r2 * r2 - 20.0 * x5 * r2 + 14.0 * x3 + xi / r2));
        let crr = erfc * (0.75 / r - 1.5 * s / (r2 * r))
            + e * (-3.0 * x3 * r2
                + 1.5 * xi
                + s * (-4.0 * x7 * r2 * r2 + 16.0 * x5 * r2 - 2.0 * x3 - 3.0 * xi / r2));
        (ci, crr)
    }

    /// The self term less the Stokes drag, units 1/(6πμ): −6ξ/√π + (40/3)ξ³a²/√π.
    fn self_excess(&self, a: f64) -> f64 {
        let s = self.s(a, a);
        (-6.0 * self.xi + 40.0 / 3.0 * self.xi.powi(3) * s) / PI.sqrt()
    }

    /// The overlapping-sphere correction (c_I, c_rr) at the nearest image `r0`, absolute units
    /// (RPY only; `None` when apart).
    #[inline]
    fn overlap(&self, r0: &Vector3<f64>, ai: f64, aj: f64) -> Option<(f64, f64)> {
        let d = r0.norm();
        if !self.finite_size || d >= ai + aj || d == 0.0 {
            return None;
        }
        let (zi, zrr) = Mobility::Rpy.pair_coefficients(self.mu, d, ai, aj);
        let oseen = 1.0 / (8.0 * PI * self.mu * d);
        let fs = (ai * ai + aj * aj) / (24.0 * PI * self.mu * d * d * d);
        Some((zi - oseen - fs, zrr - oseen + 3.0 * fs))
    }

    /// The overlapping-sphere correction applied to `f` (zero when apart).
    #[inline]
    fn overlap_apply(&self, r0: &Vector3<f64>, ai: f64, aj: f64, f: &Vector3<f64>) -> Vector3<f64> {
        match self.overlap(r0, ai, aj) {
            Some((ci, crr)) => ci * f + r0 * (crr * r0.dot(f) / r0.norm_squared()),
            None => Vector3::zeros(),
        }
    }
}

impl Ewald {
    /// The periodic `mobility` in box `periodic` for `spheres` spheres, accurate to `tol`; `xi`
    /// (1/m) fixes the splitting, else it is chosen for speed.
    pub fn new(
        periodic: PeriodicBox,
        mu: f64,
        mobility: Mobility,
        spheres: usize,
        tol: f64,
        xi: Option<f64>,
    ) -> Result<Self> {
        check_tol(tol)?;
        let p = truncation(tol);
        let l = periodic.sides();
        let volume = periodic.volume();
        let counts = |xi: f64| {
            let rc = p / xi;
            let kc = 2.0 * p * xi;
            let images = (4.0 * PI / 3.0 * rc.powi(3) / volume).max(1.0);
            let waves = kc.powi(3) * volume / (12.0 * PI * PI);
            (images, waves)
        };
        let given_xi = xi.is_some();
        let xi = match xi {
            Some(x) if x.is_finite() && x > 0.0 => x,
            Some(x) => {
                return Err(invalid!(
                    "the Ewald splitting parameter must be a positive number (1/m), got {x}; leave it out to have it chosen"
                ))
            }
            None => {
                let n = spheres.max(1) as f64;
                let lmin = periodic.shortest();
                // Measured costs per term: an image within r_c (erfc and exp) ~25 units, a
                // lattice shift tested ~1, a wave per sphere ~10 (its phase and the sum, twice).
                (0..=80)
                    .map(|i| 0.5 * 10f64.powf(i as f64 / 40.0) / lmin)
                    .min_by(|a, b| {
                        let cost = |xi: f64| {
                            let (im, wv) = counts(xi);
                            let tested = 27.0f64.max(8.0 * im);
                            n * n * (25.0 * im + tested) + 10.0 * n * wv
                        };
                        cost(*a).total_cmp(&cost(*b))
                    })
                    .unwrap_or(PI.sqrt() / lmin)
            }
        };
        let (images, waves) = counts(xi);
        let rc = p / xi;
        let kc = 2.0 * p * xi;
        let half_diag = 0.5 * (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
        let reach = rc + half_diag;
        // Lattice shifts tested: every minimum image lies within half the diagonal, so the images
        // within r_c of it need shifts up to their sum, along each side.
        let tested: f64 = l
            .iter()
            .map(|side| 2.0 * (reach / side).ceil() + 1.0)
            .product();
        if images > 2e5 || waves > 2e6 || tested > 2e7 {
            if given_xi {
                return Err(invalid!(
                    "the Ewald sums would need {images:.0} images, {waves:.0} waves and {tested:.0} lattice shifts at splitting {xi:e} 1/m; choose a splitting nearer 1/L (about {:e} 1/m) or a looser tolerance",
                    PI.sqrt() / periodic.shortest()
                ));
            }
            return Err(unsupported(
                format!(
                    "the Ewald sums of a box of sides {:e}, {:e}, {:e} m at tolerance {tol:e} would need {images:.0} images, {waves:.0} waves and {tested:.0} lattice shifts, beyond what they take (2e5, 2e6 and 2e7): the box is too elongated (its sides {:.0} times apart) for this tolerance; give it sides nearer each other (the averaged model takes minimum images, no Ewald sums)",
                    l[0],
                    l[1],
                    l[2],
                    l.iter().copied().fold(0.0, f64::max) / periodic.shortest()
                ),
                if tested > 2e7 {
                    // Shifts follow the box's shape, not the tolerance.
                    &[Setting::Model("averaged")][..]
                } else {
                    &[Setting::LooserEwaldTol, Setting::Model("averaged")][..]
                },
            ));
        }
        let m = l.map(|side| (reach / side).ceil() as i32);
        let mut shifts = Vec::new();
        for i in -m[0]..=m[0] {
            for j in -m[1]..=m[1] {
                for k in -m[2]..=m[2] {
                    let s = Vector3::new(i as f64 * l[0], j as f64 * l[1], k as f64 * l[2]);
                    if s.norm() <= reach {
                        shifts.push(s);
                    }
                }
            }
        }
        shifts.sort_by(|a, b| a.norm().total_cmp(&b.norm()));
        let shift_norms = shifts.iter().map(|s| s.norm()).collect();
        let list = periodic
            .half_space_waves(kc)
            .into_iter()
            .map(|(n, k)| {
                let k2 = k.norm_squared();
                let q = k2 / (4.0 * xi * xi);
                let g = 2.0 * 6.0 * PI / volume * (1.0 + q + 2.0 * q * q) * (-q).exp() / k2;
                Wave { n, k, k2, g }
            })
            .collect();
        Ok(Ewald {
            periodic,
            split: Split {
                mu,
                finite_size: mobility == Mobility::Rpy,
                xi,
            },
            rc2: rc * rc,
            shifts,
            shift_norms,
            rc,
            waves: list,
            n_max: periodic.wave_index_max(kc),
            spectral: None,
        })
    }

    /// The periodic mobility by `method` ("auto" resolved for `spheres` spheres; `xi` fixes the
    /// products' splitting, else it is chosen for speed): with the
    /// spectral method the products are spectral Ewald sums, while blocks and the dense matrix
    /// stay Beenakker's (splitting chosen for one block at a time).
    pub fn with_method(
        periodic: PeriodicBox,
        mu: f64,
        mobility: Mobility,
        spheres: usize,
        tol: f64,
        method: EwaldMethod,
        xi: Option<f64>,
    ) -> Result<Self> {
        if method.resolve(spheres) == EwaldMethod::Beenakker {
            return Self::new(periodic, mu, mobility, spheres, tol, xi);
        }
        let mut e = Self::new(periodic, mu, mobility, 1, tol, None)?;
        match SpectralEwald::new(periodic, e.split, spheres, tol, xi) {
            Ok(g) => e.spectral = Some(g),
            // A box too elongated for the grid: "auto" sums by Beenakker's method instead.
            Err(_) if method == EwaldMethod::Auto => {
                return Self::new(periodic, mu, mobility, spheres, tol, xi)
            }
            Err(err) => return Err(err),
        }
        Ok(e)
    }

    /// The method of the products: Beenakker or spectral.
    pub fn method(&self) -> EwaldMethod {
        match self.spectral {
            Some(_) => EwaldMethod::Spectral,
            None => EwaldMethod::Beenakker,
        }
    }

    /// The spectral method's sums, when it gives the products.
    pub fn spectral(&self) -> Option<&SpectralEwald> {
        self.spectral.as_ref()
    }

    /// The splitting parameter ξ (1/m).
    pub fn splitting(&self) -> f64 {
        self.split.xi
    }

    /// The box.
    pub fn periodic(&self) -> &PeriodicBox {
        &self.periodic
    }

    /// Every image r = r0 + nL of separation `r0` (a minimum image) within r_c, the particle's own
    /// r = 0 left out, given to `visit` with |r|² and its real-space coefficients (c_I, c_rr).
    #[inline]
    fn real_images(
        &self,
        r0: &Vector3<f64>,
        s: f64,
        mut visit: impl FnMut(&Vector3<f64>, f64, f64, f64),
    ) {
        // |r0 + nL| ≥ |nL| − |r0|: the shifts, by length, are done once that exceeds r_c.
        let reach = self.rc + r0.norm();
        for (sh, &len) in self.shifts.iter().zip(&self.shift_norms) {
            if len > reach {
                break;
            }
            let r = r0 + sh;
            let r2 = r.norm_squared();
            if r2 == 0.0 || r2 > self.rc2 {
                continue;
            }
            let (ci, crr) = self.split.real(r2.sqrt(), s);
            visit(&r, r2, ci, crr);
        }
    }

    /// The real-space sum over the images of separation `r0`: Σ_n M(r0 + nL) f.
    #[inline]
    fn real_apply(&self, r0: &Vector3<f64>, s: f64, f: &Vector3<f64>) -> Vector3<f64> {
        let mut u = Vector3::zeros();
        self.real_images(r0, s, |r, r2, ci, crr| {
            u += ci * f + r * (crr * r.dot(f) / r2)
        });
        u
    }

    /// u_i = Σ_j M_ij F_j − F_i/(6πμa_i) for every sphere: the periodic interaction velocities
    /// (the Stokes drag of each sphere's own force left out, as [`Mobility::interaction_velocities`]).
    pub fn interaction_velocities(
        &self,
        pos: &[Vector3<f64>],
        radii: &[f64],
        forces: &[Vector3<f64>],
        out: &mut [Vector3<f64>],
    ) {
        if let Some(g) = &self.spectral {
            return g.interaction_velocities(pos, radii, forces, out);
        }
        let n = pos.len();
        let unit = 1.0 / (6.0 * PI * self.split.mu);
        let parallel = n >= PARALLEL_IMAGE_SPHERES;
        // Reciprocal space: per wave, C = Σ_j F_j e^{−ik·x_j} and D = Σ_j a_j² F_j e^{−ik·x_j}.
        let phases = WavePhases::new(&self.periodic, pos, self.n_max);
        let sums = |w: &Wave| {
            let mut c = [[0.0; 2]; 3];
            let mut d = [[0.0; 2]; 3];
            for j in 0..n {
                let (re, im) = phases.at(j, w.n);
                // e^{−ik·x} = re − i im.
                let a2 = if self.split.finite_size {
                    radii[j] * radii[j]
                } else {
                    0.0
                };
                for q in 0..3 {
                    let f = forces[j][q];
                    c[q][0] += f * re;
                    c[q][1] -= f * im;
                    d[q][0] += a2 * f * re;
                    d[q][1] -= a2 * f * im;
                }
            }
            (c, d)
        };
        let wave_sums: Vec<_> = if parallel {
            self.waves.par_iter().map(sums).collect()
        } else {
            self.waves.iter().map(sums).collect()
        };
        let row = |i: usize, u: &mut Vector3<f64>| {
            let mut v = Vector3::zeros();
            for j in 0..n {
                let r0 = self.periodic.min_image(pos[i] - pos[j]);
                v += self.real_apply(&r0, self.split.s(radii[i], radii[j]), &forces[j]);
                if j != i {
                    v += self
                        .split
                        .overlap_apply(&r0, radii[i], radii[j], &forces[j])
                        / unit;
                }
            }
            v += self.split.self_excess(radii[i]) * forces[i];
            let ai2 = if self.split.finite_size {
                radii[i] * radii[i]
            } else {
                0.0
            };
            for (w, (c, d)) in self.waves.iter().zip(&wave_sums) {
                let (re, im) = phases.at(i, w.n);
                // Re[e^{ik·x_i}((1 − a_i²k²/6) C − (k²/6) D)] per component.
                let (p, q) = (1.0 - ai2 * w.k2 / 6.0, -w.k2 / 6.0);
                let z = Vector3::from_fn(|m, _| {
                    let (zr, zi) = (p * c[m][0] + q * d[m][0], p * c[m][1] + q * d[m][1]);
                    re * zr - im * zi
                });
                v += w.g * (z - w.k * (w.k.dot(&z) / w.k2));
            }
            *u = v * unit;
        };
        if parallel {
            out.par_iter_mut().enumerate().for_each(|(i, u)| row(i, u));
        } else {
            out.iter_mut().enumerate().for_each(|(i, u)| row(i, u));
        }
    }

    /// The block M_ij (3×3) between spheres at minimum image separation `r0` = x_i − x_j, radii
    /// `ai`, `aj`; `same`: i = j (the block then includes the sphere's Stokes drag).
    pub fn block(&self, r0: &Vector3<f64>, ai: f64, aj: f64, same: bool) -> Matrix3<f64> {
        let unit = 1.0 / (6.0 * PI * self.split.mu);
        let mut m = Matrix3::zeros();
        self.real_images(r0, self.split.s(ai, aj), |r, r2, ci, crr| {
            m += ci * Matrix3::identity() + (crr / r2) * r * r.transpose();
        });
        if same {
            m += (self.split.self_excess(ai) + 1.0 / ai) * Matrix3::identity();
        } else if let Some((ci, crr)) = self.split.overlap(r0, ai, aj) {
            m +=
                (ci * Matrix3::identity() + (crr / r0.norm_squared()) * r0 * r0.transpose()) / unit;
        }
        let (ai2, aj2) = if self.split.finite_size {
            (ai * ai, aj * aj)
        } else {
            (0.0, 0.0)
        };
        for w in &self.waves {
            let factor = 1.0 - (ai2 + aj2) * w.k2 / 6.0;
            let proj = Matrix3::identity() - w.k * w.k.transpose() / w.k2;
            m += w.g * factor * w.k.dot(r0).cos() * proj;
        }
        m * unit
    }

    /// The full 3N×3N periodic mobility matrix, Stokes drag included (tests, dense noise roots).
    pub fn matrix(&self, pos: &[Vector3<f64>], radii: &[f64]) -> DMatrix<f64> {
        let n = pos.len();
        let mut m = DMatrix::zeros(3 * n, 3 * n);
        for a in 0..n {
            for b in a..n {
                let r0 = self.periodic.min_image(pos[a] - pos[b]);
                let h = self.block(&r0, radii[a], radii[b], a == b);
                m.fixed_view_mut::<3, 3>(3 * a, 3 * b).copy_from(&h);
                if a != b {
                    m.fixed_view_mut::<3, 3>(3 * b, 3 * a)
                        .copy_from(&h.transpose());
                }
            }
        }
        m
    }
}

/// The Ewald tolerance must lie in [1e-15, 1e-2].
pub fn check_tol(tol: f64) -> Result<()> {
    if tol.is_finite() && (1e-15..=1e-2).contains(&tol) {
        Ok(())
    } else {
        Err(invalid!(
            "the Ewald tolerance must lie between 1e-15 and 1e-2, got {tol}; e.g. 1e-10"
        ))
    }
}

/// Stokes' drag mobility of a single sphere of radius `a` in a cubic box of side `l` (Hasimoto's
/// series, exact for the RPY sphere): (1 − c a/L + (4π/3)(a/L)³)/(6πμa), c = 2.8372974794 (the
/// Madelung-like constant to ten digits; quoted as 2.837297 it is 5e-7 a/L low).
pub fn hasimoto(mu: f64, a: f64, l: f64) -> f64 {
    let x = a / l;
    self_mobility(mu, a) * (1.0 - 2.837_297_479_4 * x + 4.0 * PI / 3.0 * x.powi(3))
}

impl MobilityOperator for Ewald {
    fn interaction_velocities(
        &mut self,
        pos: &[Vector3<f64>],
        radii: &[f64],
        forces: &[Vector3<f64>],
        out: &mut [Vector3<f64>],
    ) {
        Ewald::interaction_velocities(self, pos, radii, forces, out);
    }

    fn block(
        &self,
        xa: &Vector3<f64>,
        xb: &Vector3<f64>,
        ai: f64,
        aj: f64,
        same: bool,
    ) -> Matrix3<f64> {
        Ewald::block(self, &self.periodic.min_image(xa - xb), ai, aj, same)
    }

    fn matrix(&self, pos: &[Vector3<f64>], radii: &[f64]) -> DMatrix<f64> {
        Ewald::matrix(self, pos, radii)
    }

    fn periodic(&self) -> Option<&PeriodicBox> {
        Some(&self.periodic)
    }

    fn boxed(&self) -> Box<dyn MobilityOperator> {
        Box::new(self.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(l: f64) -> PeriodicBox {
        PeriodicBox::new([l; 3]).unwrap()
    }

    /// A lone sphere's periodic self-mobility is Hasimoto's, whatever the splitting and size.
    /// The tolerance, 1e-10, is the sums' (1e-13) times the ~1e3 terms rounding adds up.
    #[test]
    fn lone_sphere_is_hasimoto() {
        let (mu, l) = (1e-3, 10e-6);
        for x in [0.02, 0.1, 0.2] {
            for xi in [0.5, 1.0, 3.0] {
                let a = x * l;
                let split = Some(xi * PI.sqrt() / l);
                let e = Ewald::new(cube(l), mu, Mobility::Rpy, 1, 1e-13, split).unwrap();
                let m = e.block(&Vector3::zeros(), a, a, true);
                let want = hasimoto(mu, a, l);
                for q in 0..3 {
                    let err = (m[(q, q)] / want - 1.0).abs();
                    assert!(err < 1e-10, "a/L {x}, xi L {xi}: relative error {err:e}");
                }
            }
        }
    }
}
