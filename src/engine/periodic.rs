//! A periodic box centred on the origin (−L/2 … L/2 in each direction): minimum images and
//! wrapping.
//!
//! The engine integrates the swimmers' unwrapped motion (displacements and drifts stay continuous
//! across the box faces, as mean-square displacements need); every pair pass measures separations
//! by their minimum image, and what is shown (snapshots, trajectories, fields) is wrapped into the
//! box.

use super::error::{invalid, Result};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// A rectangular periodic box of sides `l` (m), centred on the origin.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PeriodicBox {
    l: [f64; 3],
}

impl PeriodicBox {
    /// A box of sides `l` (m): each positive and finite.
    pub fn new(l: [f64; 3]) -> Result<Self> {
        for (k, v) in ["x", "y", "z"].iter().zip(l) {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid!(
                    "the box side along {k} must be a positive length in m (e.g. 1e-3), got {v}; give three positive sides, or no box for open space"
                ));
            }
        }
        let volume = l[0] * l[1] * l[2];
        if !(volume.is_normal()) {
            return Err(invalid!(
                "a box of sides {:e}, {:e}, {:e} m has a volume f64 cannot hold ({volume:e} m^3); give sides nearer the swimmers' size",
                l[0],
                l[1],
                l[2]
            ));
        }
        Ok(PeriodicBox { l })
    }

    /// The sides (m).
    pub fn sides(&self) -> [f64; 3] {
        self.l
    }

    /// The shortest side (m).
    pub fn shortest(&self) -> f64 {
        self.l.iter().copied().fold(f64::INFINITY, f64::min)
    }

    /// The volume (m³).
    pub fn volume(&self) -> f64 {
        self.l[0] * self.l[1] * self.l[2]
    }

    /// The component `d` of a separation along axis `k`, moved to its nearest image
    /// (−L/2 ≤ d ≤ L/2).
    #[inline]
    pub fn image(&self, d: f64, k: usize) -> f64 {
        d - self.l[k] * nearest_integer(d / self.l[k])
    }

    /// The minimum image of separation `r`.
    #[inline]
    pub fn min_image(&self, r: Vector3<f64>) -> Vector3<f64> {
        Vector3::new(self.image(r.x, 0), self.image(r.y, 1), self.image(r.z, 2))
    }

    /// Position `p` wrapped into the box (−L/2 ≤ x < L/2).
    pub fn wrap(&self, p: Vector3<f64>) -> Vector3<f64> {
        let w = |x: f64, l: f64| {
            let y = x - l * ((x + 0.5 * l) / l).floor();
            // Rounding can land a point just below −L/2 on L/2 exactly: keep the half-open range.
            if y >= 0.5 * l {
                y - l
            } else {
                y
            }
        };
        Vector3::new(w(p.x, self.l[0]), w(p.y, self.l[1]), w(p.z, self.l[2]))
    }
}

impl PeriodicBox {
    /// The box's wave vectors k = 2π(n_x/L_x, n_y/L_y, n_z/L_z) ≠ 0 with |k| ≤ `k_max`, one of each
    /// ±k pair (n_x > 0, or n_x = 0 and n_y > 0, or n_x = n_y = 0 and n_z > 0), as (n, k).
    pub fn half_space_waves(&self, k_max: f64) -> Vec<([i64; 3], Vector3<f64>)> {
        let l = self.l;
        let m = self.wave_index_max(k_max).map(|n| n as i64);
        let mut waves = Vec::new();
        for i in 0..=m[0] {
            for j in -m[1]..=m[1] {
                for k in -m[2]..=m[2] {
                    if i == 0 && (j < 0 || (j == 0 && k <= 0)) {
                        continue;
                    }
                    let tau = 2.0 * std::f64::consts::PI;
                    let kv = Vector3::new(
                        tau * i as f64 / l[0],
                        tau * j as f64 / l[1],
                        tau * k as f64 / l[2],
                    );
                    if kv.norm() <= k_max {
                        waves.push(([i, j, k], kv));
                    }
                }
            }
        }
        waves
    }

    /// The largest |n_d| per axis among the waves with |k| ≤ `k_max`.
    pub fn wave_index_max(&self, k_max: f64) -> [usize; 3] {
        self.l.map(|side| {
            (k_max * side / (2.0 * std::f64::consts::PI))
                .floor()
                .max(0.0) as usize
        })
    }
}

