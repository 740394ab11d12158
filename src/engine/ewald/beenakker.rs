//! Beenakker's Ewald sums ([`Ewald`]): the splitting chosen for the work, the lattice shifts and
//! waves within the truncation, the matrix-free product, blocks and the dense matrix; Hasimoto's
//! self-mobility of a lone sphere in a cube.

use super::erfc::ErfcTable;
use super::method::{check_tol, EwaldMethod};
use super::real;
use super::reciprocal::{add_reciprocal, Wave};
use super::spectral::SpectralEwald;
use super::split::{truncation, Split};
use crate::engine::error::{invalid, unsupported, Result, Setting};
use crate::engine::mobility::{block_matrix, self_mobility, Blocks, Mobility, MobilityOperator};
use crate::engine::parallel::PARALLEL_IMAGE_SPHERES;
use crate::engine::periodic::PeriodicBox;
use nalgebra::{DMatrix, Matrix3, Vector3};
use rayon::prelude::*;
use std::f64::consts::{FRAC_2_SQRT_PI, PI};

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
    /// erfc and e^{−x²} of the real-space lanes.
    erfc: ErfcTable,
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
                // Measured costs per term, in units of one wave per sphere (its phase, the
                // structure factors and the velocity, in vector lanes): with r_c ≤ L/2 a
                // candidate of the cell lists (every sphere in the cells around one, in lanes)
                // ~3; else an image within r_c (erfc and exp from the table) ~10 and a lattice
                // shift tested per pair ~0.4.
                let cost = |xi: f64| {
                    let (im, wv) = counts(xi);
                    let rc = p / xi;
                    let real = if real::fits(&periodic, rc) {
                        let frac: f64 = l
                            .iter()
                            .map(|side| {
                                let cells = (side / rc).floor().max(1.0);
                                cells.min(3.0) / cells
                            })
                            .product();
                        n * n * 3.0 * frac
                    } else {
                        // Below PARALLEL_IMAGE_SPHERES each pair is evaluated once for both
                        // spheres, at half the cost.
                        let per_pair = if spheres < PARALLEL_IMAGE_SPHERES { 0.5 } else { 1.0 };
                        n * n * per_pair * (10.0 * im + 0.4 * 27.0f64.max(8.0 * im))
                    };
                    real + n * wv
                };
                (0..=120)
                    .map(|i| 0.5 * 10f64.powf(i as f64 / 40.0) / lmin)
                    .min_by(|a, b| cost(*a).total_cmp(&cost(*b)))
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
            erfc: ErfcTable::default(),
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
            let d = r2.sqrt();
            let (erfc, gauss) = self.erfc.eval(self.split.xi * d);
            let (ci, crr) =
                self.split
                    .real_with(d, 1.0 / d, s, erfc, gauss * (0.5 * FRAC_2_SQRT_PI));
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
        out.iter_mut().for_each(|u| *u = Vector3::zeros());
        add_reciprocal(
            &self.periodic,
            &self.waves,
            self.n_max,
            self.split.finite_size,
            pos,
            radii,
            forces,
            out,
            parallel,
        );
        if real::fits(&self.periodic, self.rc) {
            real::add_real(
                &self.split,
                &self.periodic,
                self.rc,
                &self.erfc,
                pos,
                radii,
                forces,
                out,
                parallel,
            );
        } else if !parallel {
            // Each pair once: its images' terms depend on r only through r r^T and |r|, the same
            // for r and −r, so one evaluation serves both spheres.
            for i in 0..n {
                let mut v = self.split.self_excess(radii[i]) * forces[i]
                    + self.real_apply(
                        &Vector3::zeros(),
                        self.split.s(radii[i], radii[i]),
                        &forces[i],
                    );
                for j in i + 1..n {
                    let r0 = self.periodic.min_image(pos[i] - pos[j]);
                    let (fi, fj) = (forces[i], forces[j]);
                    let mut w = Vector3::zeros();
                    self.real_images(&r0, self.split.s(radii[i], radii[j]), |r, r2, ci, crr| {
                        v += ci * fj + r * (crr * r.dot(&fj) / r2);
                        w += ci * fi + r * (crr * r.dot(&fi) / r2);
                    });
                    v += self.split.overlap_apply(&r0, radii[i], radii[j], &fj) / unit;
                    w += self.split.overlap_apply(&-r0, radii[j], radii[i], &fi) / unit;
                    out[j] += w;
                }
                out[i] += v;
            }
        } else {
            let row = |i: usize, u: &mut Vector3<f64>| {
                let mut v = self.split.self_excess(radii[i]) * forces[i];
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
                *u += v;
            };
            // Many spheres: a row per sphere, the rows in parallel.
            out.par_iter_mut().enumerate().for_each(|(i, u)| row(i, u));
        }
        out.iter_mut().for_each(|u| *u *= unit);
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
        block_matrix(pos.len(), Blocks::Upper, |a, b| {
            let r0 = self.periodic.min_image(pos[a] - pos[b]);
            self.block(&r0, radii[a], radii[b], a == b)
        })
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
