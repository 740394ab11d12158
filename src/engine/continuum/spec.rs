//! How a continuum is built from a scene: the spec and its checks, the phase populations, and
//! the particles deposited on the grid.

use super::operator::Operator;
use super::sphere::MAX_DEGREE;
use crate::engine::error::{invalid, short, Result};
use crate::engine::fields::gaussian_axis;
use crate::engine::integrators::{check_tolerance, MIN_DRIFT_TOL};
use crate::engine::swimmer::Dumbbell;
use std::f64::consts::PI;

/// The most grid cells a continuum takes (its kernel then holds some 600 transforms of 32³).
pub const MAX_CELLS: usize = 1 << 15;

/// The most phase populations a continuum tracks.
pub const MAX_POPULATIONS: usize = 16;

/// One phase population.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Population {
    /// Its phase φ (rad, in [0, 2π)).
    pub phase: f64,
    /// How many swimmers of the scene it was built from.
    pub swimmers: usize,
}

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
    /// An effective diffusion added to the thermal one: the fluctuations and correlations of a
    /// suspension that the mean field leaves out, measured from particle runs.
    pub closure: Option<Closure>,
}

/// A closure of the mean field: an effective rotational and translational diffusion of each
/// swimmer, measured from particle runs, and where it was measured (fitted on one set of runs,
/// it is held against others).
#[derive(Debug, Clone, PartialEq)]
pub struct Closure {
    /// D_r (1/s).
    pub rotation: f64,
    /// D_t, isotropic (m²/s).
    pub translation: f64,
    /// Where it was fitted, in words ("averaged model, phi = 1%, 8 seeds of 64 swimmers").
    pub fitted: String,
}

impl Closure {
    /// A closure of rotational diffusion `rotation` (1/s) and translational `translation`
    /// (m²/s), fitted where `fitted` says.
    pub fn new(rotation: f64, translation: f64, fitted: &str) -> Result<Closure> {
        for (name, v, unit) in [
            ("rotation", rotation, "1/s"),
            ("translation", translation, "m²/s"),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(invalid!(
                    "the closure's {name} must be a diffusion coefficient of zero or more ({unit}), got {v}"
                ));
            }
        }
        if fitted.trim().is_empty() {
            return Err(invalid!(
                "a closure says where it was fitted: give fitted: \"...\" (the model, density and runs it was measured on)"
            ));
        }
        Ok(Closure {
            rotation,
            translation,
            fitted: fitted.to_string(),
        })
    }
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
            closure: None,
        }
    }
}

/// The least cells per axis of a continuum's grid (the 2/3 rule then keeps modes −1 to 1).
pub const MIN_CELLS_PER_AXIS: usize = 4;

/// The least harmonic degree of the orientations: the mean field reads second moments.
pub const MIN_DEGREE: usize = 2;

/// The least tolerance of a continuum's time stepping.
pub const MIN_TOL: f64 = MIN_DRIFT_TOL;

/// The least core, in swimmer lengths ℓ: the pair terms are the leading terms of an expansion in
/// ℓ/D for swimmers far apart, so they describe pairs about a length apart or more; at ℓ/4 their
/// (ℓ/D)⁵ term is already 4⁵ ≈ 1000 times its size at one length. (The cost does not follow the
/// core: the kernel's radial panels grow with log(cutoff/core), and its transform at the kept
/// waves depends on the core only logarithmically.)
pub const MIN_CORE_IN_LENGTHS: f64 = 0.25;

/// The whole-number options of a continuum: the values each accepts, in words, so that the spec's
/// refusals and a front end's (a value that is no whole number at all) say the same.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WholeOption {
    /// Cells per axis.
    Grid,
    /// The harmonic degree of the orientations.
    Degree,
    /// Phase bins.
    PhaseBins,
}

impl WholeOption {
    /// What the option accepts.
    pub fn accepts(self) -> String {
        match self {
            WholeOption::Grid => format!(
                "{MIN_CELLS_PER_AXIS} or more cells per axis and at most {MAX_CELLS} cells in all (e.g. 16 per axis)"
            ),
            WholeOption::Degree => format!(
                "a harmonic degree from {MIN_DEGREE} (the mean field reads second moments) to {MAX_DEGREE} (e.g. 4)"
            ),
            WholeOption::PhaseBins => format!("1 to {MAX_POPULATIONS} phase bins"),
        }
    }
}