/// x rounded to the nearest integer (ties to even) by the 1.5·2⁵² trick, for |x| < 2⁵¹: no library
/// call where the baseline x86-64 build has no rounding instruction.
#[inline]
pub fn nearest_integer(x: f64) -> f64 {
    const MAGIC: f64 = 6_755_399_441_055_744.0;
    if x.abs() < 2_251_799_813_685_248.0 {
        (x + MAGIC) - MAGIC
    } else {
        x.round()
    }
}

/// The plane-wave phases e^{ik·x} of points in a box, for the box's wave vectors
/// k = 2π(n_x/L_x, n_y/L_y, n_z/L_z) with |n_d| ≤ n_max[d]: per axis and point the powers
/// e^{i 2π m x_d/L_d}, m = 0 … n_max, so that a wave's phase is three complex products, with no
/// sine or cosine per wave and point (the Ewald sums' reciprocal part, the structure factor).
/// Each axis's table is m-major (all points for m = 0, then m = 1, …), so that one power of all
/// points is a contiguous row, as vector lanes read it.
#[derive(Debug, Clone)]
pub struct WavePhases {
    re: [Vec<f64>; 3],
    im: [Vec<f64>; 3],
    points: usize,
}

impl WavePhases {
    /// The tables of `points` in box `b` up to `n_max` per axis.
    pub fn new(b: &PeriodicBox, points: &[Vector3<f64>], n_max: [usize; 3]) -> Self {
        let count = points.len();
        let table = |d: usize| {
            let powers = n_max[d] + 1;
            let (mut re, mut im) = (vec![0.0; powers * count], vec![0.0; powers * count]);
            for (j, p) in points.iter().enumerate() {
                let (s1, c1) = (2.0 * std::f64::consts::PI * p[d] / b.l[d]).sin_cos();
                let (mut a, mut c) = (1.0, 0.0);
                for m in 0..powers {
                    re[m * count + j] = a;
                    im[m * count + j] = c;
                    (a, c) = (a * c1 - c * s1, a * s1 + c * c1);
                }
            }
            (re, im)
        };
        let (x, y, z) = (table(0), table(1), table(2));
        WavePhases {
            re: [x.0, y.0, z.0],
            im: [x.1, y.1, z.1],
            points: count,
        }
    }

    /// e^{i 2π m x_d/L_d} of every point along axis `d`, m ≤ n_max[d]: (re, im) rows.
    #[inline]
    pub fn row(&self, d: usize, m: usize) -> (&[f64], &[f64]) {
        let range = m * self.points..(m + 1) * self.points;
        (&self.re[d][range.clone()], &self.im[d][range])
    }

    /// e^{ik·x_j} for wave index `n` (|n_d| ≤ n_max[d]) as (re, im); a negative n_d conjugates.
    #[inline]
    pub fn at(&self, j: usize, n: [i64; 3]) -> (f64, f64) {
        let (mut re, mut im) = (1.0, 0.0);
        for (d, &nd) in n.iter().enumerate() {
            let k = nd.unsigned_abs() as usize * self.points + j;
            let (a, b) = (self.re[d][k], self.im[d][k]);
            let b = if nd < 0 { -b } else { b };
            (re, im) = (re * a - im * b, re * b + im * a);
        }
        (re, im)
    }
}

/// Separation `r` as the pair passes see it: its minimum image in a box, itself in open space.
#[inline]
pub fn separation(periodic: Option<&PeriodicBox>, r: Vector3<f64>) -> Vector3<f64> {
    match periodic {
        Some(b) => b.min_image(r),
        None => r,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn images_and_wrapping() {
        let b = PeriodicBox::new([2.0, 4.0, 8.0]).unwrap();
        let r = b.min_image(Vector3::new(1.5, -3.0, 9.0));
        assert_eq!(r, Vector3::new(-0.5, 1.0, 1.0));
        let w = b.wrap(Vector3::new(1.0, -2.0, 13.0));
        assert_eq!(w, Vector3::new(-1.0, -2.0, -3.0));
        assert!(PeriodicBox::new([1.0, 0.0, 1.0]).is_err());
        assert!(PeriodicBox::new([1.0, f64::NAN, 1.0]).is_err());
    }
}
