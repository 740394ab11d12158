//! A continuum's state: the distribution, its time, the stepper and what it was built with;
//! its plain reading (sizes, counts, means).

use super::operator::Kinetic;
use super::spec::{Closure, Population};
use crate::engine::error::{invalid, Result};
use crate::engine::integrators::{Dopri5, Stats};
use crate::engine::stepping::RunControl;
use crate::engine::swimmer::Dumbbell;
use std::f64::consts::PI;

/// A continuum: the distribution, its time, and the stepper. A clone is an independent copy (the
/// operator, which no run changes, shared).
#[derive(Clone)]
pub struct Continuum {
    pub(super) kinetic: Kinetic,
    pub(super) state: Vec<f64>,
    pub(super) time: f64,
    pub(super) stepper: Dopri5,
    pub(super) stats: Stats,
    pub(super) populations: Vec<Population>,
    pub(super) sides: [f64; 3],
    pub(super) grid: [usize; 3],
    pub(super) width: f64,
    pub(super) core: f64,
    pub(super) cutoff: f64,
    pub(super) period: f64,
    pub(super) tol: f64,
    /// The swimmer kind (phase aside).
    pub(super) kind: Dumbbell,
    /// The effective diffusion it was given, if any.
    pub(super) closure: Option<Closure>,
    /// What every run takes: the interrupt and the progress report (a scene's run control).
    pub(super) control: RunControl,
}

impl std::fmt::Debug for Continuum {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Continuum")
            .field("grid", &self.grid)
            .field("degree", &self.kinetic.op.sphere.degree())
            .field("populations", &self.populations)
            .field("time", &self.time)
            .finish()
    }
}

impl Continuum {
    /// The distribution's time (s).
    pub fn time(&self) -> f64 {
        self.time
    }
    /// The swimmers' stroke period (s).
    pub fn period(&self) -> f64 {
        self.period
    }
    /// Work counters of the time stepping.
    pub fn stats(&self) -> &Stats {
        &self.stats
    }
    /// The phase populations.
    pub fn populations(&self) -> &[Population] {
        &self.populations
    }
    /// Cells per axis.
    pub fn grid(&self) -> [usize; 3] {
        self.grid
    }
    /// The box's sides (m).
    pub fn sides(&self) -> [f64; 3] {
        self.sides
    }
    /// The harmonic degree L of the orientations.
    pub fn degree(&self) -> usize {
        self.kinetic.op.sphere.degree()
    }
    /// The core (m): no pair closer.
    pub fn core(&self) -> f64 {
        self.core
    }
    /// The cutoff (m): no pair further (the scene's, switched off smoothly as in the particle runs).
    pub fn cutoff(&self) -> f64 {
        self.cutoff
    }
    /// The time stepping's relative tolerance.
    pub fn tol(&self) -> f64 {
        self.tol
    }
    /// The effective diffusion it was given (a closure of the mean field), if any.
    pub fn closure(&self) -> Option<&Closure> {
        self.closure.as_ref()
    }
    /// The smoothing width the particles were deposited with (m).
    pub fn width(&self) -> f64 {
        self.width
    }
    /// Number of kernel components (terms of the folded pair kernel).
    pub fn kernel_terms(&self) -> usize {
        self.kinetic.op.comps.len()
    }

    /// The raw Galerkin state, [(p·B + i)·cells + cell].
    pub fn state(&self) -> &[f64] {
        &self.state
    }

    /// The number of swimmers of each population: ∫ ρ_p dx.
    pub fn counts(&self) -> Vec<f64> {
        let op = &self.kinetic.op;
        let b = op.sphere.len();
        let dv = self.sides.iter().product::<f64>() / op.cells as f64;
        (0..self.kinetic.pops)
            .map(|p| {
                let c0 = &self.state[p * b * op.cells..(p * b + 1) * op.cells];
                c0.iter().sum::<f64>() * (4.0 * PI).sqrt() * dv
            })
            .collect()
    }

    /// Refuse a population index `p` this continuum does not have.
    pub(super) fn check_population(&self, p: usize) -> Result<()> {
        let n = self.kinetic.pops;
        if p < n {
            return Ok(());
        }
        Err(invalid!(
            "population {p} does not exist: this continuum has {n} ({}), numbered from 0 in the order of its populations",
            if n == 1 { "0".to_string() } else { format!("0 to {}", n - 1) }
        ))
    }

    /// Each population's mean number density (1/m³).
    pub fn mean_densities(&self) -> Vec<f64> {
        let v: f64 = self.sides.iter().product();
        self.counts().iter().map(|c| c / v).collect()
    }

    /// The spatial mean of each population's Galerkin coefficients, [p·B + i].
    pub fn mean_coefficients(&self) -> Vec<f64> {
        let cells = self.kinetic.op.cells;
        self.state
            .chunks(cells)
            .map(|b| b.iter().sum::<f64>() / cells as f64)
            .collect()
    }
}
