//! A continuum built from a scene: its swimmers checked to be of one kind, their phases binned
//! into populations, and their smoothed distribution deposited on the grid.

use super::kernel::Constants;
use super::operator::{KernelRange, Kinetic, Operator};
use super::spec::{deposit, populations, ContinuumSpec, Lengths, Particles};
use super::state::Continuum;
use crate::engine::averaged::pair_constants;
use crate::engine::error::{invalid, Result};
use crate::engine::integrators::{Dopri5, Stats};
use crate::engine::scene::Scene;
use crate::engine::stepping::RunControl;
use crate::engine::thermal::RigidDiffusion;
use rustfft::num_complex::Complex64;
use std::sync::Arc;

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
        let mut diffusion = if thermal.is_on() {
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
        // A closure adds its isotropic diffusion to the thermal one (or stands alone).
        if let Some(c) = &spec.closure {
            let base = diffusion.unwrap_or(RigidDiffusion {
                parallel: 0.0,
                perpendicular: 0.0,
                rotation: 0.0,
                offset: 0.0,
            });
            diffusion = Some(RigidDiffusion {
                parallel: base.parallel + c.translation,
                perpendicular: base.perpendicular + c.translation,
                rotation: base.rotation + c.rotation,
                offset: base.offset,
            });
        }
        let phases: Vec<f64> = pops.iter().map(|p| p.phase).collect();
        let op = Operator::new(
            spec.grid,
            sides,
            spec.degree,
            &constants,
            KernelRange { core, cutoff },
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
        let particles = Particles {
            centres: &centres,
            dirs: &dirs,
            member: &member,
        };
        deposit(&op, spec.grid, sides, width, &particles, &mut state);
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
            closure: spec.closure.clone(),
            control: RunControl::default(),
        };
        c.filter_state();
        Ok(c)
    }

    /// Keep only the modes the 2/3 rule keeps (the state then stays in that space).
    pub(super) fn filter_state(&mut self) {
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
}
