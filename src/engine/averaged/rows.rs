//! The rows of the averaged sums: a pair's I, J, K, L terms, a swimmer's row over all partners
//! (in 3D, in vector lanes, or the 1D reduction), the steric rates, and every row of the
//! right-hand side (in parallel for large scenes).

use super::lanes;
use super::system::{AveragedSystem, LANE_SWIMMERS, PARALLEL_SWIMMERS};
use super::terms::pair_weight;
use crate::engine::mobility::self_mobility;
use crate::engine::model::{vec3, STATE_PER_SWIMMER};
use crate::engine::periodic::separation;
use nalgebra::Vector3;
use rayon::prelude::*;

impl AveragedSystem {
    /// The steric rates (dR_H/dt, dN/dt) of swimmer σ from the forces on its spheres.
    pub(super) fn steric_rates(&self, s: usize) -> (Vector3<f64>, Vector3<f64>) {
        let n = Vector3::new(self.soa.nx[s], self.soa.ny[s], self.soa.nz[s]);
        self.steric_rates_of(s, n, [self.steric_f[2 * s], self.steric_f[2 * s + 1]])
    }

    /// The rates (dR_H/dt, dN/dt) of swimmer σ with orientation `n` from forces `f` on its spheres:
    /// a free-draining rigid dumbbell (see [`AveragedSystem::set_contacts`]).
    pub(super) fn steric_rates_of(
        &self,
        s: usize,
        n: Vector3<f64>,
        f: [Vector3<f64>; 2],
    ) -> (Vector3<f64>, Vector3<f64>) {
        let a = [self.radii[2 * s], self.radii[2 * s + 1]];
        self.steric_rates_with(a, self.coef[s].ell, n, f)
    }

    /// [`AveragedSystem::steric_rates_of`] of a swimmer with sphere radii `a` and length `ell`.
    pub(super) fn steric_rates_with(
        &self,
        a: [f64; 2],
        ell: f64,
        n: Vector3<f64>,
        f: [Vector3<f64>; 2],
    ) -> (Vector3<f64>, Vector3<f64>) {
        let [f1, f2] = f;
        let [a1, a2] = a;
        let v = (f1 + f2) * self_mobility(self.mu, a1 + a2);
        let rel = (f2 * self_mobility(self.mu, a2) - f1 * self_mobility(self.mu, a1)) / ell;
        (v, rel - n * n.dot(&rel))
    }

    /// sin(φσ − φρ) if the pair interacts (it is not skipped as a zero-phase pair).
    #[inline]
    pub(super) fn pair_sin(&self, s: usize, r: usize) -> Option<f64> {
        pair_weight(&self.sin_phi, &self.cos_phi, self.skip_zero_phase, s, r)
    }

    /// dR_H/dt of swimmer σ and the torque-like sum T (dN/dt = −(1 − NNᵀ) T), from the arrays.
    pub(super) fn row(&self, s: usize) -> (Vector3<f64>, Vector3<f64>) {
        let soa = &self.soa;
        let ns = Vector3::new(soa.nx[s], soa.ny[s], soa.nz[s]);
        let mut v = Vector3::zeros();
        let mut t = Vector3::zeros();
        for r in 0..self.coef.len() {
            if let Some(sin) = self.pair_sin(s, r) {
                let dvec = separation(
                    self.periodic.as_ref(),
                    Vector3::new(
                        soa.x[s] - soa.x[r],
                        soa.y[s] - soa.y[r],
                        soa.z[s] - soa.z[r],
                    ),
                );
                let nr = Vector3::new(soa.nx[r], soa.ny[r], soa.nz[r]);
                self.add_pair_terms(s, ns, dvec, nr, sin, &mut v, &mut t);
            }
        }
        (v, t)
    }

