//! The structure factor S(k) of the swimmers' hydrodynamic centres in a periodic box, binned by
//! |k|: the particles' side of the density fluctuations the fields smooth.

use super::error::{invalid, Result};
use super::periodic::WavePhases;
use super::scene::Scene;
use nalgebra::Vector3;
use rayon::prelude::*;
use std::f64::consts::PI;

/// The most centre-wave products one structure factor may take (a few seconds of work).
pub const MAX_WAVE_PRODUCTS: f64 = 2e9;

/// The most wave vectors a structure factor sums over per axis (|n| ≤ this).
pub const MAX_WAVE_INDEX: usize = 40;

/// The structure factor of the hydrodynamic centres in the scene's periodic box, binned by |k|.
#[derive(Debug, Clone, PartialEq)]
pub struct StructureFactor {
    /// Mean |k| of each non-empty bin (1/m).
    pub k: Vec<f64>,
    /// Mean S(k) = |Σ_σ e^{ik·R_σ}|²/N over the bin's wave vectors.
    pub s: Vec<f64>,
    /// Wave vectors in each bin (each ±k pair once).
    pub count: Vec<usize>,
}

/// S(k) = |Σ_σ e^{ik·R_H^σ}|²/N over the box's wave vectors 0 < |k| ≤ `k_max` (1/m; default
/// 1.5·2π over the mean spacing (V/N)^{1/3}, at most [`MAX_WAVE_INDEX`] waves per axis), averaged
/// in `bins` bins of equal width in |k| from 0 to k_max. Box only.
pub fn structure_factor(scene: &Scene, bins: usize, k_max: Option<f64>) -> Result<StructureFactor> {
    let Some(b) = scene.periodic() else {
        return Err(invalid!(
            "the structure factor needs a periodic box (its wave vectors are the box's); put the scene in a box of sides [Lx, Ly, Lz] first"
        ));
    };
    if !(1..=10_000).contains(&bins) {
        return Err(invalid!(
            "the structure factor takes 1 to 10000 bins, got {bins}; e.g. 32"
        ));
    }
    let n = scene.count();
    if n == 0 {
        return Err(invalid!(
            "the scene has no swimmers, so no structure factor; add some first"
        ));
    }
    let l = b.sides();
    let spacing = (b.volume() / n as f64).cbrt();
    let limit = 2.0 * PI * MAX_WAVE_INDEX as f64 / l[0].max(l[1]).max(l[2]);
    let k_max = match k_max {
        Some(k) if k.is_finite() && k > 0.0 => {
            let top = b.wave_index_max(k).into_iter().max().unwrap_or(0);
            if top > MAX_WAVE_INDEX {
                return Err(invalid!(
                    "k_max = {k:e} 1/m needs {top} waves per axis in this box, more than {MAX_WAVE_INDEX}; use k_max up to {limit:e} 1/m"
                ));
            }
            k
        }
        Some(k) => {
            return Err(invalid!(
                "k_max must be a positive wave number in 1/m, got {k}"
            ))
        }
        None => (1.5 * 2.0 * PI / spacing).min(limit),
    };
    let waves: Vec<([i64; 3], f64)> = b
        .half_space_waves(k_max)
        .into_iter()
        .map(|(idx, k)| (idx, k.norm()))
        .collect();
    if waves.len() as f64 * n as f64 > MAX_WAVE_PRODUCTS {
        return Err(invalid!(
            "the structure factor of {n} centres over {} wave vectors is {:.1e} products (more than {MAX_WAVE_PRODUCTS:e}, minutes of work); use a smaller k_max",
            waves.len(),
            waves.len() as f64 * n as f64
        ));
    }
    let centres: Vec<Vector3<f64>> = (0..n).map(|i| scene.center(i)).collect::<Result<_>>()?;
    let phases = WavePhases::new(b, &centres, b.wave_index_max(k_max));
    let s_of = |&(idx, _): &([i64; 3], f64)| {
        let (mut sr, mut si) = (0.0, 0.0);
        for p in 0..n {
            let (re, im) = phases.at(p, idx);
            sr += re;
            si += im;
        }
        (sr * sr + si * si) / n as f64
    };
    let values: Vec<f64> = waves.par_iter().map(s_of).collect();
    let (mut ks, mut ss, mut counts) = (vec![0.0; bins], vec![0.0; bins], vec![0usize; bins]);
    for ((_, k), s) in waves.iter().zip(values) {
        let bin = ((k / k_max * bins as f64) as usize).min(bins - 1);
        ks[bin] += k;
        ss[bin] += s;
        counts[bin] += 1;
    }
    let mut out = StructureFactor {
        k: Vec::new(),
        s: Vec::new(),
        count: Vec::new(),
    };
    for ((k, s), c) in ks.into_iter().zip(ss).zip(counts) {
        if c > 0 {
            out.k.push(k / c as f64);
            out.s.push(s / c as f64);
            out.count.push(c);
        }
    }
    Ok(out)
}
