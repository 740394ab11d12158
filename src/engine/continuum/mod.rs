//! The kinetic theory of the averaged model: the one-swimmer distribution f_p(x, n, t) of each
//! phase population p in a periodic box, moved by the mean field of the averaged pair terms and
//! by the thermal model's diffusion, solved pseudo-spectrally.
//!
//! ∂_t f_p = −∇·(v_p f_p) − ∇_n·(ṅ_p f_p) + ∇·(D(n)·∇f_p) + D_r ∇_n² f_p,
//!
//! v_p(x, n) = Σ_q sin(φ_p − φ_q) ∫∫ H(|D|) V(D, n, n') f_q(x − D, n') dD dn', likewise ṅ_p with
//! −(1 − nn)T: the pair terms summed over the distribution instead of over particles ([`kernel`]).
//! The pair terms depend on the partner's orientation only through n'n', so the mean field needs
//! only the second moments of f_q; and each carries sin(φ_p − φ_q), so one population alone, or
//! phases spread uniformly (Σ_q sin(φ_p − φ_q) f_q = 0), has no mean-field motion at all.
//!
//! Orientations: Galerkin in the real spherical harmonics to degree L ([`sphere`]), the
//! integrals by a product rule exact for them (no aliasing in n). Space: the box's grid, fields
//! transformed by FFT, the convolution with the kernel's exact transform at each wave vector,
//! products at the grid points, and the 2/3 rule against aliasing. Time: Dormand-Prince 5(4) with
//! error control relative to the structure (the state's deviation from its spatial mean).

pub mod kernel;
pub mod sphere;
mod stability;

pub use stability::{BaseState, Mode};

use self::kernel::{Component, Constants, Radial};
use self::sphere::{monomial, monomials, Sphere, MAX_DEGREE};
use super::averaged::pair_constants;
use super::build::place_apart;
use super::error::{invalid, Result};
use super::fft3::{signed_mode, Fft3};
use super::fields::{gaussian_axis, Field, FieldKind};
use super::integrators::{Dopri5, OdeSystem, Problem, Stats, Stepper};
use super::scene::Scene;
use super::swimmer::Dumbbell;
use super::thermal::RigidDiffusion;
use rayon::prelude::*;
use rustfft::num_complex::Complex64;
use std::f64::consts::PI;

/// The most grid cells a continuum takes (its kernel then holds some 600 transforms of 32³).
pub const MAX_CELLS: usize = 1 << 15;

/// The most phase populations a continuum tracks.
pub const MAX_POPULATIONS: usize = 16;

/// Phases closer than this (rad) are one population.
const SAME_PHASE: f64 = 1e-9;

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

/// One phase population.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Population {
    /// Its phase φ (rad, in [0, 2π)).
    pub phase: f64,
    /// How many swimmers of the scene it was built from.
    pub swimmers: usize,
}

/// The mean-field operator's parts that do not change in a run.
struct Operator {
    sphere: Sphere,
    /// The kernel's components, and their transforms: [component][k], k in the transform's
    /// layout (z fastest); K̂ = value, times i for m = 4.
    comps: Vec<Component>,
    kernel: Vec<Vec<f64>>,
    /// Components grouped by (output, target monomial): (output, monomial values at the nodes,
    /// component indices).
    groups: Vec<(usize, Vec<f64>, Vec<usize>)>,
    /// ∫ n^β Y_i dΩ for the six second moments β, at [β][i].
    second: Vec<Vec<f64>>,
    /// ∫ n_a Y_i dΩ, at [a][i].
    first: Vec<Vec<f64>>,
    /// Wave vectors (1/m) in the transform's layout, and whether each survives the 2/3 rule.
    waves: Vec<[f64; 3]>,
    keep: Vec<bool>,
    /// sin(φ_p − φ_q) at [p][q].
    sin: Vec<Vec<f64>>,
    diffusion: Option<RigidDiffusion>,
    /// ∫ Y_i n_a n_b Y_j dΩ for the anisotropic translational diffusion (with noise), at
    /// [ab][i·B + j], ab over xx, xy, xz, yy, yz, zz.
    nn: Vec<Vec<f64>>,
    fft: Fft3,
    cells: usize,
    /// The core and cutoff (m) of the kernel.
    core: f64,
    cutoff: f64,
}

