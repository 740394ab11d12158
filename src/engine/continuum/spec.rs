//! How a continuum is built from a scene: the spec and its checks, the phase populations, and
//! the particles deposited on the grid.

use super::operator::Operator;
use super::sphere::MAX_DEGREE;
use super::Population;
use crate::engine::error::{invalid, Result};
use crate::engine::fields::gaussian_axis;
use std::f64::consts::PI;

/// The most grid cells a continuum takes (its kernel then holds some 600 transforms of 32³).
pub const MAX_CELLS: usize = 1 << 15;

/// The most phase populations a continuum tracks.
pub const MAX_POPULATIONS: usize = 16;

/// Phases closer than this (rad) are one population.
pub(super) const SAME_PHASE: f64 = 1e-9;

/// How a continuum is built from a scene.
#[derive(Debug, Clone, PartialEq)]
pub struct ContinuumSpec {
    /// Cells per axis.
    pub grid: [usize; 3],
    /// Harmonic degree L of the orientations.
    pub degree: usize,
    /// No pair closer than this (m); `None`: one swimmer length ℓ.
    pub core: Option<f64>,
    /// Width of the Gaussian that smooths the particles (m); `None`: the largest cell side.
    pub width: Option<f64>,
    /// Bin the phases into this many populations; `None`: one population per distinct phase.
    pub phase_bins: Option<usize>,
    /// Relative tolerance of the time stepping, against the structure.
    pub tol: f64,
}

impl Default for ContinuumSpec {
    fn default() -> Self {
        ContinuumSpec {
            grid: [16, 16, 16],
            degree: 4,
            core: None,
            width: None,
            phase_bins: None,
            tol: 1e-6,
        }
    }
}

pub(super) fn check_spec(spec: &ContinuumSpec) -> Result<()> {
    let cells: usize = spec.grid.iter().product();
    if spec.grid.iter().any(|&n| n < 4) || cells > MAX_CELLS {
        return Err(invalid!(
            "a continuum's grid needs 4 or more cells per axis and at most {MAX_CELLS} cells in all, got {:?}; e.g. grid: [16, 16, 16]",
            spec.grid
        ));
    }
    if spec.degree < 2 || spec.degree > MAX_DEGREE {
        return Err(invalid!(
            "a continuum's orientations go to harmonic degree 2 to {MAX_DEGREE} (the mean field needs 2), got {}; e.g. orientations: 4",
            spec.degree
        ));
    }
    if let Some(w) = spec.width {
        if !(w.is_finite() && w > 0.0) {
            return Err(invalid!(
                "a continuum's smoothing width must be a positive length in m, got {w}"
            ));
        }
    }
    if !(spec.tol.is_finite() && spec.tol > 0.0 && spec.tol < 1.0) {
        return Err(invalid!(
            "a continuum's tolerance must lie between 0 and 1, got {}; e.g. tol: 1e-6",
            spec.tol
        ));
    }
    if let Some(b) = spec.phase_bins {
        if b == 0 || b > MAX_POPULATIONS {
            return Err(invalid!(
                "phase bins must be 1 to {MAX_POPULATIONS}, got {b}"
            ));
        }
    }
    Ok(())
}

/// The phase populations of swimmers with phases `phases` (one per distinct phase, or `bins`
/// equal bins over [0, 2π) at their centres, the empty left out), and each swimmer's population.
pub(super) fn populations(
    phases: &[f64],
    bins: Option<usize>,
) -> Result<(Vec<Population>, Vec<usize>)> {
    let wrapped: Vec<f64> = phases.iter().map(|p| p.rem_euclid(2.0 * PI)).collect();
    let mut pops: Vec<Population> = Vec::new();
    let mut member = Vec::with_capacity(phases.len());
    for &p in &wrapped {
        let phase = match bins {
            Some(b) => {
                let w = 2.0 * PI / b as f64;
                ((p / w).floor().min(b as f64 - 1.0) + 0.5) * w
            }
            None => p,
        };
        let close = |q: f64| {
            let d = (phase - q).rem_euclid(2.0 * PI);
            d.min(2.0 * PI - d) < SAME_PHASE
        };
        match pops.iter().position(|x| close(x.phase)) {
            Some(i) => {
                pops[i].swimmers += 1;
                member.push(i);
            }
            None => {
                if pops.len() == MAX_POPULATIONS {
                    return Err(invalid!(
                        "the swimmers have more than {MAX_POPULATIONS} distinct phases; bin them into at most {MAX_POPULATIONS} populations (the continuum's phases option)"
                    ));
                }
                member.push(pops.len());
                pops.push(Population { phase, swimmers: 1 });
            }
        }
    }
    Ok((pops, member))
}

/// Spread every swimmer over the grid (the Gaussian of `scene.field`) into its population's
/// coefficients: c_{p,i}(x) = Σ_{σ∈p} Y_i(N_σ) K_σ(x), the projection of the particles' smoothed
/// distribution on the basis.
#[allow(clippy::too_many_arguments)]
pub(super) fn deposit(
    op: &Operator,
    grid: [usize; 3],
    sides: [f64; 3],
    width: f64,
    centres: &[nalgebra::Vector3<f64>],
    dirs: &[nalgebra::Vector3<f64>],
    member: &[usize],
    state: &mut [f64],
) {
    let h: [f64; 3] = std::array::from_fn(|d| sides[d] / grid[d] as f64);
    let origin: [f64; 3] = std::array::from_fn(|d| -0.5 * sides[d] + 0.5 * h[d]);
    let dv = h[0] * h[1] * h[2];
    let b = op.sphere.len();
    let cells = op.cells;
    for ((c, dir), &p) in centres.iter().zip(dirs).zip(member) {
        let axes: [Vec<(usize, f64)>; 3] = std::array::from_fn(|d| {
            gaussian_axis(c[d], h[d], origin[d], width, grid[d], Some(sides[d]))
        });
        let total: f64 = axes
            .iter()
            .map(|a| a.iter().map(|x| x.1).sum::<f64>())
            .product();
        let y = op.sphere.basis_at(&[dir.x, dir.y, dir.z]);
        for &(k, fz) in &axes[2] {
            for &(j, fy) in &axes[1] {
                for &(i, fx) in &axes[0] {
                    let cell = i + grid[0] * (j + grid[1] * k);
                    let w = fx * fy * fz / (total * dv);
                    for (bi, yi) in y.iter().enumerate() {
                        state[(p * b + bi) * cells + cell] += w * yi;
                    }
                }
            }
        }
    }
}