    /// Add to swimmer σ's far-field sums (dR_H/dt `v`, torque-like `t`) one partner's terms, σ
    /// with orientation `ns`, the partner at separation `dvec` (σ's centre minus the partner's,
    /// the image met) with orientation `nr` and pair phase sine `sin`; none beyond the cutoff.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub(super) fn add_pair_terms(
        &self,
        s: usize,
        ns: Vector3<f64>,
        dvec: Vector3<f64>,
        nr: Vector3<f64>,
        sin: f64,
        v: &mut Vector3<f64>,
        t: &mut Vector3<f64>,
    ) {
        let c = &self.coef[s];
        let d2 = dvec.norm_squared();
        if d2 > self.cutoff2 {
            return;
        }
        let with_i = c.a_r != 0.0 || !self.skip_symmetric;
        let with_k = c.a_n != 0.0 || !self.skip_symmetric;
        let dist = d2.sqrt();
        let sin = sin * self.switch.at(dist);
        let dh = dvec / dist;
        let (ss, rr, q) = (dh.dot(&ns), dh.dot(&nr), ns.dot(&nr));
        let xi = c.ell / dist;
        let (xi3, xi4) = (xi.powi(3), xi.powi(4));
        // The bracket shared by J and K.
        let jk = 1.0 + 2.0 * q * q - 5.0 * ss * ss - 5.0 * rr * rr - 20.0 * q * ss * rr
            + 35.0 * ss * ss * rr * rr;
        *v += c.c_j
            * c.v0
            * sin
            * (9.0 / 64.0)
            * xi4
            * (ns * (2.0 * ss + 4.0 * q * rr - 10.0 * ss * rr * rr) + dh * jk);
        let l = c.w0
            * sin
            * (15.0 / 64.0)
            * c.big_l
            * xi4
            * xi
            * (3.0 * ss + 6.0 * rr * q + 6.0 * ss * q * q
                - 7.0 * ss.powi(3)
                - 21.0 * ss * rr * rr
                - 42.0 * q * ss * ss * rr
                + 63.0 * ss.powi(3) * rr * rr);
        let mut tr = dh * l;
        if with_i {
            let i_br =
                1.0 - 3.0 * rr * rr - 3.0 * ss * ss - 6.0 * q * ss * rr + 15.0 * ss * ss * rr * rr;
            *v += ns * (c.a_r * c.v0 * sin * (9.0 / 64.0) * c.big_l * xi3 * i_br);
        }
        if with_k {
            tr += dh * (c.a_n * c.w0 * sin * (9.0 / 32.0) * c.big_l * xi4 * jk);
        }
        *t += tr;
    }

    /// The 1D reduction: speed of swimmer σ along the axis (its centre coordinate in `soa.x`).
    pub(super) fn row_aligned(&self, s: usize) -> f64 {
        let c = &self.coef[s];
        let xs = self.soa.x[s];
        let n = self.soa.nx[s].signum();
        let mut v = 0.0;
        for r in 0..self.coef.len() {
            let Some(sin) = self.pair_sin(s, r) else {
                continue;
            };
            let d = xs - self.soa.x[r];
            if d * d > self.cutoff2 {
                continue;
            }
            let sin = sin * self.switch.at(d.abs());
            let xi = c.ell / d.abs();
            v += 9.0 / 16.0
                * c.v0
                * sin
                * (c.a_r * c.big_l * xi.powi(3) * n + c.c_j * xi.powi(4) * d.signum());
        }
        v
    }

    /// Whether the all-pairs rows run in vector lanes.
    pub(super) fn vector_rows(&self) -> bool {
        self.axis.is_none()
            && self.periodic.is_none()
            && self.lanes.unwrap_or(self.coef.len() >= LANE_SWIMMERS)
    }

    /// Swimmer σ's rates without neighbour lists, from the arrays filled from state `y`: the 1D
    /// reduction, or the all-pairs row (in vector lanes when `vector`), plus the steric rates.
    pub(super) fn row_rates(&self, s: usize, y: &[f64], vector: bool, out: &mut [f64]) {
        if let Some(axis) = self.axis {
            let v = self.row_aligned(s) * axis;
            out[..3].copy_from_slice(v.as_slice());
            out[3..6].fill(0.0);
            return;
        }
        let (v, t) = if vector {
            lanes::row(self, s)
        } else {
            self.row(s)
        };
        self.finish_rates(s, y, v, t, out);
    }

    /// The rates of swimmer σ from its far-field sums (dR_H/dt `v`, torque-like `t`): dN/dt =
    /// −(1 − NNᵀ)T, plus the steric rates.
    pub(super) fn finish_rates(
        &self,
        s: usize,
        y: &[f64],
        mut v: Vector3<f64>,
        t: Vector3<f64>,
        out: &mut [f64],
    ) {
        let n = vec3(y, STATE_PER_SWIMMER * s + 3);
        let mut dn = -(t - n * n.dot(&t));
        if self.contacts.steric.is_some() {
            let (vs, ns) = self.steric_rates(s);
            v += vs;
            dn += ns;
        }
        out[..3].copy_from_slice(v.as_slice());
        out[3..6].copy_from_slice(dn.as_slice());
    }

    /// Fill `dy` row by row (in parallel for large scenes).
    pub(super) fn rows_into(&self, y: &[f64], dy: &mut [f64]) {
        let vector = self.vector_rows();
        let one = |s: usize, out: &mut [f64]| self.row_rates(s, y, vector, out);
        if self.coef.len() >= PARALLEL_SWIMMERS {
            dy.par_chunks_mut(STATE_PER_SWIMMER)
                .enumerate()
                .for_each(|(s, out)| one(s, out));
        } else {
            dy.chunks_mut(STATE_PER_SWIMMER)
                .enumerate()
                .for_each(|(s, out)| one(s, out));
        }
    }
}