/// The distribution's ODE: state y[(p·B + i)·cells + cell] = c_{p,i}(x_cell), f_p = Σ_i c_{p,i} Y_i.
struct Kinetic {
    op: Operator,
    pops: usize,
}

/// A continuum: the distribution, its time, and the stepper.
pub struct Continuum {
    kinetic: Kinetic,
    state: Vec<f64>,
    time: f64,
    stepper: Dopri5,
    stats: Stats,
    populations: Vec<Population>,
    sides: [f64; 3],
    grid: [usize; 3],
    width: f64,
    core: f64,
    cutoff: f64,
    period: f64,
    tol: f64,
    /// The swimmer kind (phase aside).
    kind: Dumbbell,
    interrupt: Option<super::integrators::Interrupt>,
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
    /// The continuum of `scene`'s swimmers: their smoothed distribution in the scene's box, with
    /// the scene's coefficients, cutoff and temperature.
    pub fn of(scene: &Scene, spec: &ContinuumSpec) -> Result<Continuum> {
        let Some(b) = scene.periodic() else {
            return Err(invalid!(
                "a continuum lives in a periodic box and this scene has none; give the scene a box first"
            ));
        };
        let sides = b.sides();
        if scene.count() == 0 {
            return Err(invalid!(
                "the scene has no swimmers to build a continuum from; add some first"
            ));
        }
        check_spec(spec)?;
        let first = scene.swimmers()[0];
        for (i, d) in scene.swimmers().iter().enumerate() {
            let same = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs());
            if !(same(d.a1, first.a1)
                && same(d.a2, first.a2)
                && same(d.ell, first.ell)
                && same(d.lambda, first.lambda)
                && same(d.omega, first.omega))
            {
                return Err(invalid!(
                    "swimmer {i} differs from swimmer 0 in its radii, length, amplitude or omega; a continuum takes one kind of swimmer (its populations differ in phase only): build it from a scene of one kind"
                ));
            }
        }
        let core = spec.core.unwrap_or(first.ell);
        let cutoff = scene.averaged_cutoff()?.expect("a box always has a cutoff");
        if !(core.is_finite() && core > 0.0 && core < cutoff) {
            return Err(invalid!(
                "the continuum's core {core:e} m must be positive and shorter than the cutoff {cutoff:e} m; e.g. core: 5e-6 (one length ℓ)"
            ));
        }
        let (pops, member) = populations(&scene.phases(), spec.phase_bins)?;
        let c = pair_constants(&first, scene.coefficients());
        let constants = Constants {
            a_r: c[0],
            c_j: c[1],
            a_n: c[2],
            v0: c[3],
            w0: c[4],
            big_l: c[5],
            ell: c[6],
        };
        let thermal = scene.thermal();
        let diffusion = if thermal.is_on() {
            Some(RigidDiffusion::new(
                &first,
                first.ell,
                scene.mu(),
                scene.mobility(),
                thermal.kt(),
            )?)
        } else {
            None
        };
        let phases: Vec<f64> = pops.iter().map(|p| p.phase).collect();
        let op = Operator::new(
            spec.grid,
            sides,
            spec.degree,
            &constants,
            core,
            cutoff,
            &phases,
            diffusion,
        );
        let h: [f64; 3] = std::array::from_fn(|d| sides[d] / spec.grid[d] as f64);
        let width = spec.width.unwrap_or(h[0].max(h[1]).max(h[2]));
        let mut state = vec![0.0; pops.len() * op.sphere.len() * op.cells];
        let centres: Vec<_> = (0..scene.count())
            .map(|i| scene.center(i).map(|c| scene.shown(c)))
            .collect::<Result<_>>()?;
        let dirs: Vec<_> = (0..scene.count())
            .map(|i| scene.dir(i))
            .collect::<Result<_>>()?;
        deposit(
            &op, spec.grid, sides, width, &centres, &dirs, &member, &mut state,
        );
        let kinetic = Kinetic {
            pops: pops.len(),
            op,
        };
        let mut c = Continuum {
            kinetic,
            state,
            time: scene.time(),
            stepper: Dopri5::new(spec.tol),
            stats: Stats::default(),
            populations: pops,
            sides,
            grid: spec.grid,
            width,
            core,
            cutoff,
            period: first.period(),
            tol: spec.tol,
            kind: first,
            interrupt: None,
        };
        c.filter_state();
        Ok(c)
    }

    /// Keep only the modes the 2/3 rule keeps (the state then stays in that space).
    fn filter_state(&mut self) {
        let op = &self.kinetic.op;
        let mut buf = vec![Complex64::default(); op.cells];
        let mut spare = buf.clone();
        let inv = 1.0 / op.cells as f64;
        for block in self.state.chunks_mut(op.cells) {
            for (b, v) in buf.iter_mut().zip(block.iter()) {
                *b = Complex64::new(*v, 0.0);
            }
            op.fft.forward(&mut buf, &mut spare);
            for (b, k) in buf.iter_mut().zip(&op.keep) {
                if !k {
                    *b = Complex64::default();
                }
            }
            op.fft.inverse(&mut buf, &mut spare);
            for (v, b) in block.iter_mut().zip(&buf) {
                *v = b.re * inv;
            }
        }
    }

    /// Ask `interrupt` between steps: when it answers true the run stops there, state kept.
    pub fn set_interrupt(&mut self, interrupt: Option<super::integrators::Interrupt>) {
        self.interrupt = interrupt;
    }

    /// Advance by `seconds`. On an error the state is the last accepted one.
    pub fn run(&mut self, seconds: f64) -> Result<()> {
        if !(seconds.is_finite() && seconds >= 0.0) {
            return Err(invalid!(
                "a continuum runs for a finite time of 0 s or more, got {seconds}"
            ));
        }
        let end = self.time + seconds;
        while self.time < end {
            if self.interrupt.as_ref().is_some_and(|stop| stop()) {
                return Err(super::error::EngineError::Interrupted { time: self.time });
            }
            match self.stepper.step(
                &mut self.kinetic,
                self.time,
                &mut self.state,
                end,
                &mut self.stats,
            ) {
                Ok(t) => self.time = t,
                Err(e) => {
                    return Err(invalid!(
                        "the continuum's time stepping failed at t = {:e} s: {}; a finer tolerance or a smaller amplitude may help",
                        self.time,
                        e.problem.cause
                    ))
                }
            }
        }
        Ok(())
    }

    /// Advance by `periods` stroke periods.
    pub fn run_periods(&mut self, periods: f64) -> Result<()> {
        self.run(periods * self.period)
    }

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

    /// Replace the state (same length), e.g. with a prepared perturbation.
    pub fn set_state(&mut self, state: &[f64]) -> Result<()> {
        if state.len() != self.state.len() || state.iter().any(|x| !x.is_finite()) {
            return Err(invalid!(
                "a continuum state has {} finite values, got {}",
                self.state.len(),
                state.len()
            ));
        }
        self.state.copy_from_slice(state);
        self.filter_state();
        self.stepper.reset();
        Ok(())
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

    /// The field `kind` of population `population` (all populations when `None`), on the grid:
    /// the same [`Field`] as a scene's, with the continuum's smoothing width.
    pub fn field(&self, kind: FieldKind, population: Option<usize>) -> Result<Field> {
        let op = &self.kinetic.op;
        if let Some(p) = population {
            if p >= self.kinetic.pops {
                return Err(invalid!(
                    "population {p} does not exist: this continuum has {} (0 to {})",
                    self.kinetic.pops,
                    self.kinetic.pops - 1
                ));
            }
        }
        let b = op.sphere.len();
        let cells = op.cells;
        let pops: Vec<usize> = match population {
            Some(p) => vec![p],
            None => (0..self.kinetic.pops).collect(),
        };
        let y0 = 1.0 / (4.0 * PI).sqrt();
        let mut values = vec![0.0; cells * kind.components()];
        let mut rho = vec![0.0; cells];
        for &p in &pops {
            let block = |i: usize| &self.state[(p * b + i) * cells..(p * b + i + 1) * cells];
            let c0 = block(0);
            for (r, c) in rho.iter_mut().zip(c0) {
                *r += c / y0;
            }
            match kind {
                FieldKind::Density => {}
                FieldKind::Polarization => {
                    for a in 0..3 {
                        for (i, w) in op.first[a].iter().enumerate() {
                            if *w != 0.0 {
                                for (cell, c) in block(i).iter().enumerate() {
                                    values[3 * cell + a] += w * c;
                                }
                            }
                        }
                    }
                }
                FieldKind::Nematic => {
                    // ∫ (3nn − I)/2 f = 3M/2 − ρ I/2, M from the six second moments.
                    let idx = [[0, 1, 2], [1, 3, 4], [2, 4, 5]];
                    for a in 0..3 {
                        for bb in 0..3 {
                            for (i, w) in op.second[idx[a][bb]].iter().enumerate() {
                                if *w != 0.0 {
                                    for (cell, c) in block(i).iter().enumerate() {
                                        values[9 * cell + 3 * a + bb] += 1.5 * w * c;
                                    }
                                }
                            }
                        }
                    }
                    for (cell, c) in c0.iter().enumerate() {
                        for a in 0..3 {
                            values[9 * cell + 4 * a] -= 0.5 * c * (4.0 * PI).sqrt();
                        }
                    }
                }
            }
        }
        match kind {
            FieldKind::Density => values.copy_from_slice(&rho),
            _ => {
                let comps = kind.components();
                for (cell, r) in rho.iter().enumerate() {
                    let v = &mut values[comps * cell..comps * (cell + 1)];
                    if *r > 0.0 {
                        v.iter_mut().for_each(|x| *x /= r);
                    } else {
                        v.fill(0.0);
                    }
                }
            }
        }
        let h: [f64; 3] = std::array::from_fn(|d| self.sides[d] / self.grid[d] as f64);
        Ok(Field {
            kind,
            grid: self.grid,
            origin: std::array::from_fn(|d| -0.5 * self.sides[d] + 0.5 * h[d]),
            spacing: h,
            width: self.width,
            periodic: true,
            values,
        })
    }

    /// The mean-field rates (dR_H/dt, dN/dt) of a swimmer of population `p` with orientation `n`
    /// at every cell centre: the particles' averaged rates summed over the distribution.
    pub fn mean_field(&self, p: usize, n: [f64; 3]) -> Result<Vec<([f64; 3], [f64; 3])>> {
        if p >= self.kinetic.pops {
            return Err(invalid!("population {p} does not exist"));
        }
        let op = &self.kinetic.op;
        let u = op.mean_field_terms(&self.state, self.kinetic.pops, p);
        let mut out = vec![([0.0; 3], [0.0; 3]); op.cells];
        if let Some(u) = u {
            for (g, (o, _, comps)) in op.groups.iter().enumerate() {
                let m = monomial(&n, &op.comps[comps[0]].alpha);
                for (cell, r) in out.iter_mut().enumerate() {
                    if *o < 3 {
                        r.0[*o] += m * u[g][cell];
                    } else {
                        r.1[*o - 3] += m * u[g][cell];
                    }
                }
            }
            for r in &mut out {
                let t = r.1;
                let along = t[0] * n[0] + t[1] * n[1] + t[2] * n[2];
                r.1 = std::array::from_fn(|d| -(t[d] - along * n[d]));
            }
        }
        Ok(out)
    }

    /// The Fourier amplitude ∫ e^{−ik·x} q(x) dx of the field density ρ, ρΠ or ρQ (Q row by
    /// row), of population `population` (all when `None`), at box mode `mode` (k = 2π mode/L):
    /// what Σ_σ e^{−ik·R_σ} (times N_σ or (3N_σN_σ − I)/2) is for the particles.
    pub fn mode(
        &self,
        kind: FieldKind,
        population: Option<usize>,
        mode: [i64; 3],
    ) -> Result<Vec<Complex64>> {
        let f = self.field(kind, population)?;
        let rho = match kind {
            FieldKind::Density => None,
            _ => Some(self.field(FieldKind::Density, population)?),
        };
        Ok(fourier_mode(&f, rho.as_ref(), self.sides, mode))
    }

    /// Growth rates about a homogeneous state at wave vector `k` (1/m), fastest first: the
    /// eigenvalues of the linearised operator (see [`stability`]).
    pub fn growth_rates(&self, base: &BaseState, k: [f64; 3]) -> Result<Vec<Mode>> {
        let mean = self.mean_densities();
        stability::growth_rates(&self.kinetic.op, &self.populations, &mean, base, k)
    }

    /// The operator linearised about `base` at wave vector `k` (1/m): dδc/dt = A δc, δc_{p,i} the
    /// complex amplitude of c_{p,i} at e^{ik·x}, at [p·B + i].
    pub fn linear_operator(
        &self,
        base: &BaseState,
        k: [f64; 3],
    ) -> Result<nalgebra::DMatrix<Complex64>> {
        let mean = self.mean_densities();
        stability::linear_operator(&self.kinetic.op, &self.populations, &mean, base, k)
    }

    /// The complex amplitudes δc_{p,i} = (1/cells) Σ_x c_{p,i}(x) e^{−ik·x} of the state at box
    /// mode `mode`, at [p·B + i] (x the cell centres).
    pub fn amplitudes(&self, mode: [i64; 3]) -> Vec<Complex64> {
        let cells = self.kinetic.op.cells;
        let phases = self.cell_phases(mode);
        self.state
            .chunks(cells)
            .map(|b| {
                b.iter()
                    .zip(&phases)
                    .map(|(v, e)| v * e.conj())
                    .sum::<Complex64>()
                    / cells as f64
            })
            .collect()
    }

    /// e^{ik·x} at every cell centre for box mode `mode`.
    fn cell_phases(&self, mode: [i64; 3]) -> Vec<Complex64> {
        let [nx, ny, _] = self.grid;
        let h: [f64; 3] = std::array::from_fn(|d| self.sides[d] / self.grid[d] as f64);
        (0..self.kinetic.op.cells)
            .map(|cell| {
                let idx = [cell % nx, (cell / nx) % ny, cell / (nx * ny)];
                let phase: f64 = (0..3)
                    .map(|d| {
                        let x = -0.5 * self.sides[d] + (idx[d] as f64 + 0.5) * h[d];
                        2.0 * PI * mode[d] as f64 * x / self.sides[d]
                    })
                    .sum();
                Complex64::from_polar(1.0, phase)
            })
            .collect()
    }

    /// The centre of every cell (m).
    pub fn cell_centres(&self) -> Vec<[f64; 3]> {
        let [nx, ny, _] = self.grid;
        let h: [f64; 3] = std::array::from_fn(|d| self.sides[d] / self.grid[d] as f64);
        (0..self.kinetic.op.cells)
            .map(|cell| {
                let idx = [cell % nx, (cell / nx) % ny, cell / (nx * ny)];
                std::array::from_fn(|d| -0.5 * self.sides[d] + (idx[d] as f64 + 0.5) * h[d])
            })
            .collect()
    }

    /// Set population `p`'s distribution to f(x, n) (1/(m³ sr)), projected on the basis at every
    /// cell centre (and filtered as the solver's states are).
    pub fn set_distribution(
        &mut self,
        p: usize,
        f: impl Fn([f64; 3], [f64; 3]) -> f64,
    ) -> Result<()> {
        if p >= self.kinetic.pops {
            return Err(invalid!("population {p} does not exist"));
        }
        let op = &self.kinetic.op;
        let b = op.sphere.len();
        let cells = op.cells;
        let mut at = vec![0.0; op.sphere.node_count()];
        let mut c = vec![0.0; b];
        for (cell, x) in self.cell_centres().into_iter().enumerate() {
            for (a, n) in at.iter_mut().zip(&op.sphere.nodes) {
                *a = f(x, *n);
            }
            op.sphere.project(&at, &mut c);
            for (i, ci) in c.iter().enumerate() {
                self.state[(p * b + i) * cells + cell] = *ci;
            }
        }
        self.filter_state();
        self.stepper.reset();
        Ok(())
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

    /// The state of a homogeneous `base` at each population's mean density, [p·B + i].
    pub fn base_coefficients(&self, base: &BaseState) -> Result<Vec<f64>> {
        stability::base_coefficients(&self.kinetic.op, &self.mean_densities(), base)
    }

    /// Set the state to a homogeneous `base` at each population's mean density, plus a plane
    /// wave of relative amplitude `amplitude` at box mode `mode` in the population `population`'s
    /// (all when `None`) density (`shape` "density"), polarization along `axis`
    /// (c(n) gains 3 axis·n) or nematic order along `axis` (gains (15/2)(axis·n)² − 5/2).
    #[allow(clippy::too_many_arguments)]
    pub fn perturb(
        &mut self,
        base: &BaseState,
        shape: FieldKind,
        axis: [f64; 3],
        mode: [i64; 3],
        amplitude: f64,
        population: Option<usize>,
    ) -> Result<()> {
        if !amplitude.is_finite() {
            return Err(invalid!(
                "a perturbation's amplitude must be a finite number, got {amplitude}"
            ));
        }
        let coef = self.base_coefficients(base)?;
        let op = &self.kinetic.op;
        let b = op.sphere.len();
        let cells = op.cells;
        let sphere = &op.sphere;
        let norm = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
        if norm.is_nan() || (norm <= 0.0 && shape != FieldKind::Density) {
            return Err(invalid!("a perturbation's axis must be a nonzero vector"));
        }
        let e = axis.map(|x| x / norm.max(1e-300));
        // The angular shape g(n) of the perturbation, projected on the basis.
        let shape_at: Vec<f64> = sphere
            .nodes
            .iter()
            .map(|n| {
                let c = e[0] * n[0] + e[1] * n[1] + e[2] * n[2];
                match shape {
                    FieldKind::Density => 1.0,
                    FieldKind::Polarization => 3.0 * c,
                    FieldKind::Nematic => 7.5 * c * c - 2.5,
                }
            })
            .collect();
        let mut g = vec![0.0; b];
        sphere.project(&shape_at, &mut g);
        let dens = self.mean_densities();
        let waves = self.cell_phases(mode);
        for p in 0..self.kinetic.pops {
            let hit = population.is_none_or(|q| q == p);
            for i in 0..b {
                let block = &mut self.state[(p * b + i) * cells..(p * b + i + 1) * cells];
                for (v, e) in block.iter_mut().zip(&waves) {
                    let wave = if hit {
                        amplitude * dens[p] / (4.0 * PI) * g[i] * e.re
                    } else {
                        0.0
                    };
                    *v = coef[p * b + i] + wave;
                }
            }
        }
        self.filter_state();
        self.stepper.reset();
        Ok(())
    }
}

impl Continuum {
    /// Add `n` swimmers of the continuum's kind to `scene` drawn from its distribution: a
    /// population in proportion to its number, a cell in proportion to its density there (the
    /// density clipped at 0: a truncated distribution can dip below), a place uniform in the cell,
    /// an orientation from f_p at the cell's centre (rejection, f clipped at 0), the population's
    /// phase; draws that would bring spheres within `gap` of others are drawn again (as
    /// `add_random`). All or nothing. The scene needs the continuum's box.
    pub fn sample(&self, scene: &mut Scene, n: usize, seed: u64, gap: Option<f64>) -> Result<()> {
        let same_box = scene.periodic().is_some_and(|b| {
            b.sides()
                .iter()
                .zip(&self.sides)
                .all(|(a, b)| (a - b).abs() <= 1e-12 * a.abs())
        });
        if !same_box {
            return Err(invalid!(
                "swimmers drawn from a continuum go into a scene with the continuum's box {:?} m; give the scene that box first",
                self.sides
            ));
        }
        let k = &self.kind;
        let filled = (scene.count() + n) as f64 * 4.0 / 3.0 * PI * (k.a1.powi(3) + k.a2.powi(3))
            / self.sides.iter().product::<f64>();
        if filled > 0.05 {
            return Err(invalid!(
                "{n} more swimmers would fill {:.1}% of the box with spheres; draws from a continuum are for dilute suspensions (at most 5%), which is what its mean field describes: draw fewer",
                100.0 * filled
            ));
        }
        let op = &self.kinetic.op;
        let b = op.sphere.len();
        let cells = op.cells;
        let nn = op.sphere.node_count();
        // Per population, the cumulative clipped density over the cells; per cell and node, f.
        let mut cum: Vec<Vec<f64>> = Vec::new();
        let mut at_nodes: Vec<Vec<f64>> = Vec::new();
        for p in 0..self.kinetic.pops {
            let mut f = vec![0.0; cells * nn];
            let mut c = vec![0.0; b];
            let mut acc = 0.0;
            let mut row = Vec::with_capacity(cells);
            for cell in 0..cells {
                for (i, ci) in c.iter_mut().enumerate() {
                    *ci = self.state[(p * b + i) * cells + cell];
                }
                op.sphere.evaluate(&c, &mut f[cell * nn..(cell + 1) * nn]);
                acc += (c[0] * (4.0 * PI).sqrt()).max(0.0);
                row.push(acc);
            }
            cum.push(row);
            at_nodes.push(f);
        }
        let totals: Vec<f64> = cum.iter().map(|r| *r.last().unwrap_or(&0.0)).collect();
        let all: f64 = totals.iter().sum();
        if all.is_nan() || all <= 0.0 {
            return Err(invalid!("the continuum holds no swimmers to draw"));
        }
        let h: [f64; 3] = std::array::from_fn(|d| self.sides[d] / self.grid[d] as f64);
        let [nx, ny, _] = self.grid;
        let sphere = &op.sphere;
        let draw = |rng: &mut super::build::Rng| {
            let mut u = rng.uniform() * all;
            let mut p = 0;
            while p + 1 < totals.len() && u >= totals[p] {
                u -= totals[p];
                p += 1;
            }
            let cell = cum[p].partition_point(|x| *x <= u).min(cells - 1);
            let idx = [cell % nx, (cell / nx) % ny, cell / (nx * ny)];
            let c = nalgebra::Vector3::from_fn(|d, _| {
                -0.5 * self.sides[d] + (idx[d] as f64 + rng.uniform()) * h[d]
            });
            let f = &at_nodes[p][cell * nn..(cell + 1) * nn];
            let top = f.iter().fold(0.0f64, |a, x| a.max(*x)) * 1.2;
            let mut dir = rng.unit_vector();
            for _ in 0..1000 {
                let y = sphere.basis_at(&[dir.x, dir.y, dir.z]);
                let c = &self.state;
                let value: f64 = (0..b).map(|i| y[i] * c[(p * b + i) * cells + cell]).sum();
                if rng.uniform() * top <= value.max(0.0) {
                    break;
                }
                dir = rng.unit_vector();
            }
            (c, dir, self.populations[p].phase)
        };
        let mut trial = scene.clone();
        place_apart(&mut trial, n, self.kind, seed, gap, draw)?;
        *scene = trial;
        Ok(())
    }
}

/// The Fourier amplitude Σ_σ e^{−ik·R_σ} w_σ of the particles' `kind` (w = 1, N_σ, or
/// (3N_σN_σ − I)/2 row by row) at box mode `mode` of `scene`'s box, over the swimmers of phase
/// `phase` (all when `None`): the particles' side of [`Continuum::mode`].
pub fn particle_mode(
    scene: &Scene,
    kind: FieldKind,
    mode: [i64; 3],
    phase: Option<f64>,
) -> Result<Vec<Complex64>> {
    let Some(b) = scene.periodic() else {
        return Err(invalid!(
            "a Fourier mode is taken over a periodic box's wave vectors, and this scene has none; set s.box first"
        ));
    };
    let sides = b.sides();
    let comps = kind.components();
    let mut out = vec![Complex64::default(); comps];
    for (i, d) in scene.swimmers().iter().enumerate() {
        if let Some(p) = phase {
            let diff = (d.phase - p).rem_euclid(2.0 * PI);
            if diff.min(2.0 * PI - diff) > SAME_PHASE {
                continue;
            }
        }
        let r = scene.shown(scene.center(i)?);
        let n = scene.dir(i)?;
        let arg: f64 = (0..3)
            .map(|a| -2.0 * PI * mode[a] as f64 * r[a] / sides[a])
            .sum();
        let e = Complex64::from_polar(1.0, arg);
        match kind {
            FieldKind::Density => out[0] += e,
            FieldKind::Polarization => (0..3).for_each(|a| out[a] += e * n[a]),
            FieldKind::Nematic => {
                for a in 0..3 {
                    for c in 0..3 {
                        let q = 1.5 * n[a] * n[c] - if a == c { 0.5 } else { 0.0 };
                        out[3 * a + c] += e * q;
                    }
                }
            }
        }
    }
    Ok(out)
}

/// The Fourier amplitude of field `f` (times the density `rho` for Π and Q) at box mode `mode`.
pub fn fourier_mode(
    f: &Field,
    rho: Option<&Field>,
    sides: [f64; 3],
    mode: [i64; 3],
) -> Vec<Complex64> {
    let comps = f.kind.components();
    let [nx, ny, _] = f.grid;
    let dv = f.spacing.iter().product::<f64>();
    let mut out = vec![Complex64::default(); comps];
    for cell in 0..f.cells() {
        let idx = [cell % nx, (cell / nx) % ny, cell / (nx * ny)];
        let phase: f64 = (0..3)
            .map(|d| {
                let x = f.origin[d] + idx[d] as f64 * f.spacing[d];
                -2.0 * PI * mode[d] as f64 * x / sides[d]
            })
            .sum();
        let w = Complex64::from_polar(dv * rho.map_or(1.0, |r| r.values[cell]), phase);
        for (o, v) in out
            .iter_mut()
            .zip(&f.values[comps * cell..comps * (cell + 1)])
        {
            *o += w * v;
        }
    }
    out
}

fn check_spec(spec: &ContinuumSpec) -> Result<()> {
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
fn populations(phases: &[f64], bins: Option<usize>) -> Result<(Vec<Population>, Vec<usize>)> {
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
fn deposit(
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

impl Operator {
    #[allow(clippy::too_many_arguments)]
    fn new(
        grid: [usize; 3],
        sides: [f64; 3],
        degree: usize,
        constants: &Constants,
        core: f64,
        cutoff: f64,
        phases: &[f64],
        diffusion: Option<RigidDiffusion>,
    ) -> Operator {
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
            core,
            cutoff,
        }
    }

    /// The transformed second moments M̂_{q,β}(k) of every population of state `y`.
    fn moments(&self, y: &[f64], pops: usize) -> Vec<Vec<Vec<Complex64>>> {
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
    fn mean_field_terms(&self, y: &[f64], pops: usize, p: usize) -> Option<Vec<Vec<f64>>> {
        if self.sin[p].iter().all(|s| *s == 0.0) {
            return None;
        }
        let m = self.moments(y, pops);
        Some(self.terms_from_moments(&m, p))
    }

    fn terms_from_moments(&self, m: &[Vec<Vec<Complex64>>], p: usize) -> Vec<Vec<f64>> {
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
        self.groups
            .par_iter()
            .map(|(_, _, comps)| {
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
            })
            .collect()
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
            // Fluxes F_{i,a} = ∫ Y_i v_a f and turns R_i = ∫ f ṅ·∇Y_i at every cell, [i·4 + a].
            let mut flux = vec![vec![0.0; cells]; 4 * b];
            if let Some(u) = &terms {
                let per_cell: Vec<Vec<f64>> = (0..cells)
                    .into_par_iter()
                    .map_init(
                        || (vec![0.0; nn], vec![[0.0; 6]; nn]),
                        |(f, rates), cell| {
                            let coef: Vec<f64> = (0..b).map(|i| block(i)[cell]).collect();
                            op.sphere.evaluate(&coef, f);
                            rates.iter_mut().for_each(|r| *r = [0.0; 6]);
                            for (g, (o, at, _)) in op.groups.iter().enumerate() {
                                let uv = u[g][cell];
                                if uv != 0.0 {
                                    for (r, a) in rates.iter_mut().zip(at) {
                                        r[*o] += uv * a;
                                    }
                                }
                            }
                            let mut out = vec![0.0; 4 * b];
                            for (j, (r, fj)) in rates.iter().zip(f.iter()).enumerate() {
                                let n = op.sphere.nodes[j];
                                let t = [r[3], r[4], r[5]];
                                let along = t[0] * n[0] + t[1] * n[1] + t[2] * n[2];
                                let turn: [f64; 3] =
                                    std::array::from_fn(|d| -(t[d] - along * n[d]));
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
                            out
                        },
                    )
                    .collect();
                for (cell, v) in per_cell.iter().enumerate() {
                    for (q, x) in v.iter().enumerate() {
                        flux[q][cell] = *x;
                    }
                }
            }
            // With noise: every coefficient's transform, for the diffusion terms.
            let hats: Option<Vec<Vec<Complex64>>> = op.diffusion.as_ref().map(|_| {
                (0..b)
                    .into_par_iter()
                    .map(|i| {
                        let mut spare = vec![Complex64::default(); cells];
                        let mut buf: Vec<Complex64> =
                            block(i).iter().map(|x| Complex64::new(*x, 0.0)).collect();
                        op.fft.forward(&mut buf, &mut spare);
                        buf
                    })
                    .collect()
            });
            let out: Vec<Vec<f64>> = (0..b)
                .into_par_iter()
                .map(|i| {
                    let mut spare = vec![Complex64::default(); cells];
                    let to_k = |v: &[f64], spare: &mut Vec<Complex64>| {
                        let mut buf: Vec<Complex64> =
                            v.iter().map(|x| Complex64::new(*x, 0.0)).collect();
                        op.fft.forward(&mut buf, spare);
                        buf
                    };
                    let mut acc = vec![Complex64::default(); cells];
                    if terms.is_some() {
                        let fx = to_k(&flux[4 * i], &mut spare);
                        let fy = to_k(&flux[4 * i + 1], &mut spare);
                        let fz = to_k(&flux[4 * i + 2], &mut spare);
                        let r = to_k(&flux[4 * i + 3], &mut spare);
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
                })
                .collect();
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
