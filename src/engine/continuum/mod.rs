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
mod operator;
mod prepare;
mod reading;
mod spec;
pub mod sphere;
mod stability;

pub use reading::{fourier_mode, particle_mode, MAX_PARTICLE_MODE};
pub use spec::{
    ContinuumSpec, WholeOption, MAX_CELLS, MAX_POPULATIONS, MIN_CELLS_PER_AXIS,
    MIN_CORE_IN_LENGTHS, MIN_DEGREE, MIN_TOL,
};
pub use stability::{BaseState, Mode};

use self::kernel::Constants;
use self::operator::{Kinetic, Operator};
use self::spec::{deposit, populations, Lengths};
use self::sphere::monomial;
use super::averaged::pair_constants;
use super::error::{invalid, Result};
use super::integrators::{Dopri5, Horizon, Stats, Stepper};
use super::scene::{Scene, MAX_TIME_IN_PERIODS};
use super::swimmer::Dumbbell;
use super::thermal::RigidDiffusion;
use rustfft::num_complex::Complex64;
use std::f64::consts::PI;
use std::sync::Arc;

/// One phase population.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Population {
    /// Its phase φ (rad, in [0, 2π)).
    pub phase: f64,
    /// How many swimmers of the scene it was built from.
    pub swimmers: usize,
}

/// A continuum: the distribution, its time, and the stepper. A clone is an independent copy (the
/// operator, which no run changes, shared).
#[derive(Clone)]
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
        let cutoff = scene.averaged_cutoff()?.expect("a box always has a cutoff");
        let Lengths { core, width } = spec.check(sides, cutoff, &first)?;
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
            op: Arc::new(op),
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

    /// Advance by `seconds`. Refused before it starts: a negative time, or an end past the
    /// latest time a continuum may hold ([`Continuum::horizon`]). On an error the state is the
    /// last accepted one.
    pub fn run(&mut self, seconds: f64) -> Result<()> {
        if seconds < 0.0 {
            return Err(invalid!(
                "a continuum runs for 0 s or more, got {seconds:e} s; the dynamics cannot run backwards"
            ));
        }
        let end = self.time + seconds;
        self.horizon().check(self.time, end)?;
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

    /// The latest time a continuum may hold: [`MAX_TIME_IN_PERIODS`] of its stroke period, as a
    /// scene (it starts at its scene's time).
    pub fn horizon(&self) -> Horizon<'static> {
        Horizon {
            holder: "a continuum",
            latest: MAX_TIME_IN_PERIODS * self.period,
            max_periods: MAX_TIME_IN_PERIODS,
            period: Some(self.period),
            beyond: "",
            restart: "build a new continuum from a scene at time 0",
        }
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
    fn check_population(&self, p: usize) -> Result<()> {
        let n = self.kinetic.pops;
        if p < n {
            return Ok(());
        }
        Err(invalid!(
            "population {p} does not exist: this continuum has {n} ({}), numbered from 0 in the order of its populations",
            if n == 1 { "0".to_string() } else { format!("0 to {}", n - 1) }
        ))
    }

    /// The mean-field rates (dR_H/dt, dN/dt) of a swimmer of population `p` with orientation `n`
    /// at every cell centre: the particles' averaged rates summed over the distribution.
    pub fn mean_field(&self, p: usize, n: [f64; 3]) -> Result<Vec<([f64; 3], [f64; 3])>> {
        self.check_population(p)?;
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
}
