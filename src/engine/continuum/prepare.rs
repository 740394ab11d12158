//! Prepared states of a continuum (a state given whole, a distribution f(x, n), a homogeneous
//! state with a plane wave) and particles drawn from its distribution.

use super::stability::BaseState;
use super::state::Continuum;
use crate::engine::build::place_apart;
use crate::engine::error::{invalid, Result};
use crate::engine::fields::FieldKind;
use crate::engine::integrators::Stepper;
use crate::engine::scene::Scene;
use std::f64::consts::PI;

impl Continuum {
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

    /// Set population `p`'s distribution to f(x, n) (1/(m³ sr)), projected on the basis at every
    /// cell centre (and filtered as the solver's states are).
    pub fn set_distribution(
        &mut self,
        p: usize,
        f: impl Fn([f64; 3], [f64; 3]) -> f64,
    ) -> Result<()> {
        self.check_population(p)?;
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

    /// Set the state to a homogeneous `base` at each population's mean density, plus a plane
    /// wave cos(k·x) of relative amplitude `amplitude` at box mode `mode` in the population
    /// `population`'s (all when `None`) density (`shape` "density"), polarization along `axis`
    /// (c(n) gains 3 axis·n) or nematic order along `axis` (gains (15/2)(axis·n)² − 5/2).
    /// Refused, the state unchanged: a population that does not exist, mode 0 (the mean, which
    /// would change the conserved numbers), a mode the grid does not hold, an amplitude that would
    /// make f negative somewhere ([`largest_amplitude`]).
    pub fn perturb(
        &mut self,
        base: &BaseState,
        shape: FieldKind,
        axis: [f64; 3],
        mode: [i64; 3],
        amplitude: f64,
        population: Option<usize>,
    ) -> Result<()> {
        if let Some(p) = population {
            self.check_population(p)?;
        }
        if mode == [0, 0, 0] {
            return Err(invalid!(
                "box mode [0, 0, 0] is no wave but the mean: a perturbation there would change each population's number of swimmers, which the dynamics conserves; give a mode with a nonzero entry, e.g. [1, 0, 0]"
            ));
        }
        self.check_mode(mode)?;
        if !amplitude.is_finite() {
            return Err(invalid!(
                "a perturbation's amplitude must be a finite number, got {amplitude}"
            ));
        }
        let coef = self.base_coefficients(base)?;
        let e = match unit(axis) {
            Some(e) => e,
            None if shape == FieldKind::Density => [0.0, 0.0, 1.0],
            None => {
                return Err(invalid!(
                "a perturbation's axis must be a nonzero vector of finite components, got {axis:?}"
            ))
            }
        };
        let most = largest_amplitude(base, shape, e);
        // The bound's own round-off (1e-9) aside, so that a bound typed in full passes.
        if amplitude.abs() > most * (1.0 + 1e-9) {
            return Err(invalid!(
                "a {} wave of relative amplitude {amplitude:e} would make the distribution negative for some orientations (where cos(k·x) has the sign that lowers it); about this state its amplitude must lie within ±{most:.6} so that f ≥ 0 everywhere: give a smaller amplitude",
                shape.name()
            ));
        }
        let op = &self.kinetic.op;
        let b = op.sphere.len();
        let cells = op.cells;
        let sphere = &op.sphere;
        // The angular shape g(n) of the perturbation, projected on the basis.
        let shape_at: Vec<f64> = sphere
            .nodes
            .iter()
            .map(|n| shape_value(shape, e[0] * n[0] + e[1] * n[1] + e[2] * n[2]))
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
        let draw = |rng: &mut crate::engine::build::Rng| {
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

/// The angular shape g of a perturbation of `shape` at c = axis·n.
fn shape_value(shape: FieldKind, c: f64) -> f64 {
    match shape {
        FieldKind::Density => 1.0,
        FieldKind::Polarization => 3.0 * c,
        FieldKind::Nematic => 7.5 * c * c - 2.5,
    }
}

/// `v` scaled to length 1, if it has a direction.
fn unit(v: [f64; 3]) -> Option<[f64; 3]> {
    let big = v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    if !(big.is_finite() && big > 0.0) {
        return None;
    }
    let w = v.map(|x| x / big);
    let n = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
    Some(w.map(|x| x / n))
}

/// The largest |amplitude| of a wave of `shape` along the unit `axis` about `base` that keeps f
/// ≥ 0 at every orientation and place: f ∝ 1 + 3P·n + A g(axis·n) cos(k·x) with cos(k·x) of
/// either sign, so |A| ≤ min over n of (1 + 3P·n)/|g(axis·n)|. That is 1 − 3|P| for the density
/// (g = 1). Otherwise n enters through axis·n and P·n alone, and for fixed axis·n the ratio grows
/// with P·n, so the minimum lies on the great circle through the axis and P (any through the
/// axis when P is along it or 0): sampled at 2^12 points, the least refined by golden sections
/// between its neighbours (to round-off).
fn largest_amplitude(base: &BaseState, shape: FieldKind, axis: [f64; 3]) -> f64 {
    let p = match base {
        BaseState::Isotropic => [0.0; 3],
        BaseState::Polar(p) => *p,
    };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    if shape == FieldKind::Density {
        return (1.0 - 3.0 * dot(p, p).sqrt()).max(0.0);
    }
    let along = dot(p, axis);
    let rest: [f64; 3] = std::array::from_fn(|d| p[d] - along * axis[d]);
    let other = unit(rest)
        .filter(|_| dot(rest, rest).sqrt() > 1e-12 * dot(p, p).sqrt())
        .unwrap_or_else(|| {
            // Any direction across the axis.
            let k = if axis[0].abs() < 0.9 {
                [1.0, 0.0, 0.0]
            } else {
                [0.0, 1.0, 0.0]
            };
            let c = dot(k, axis);
            unit(std::array::from_fn(|d| k[d] - c * axis[d])).expect("across the axis")
        });
    let ratio = |t: f64| {
        let (s, c) = t.sin_cos();
        let n: [f64; 3] = std::array::from_fn(|d| c * axis[d] + s * other[d]);
        let g = shape_value(shape, c).abs();
        if g > 0.0 {
            (1.0 + 3.0 * dot(p, n)) / g
        } else {
            f64::INFINITY
        }
    };
    const SAMPLES: usize = 1 << 12;
    let step = 2.0 * PI / SAMPLES as f64;
    let best = (0..SAMPLES)
        .map(|j| j as f64 * step)
        .min_by(|a, b| ratio(*a).total_cmp(&ratio(*b)))
        .expect("samples");
    let (mut lo, mut hi) = (best - step, best + step);
    let golden = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..80 {
        let (a, b) = (hi - golden * (hi - lo), lo + golden * (hi - lo));
        if ratio(a) <= ratio(b) {
            hi = b;
        } else {
            lo = a;
        }
    }
    ratio(best).min(ratio(0.5 * (lo + hi))).max(0.0)
}