/// The core and the smoothing width a spec gives (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Lengths {
    pub(super) core: f64,
    pub(super) width: f64,
}

impl ContinuumSpec {
    /// Every option checked in one place, the lengths against what the box (`sides`, m), the
    /// scene's `cutoff` (m) and the swimmer `kind` allow; the core and width it gives.
    pub(super) fn check(&self, sides: [f64; 3], cutoff: f64, kind: &Dumbbell) -> Result<Lengths> {
        let cells = self
            .grid
            .iter()
            .try_fold(1usize, |acc, &n| acc.checked_mul(n));
        if self.grid.iter().any(|&n| n < MIN_CELLS_PER_AXIS) || cells.is_none_or(|c| c > MAX_CELLS)
        {
            return Err(invalid!(
                "a continuum's grid takes {}, got {:?}",
                WholeOption::Grid.accepts(),
                self.grid
            ));
        }
        if !(MIN_DEGREE..=MAX_DEGREE).contains(&self.degree) {
            return Err(invalid!(
                "a continuum's orientations take {}, got {}",
                WholeOption::Degree.accepts(),
                self.degree
            ));
        }
        if let Some(b) = self.phase_bins {
            if !(1..=MAX_POPULATIONS).contains(&b) {
                return Err(invalid!(
                    "a continuum's phases take {}, got {b}",
                    WholeOption::PhaseBins.accepts()
                ));
            }
        }
        check_tolerance(
            "a continuum's tolerance",
            self.tol,
            MIN_TOL,
            "the error asked of a structure of 1e-6 of the density is under f64's round-off of the density",
        )?;
        let cell = (0..3)
            .map(|d| sides[d] / self.grid[d] as f64)
            .fold(0.0, f64::max);
        let longest = sides.iter().copied().fold(0.0, f64::max);
        let width = self.width.unwrap_or(cell);
        let (narrowest, widest) = (0.25 * cell, 0.5 * longest);
        if !(narrowest..=widest).contains(&width) {
            return Err(invalid!(
                "a continuum's smoothing width must lie from a quarter of its largest cell side, {narrowest:e} m (narrower, the Gaussian falls between the cell centres: each swimmer lands in one cell, and far narrower its weights underflow to nothing), to half the box's longest side, {widest:e} m (wider, it spreads every swimmer evenly over the box), got {width:e} m; leave it out for one cell, {cell:e} m"
            ));
        }
        let ell = kind.ell;
        let core = self.core.unwrap_or(ell);
        let least = MIN_CORE_IN_LENGTHS * ell;
        if !(core >= least && core < cutoff) {
            return Err(invalid!(
                "a continuum's core must lie from {MIN_CORE_IN_LENGTHS} swimmer lengths, {least:e} m, up to the cutoff {} m (not included), got {core:e} m: the pair terms are the leading terms of an expansion in ℓ/D for swimmers far apart, and closer than ℓ/4, where their (ℓ/D)⁵ term is 1000 times its size at one length, they describe no pair the particles have; leave it out for one length ℓ, {ell:e} m",
                short(cutoff)
            ));
        }
        Ok(Lengths { core, width })
    }
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

/// The swimmers a continuum's state is deposited from: centres (shown in the box), orientations,
/// and the population of each.
pub(super) struct Particles<'a> {
    pub(super) centres: &'a [nalgebra::Vector3<f64>],
    pub(super) dirs: &'a [nalgebra::Vector3<f64>],
    pub(super) member: &'a [usize],
}

/// Spread every swimmer over the grid (the Gaussian of `scene.field`) into its population's
/// coefficients: c_{p,i}(x) = Σ_{σ∈p} Y_i(N_σ) K_σ(x), the projection of the particles' smoothed
/// distribution on the basis.
pub(super) fn deposit(
    op: &Operator,
    grid: [usize; 3],
    sides: [f64; 3],
    width: f64,
    particles: &Particles,
    state: &mut [f64],
) {
    let Particles {
        centres,
        dirs,
        member,
    } = particles;
    let h: [f64; 3] = std::array::from_fn(|d| sides[d] / grid[d] as f64);
    let origin: [f64; 3] = std::array::from_fn(|d| -0.5 * sides[d] + 0.5 * h[d]);
    let dv = h[0] * h[1] * h[2];
    let b = op.sphere.len();
    let cells = op.cells;
    for ((c, dir), &p) in centres.iter().zip(dirs.iter()).zip(member.iter()) {
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
