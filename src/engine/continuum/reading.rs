//! Reading a continuum: its fields on the grid, its Fourier modes, and the particles' modes that
//! compare with them.

use super::spec::SAME_PHASE;
use super::sphere::monomial;
use super::state::Continuum;
use crate::engine::error::{invalid, Result};
use crate::engine::fields::{Field, FieldKind};
use crate::engine::scene::Scene;
use rustfft::num_complex::Complex64;
use std::f64::consts::PI;

impl Continuum {
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

    /// The field `kind` of population `population` (all populations when `None`), on the grid:
    /// the same [`Field`] as a scene's, with the continuum's smoothing width.
    pub fn field(&self, kind: FieldKind, population: Option<usize>) -> Result<Field> {
        let op = &self.kinetic.op;
        if let Some(p) = population {
            self.check_population(p)?;
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

    /// The Fourier amplitude ∫ e^{−ik·x} q(x) dx of the field density ρ, ρΠ or ρQ (Q row by
    /// row), of population `population` (all when `None`), at box mode `mode` (k = 2π mode/L):
    /// what Σ_σ e^{−ik·R_σ} (times N_σ or (3N_σN_σ − I)/2) is for the particles.
    pub fn mode(
        &self,
        kind: FieldKind,
        population: Option<usize>,
        mode: [i64; 3],
    ) -> Result<Vec<Complex64>> {
        self.check_mode(mode)?;
        let f = self.field(kind, population)?;
        let rho = match kind {
            FieldKind::Density => None,
            _ => Some(self.field(FieldKind::Density, population)?),
        };
        Ok(fourier_mode(&f, rho.as_ref(), self.sides, mode))
    }

    /// The largest |n| per axis of the box modes the state holds: the 2/3 rule against aliasing
    /// keeps 3|n| < cells.
    pub fn largest_modes(&self) -> [i64; 3] {
        self.grid.map(|n| ((n - 1) / 3) as i64)
    }

    /// Refuse a box mode the grid does not hold: the state has none beyond the 2/3 rule, and at
    /// the cell centres a shorter wave is a longer one's alias (a whole number of cells: the mean).
    pub(super) fn check_mode(&self, mode: [i64; 3]) -> Result<()> {
        let most = self.largest_modes();
        if (0..3).all(|d| mode[d].unsigned_abs() <= most[d].unsigned_abs()) {
            return Ok(());
        }
        Err(invalid!(
            "box mode {mode:?} is beyond what this continuum's grid {:?} holds: the 2/3 rule against aliasing keeps |n| up to {most:?} per axis (under a third of the cells; at the cells a shorter wave is the alias of a longer one); give a mode within that, or build the continuum on a finer grid",
            self.grid
        ))
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
    pub(super) fn cell_phases(&self, mode: [i64; 3]) -> Vec<Complex64> {
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
}

/// The Fourier amplitude Σ_σ e^{−ik·R_σ} w(N_σ) of the particles' `kind` (the weight
/// [`FieldKind::weight`]) at box mode `mode` of `scene`'s box, over the swimmers of phase
/// `phase` (all when `None`): the particles' side of [`Continuum::mode`].
pub fn particle_mode(
    scene: &Scene,
    kind: FieldKind,
    mode: [i64; 3],
    phase: Option<f64>,
) -> Result<Vec<Complex64>> {
    let Some(b) = scene.periodic() else {
        return Err(invalid!(
            "a Fourier mode is taken over a periodic box's wave vectors, and this scene has none; set a box first"
        ));
    };
    if mode.iter().any(|n| n.unsigned_abs() > MAX_PARTICLE_MODE) {
        return Err(invalid!(
            "box mode {mode:?} is beyond what f64 resolves: the phase 2π n·x/L of a swimmer carries a round-off of ~n·1e-15 rad, so modes go up to {MAX_PARTICLE_MODE:e} per axis (1e-6 rad); give a smaller mode"
        ));
    }
    if let Some(p) = phase {
        if !p.is_finite() {
            return Err(invalid!(
                "a phase must be a finite number in rad, got {p}; give one of the swimmers' phases, or none for every swimmer"
            ));
        }
        let present = distinct_phases(scene);
        if !present.iter().any(|q| same_phase(*q, p)) {
            let shown: Vec<String> = present
                .iter()
                .take(MAX_PHASES_SHOWN)
                .map(|q| format!("{q}"))
                .collect();
            return Err(invalid!(
                "no swimmer has phase {p} rad (to {SAME_PHASE:e} rad, modulo 2π): the sum would be over none; the phases present are {}{} rad",
                shown.join(", "),
                if present.len() > MAX_PHASES_SHOWN {
                    format!(" and {} more", present.len() - MAX_PHASES_SHOWN)
                } else {
                    String::new()
                }
            ));
        }
    }
    let sides = b.sides();
    let comps = kind.components();
    let mut out = vec![Complex64::default(); comps];
    for (i, d) in scene.swimmers().iter().enumerate() {
        if phase.is_some_and(|p| !same_phase(d.phase, p)) {
            continue;
        }
        let r = scene.shown(scene.center(i)?);
        let n = scene.dir(i)?;
        let arg: f64 = (0..3)
            .map(|a| -2.0 * PI * mode[a] as f64 * r[a] / sides[a])
            .sum();
        let e = Complex64::from_polar(1.0, arg);
        for (o, w) in out.iter_mut().zip(kind.weight(n)) {
            *o += e * w;
        }
    }
    Ok(out)
}

/// The largest |n| per axis of a box mode of the particles: the phase 2π n·x/L then still holds
/// to ~1e-6 rad in f64 (x within half a side, its round-off ~1e-16 of the side).
pub const MAX_PARTICLE_MODE: u64 = 1_000_000_000;

/// The most phases a message lists.
const MAX_PHASES_SHOWN: usize = 16;

/// Whether phases `a` and `b` (rad) are one, modulo 2π.
fn same_phase(a: f64, b: f64) -> bool {
    let d = (a - b).rem_euclid(2.0 * PI);
    d.min(2.0 * PI - d) <= SAME_PHASE
}

/// The distinct phases of `scene`'s swimmers, in [0, 2π), in order of first appearance.
fn distinct_phases(scene: &Scene) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::new();
    for d in scene.swimmers() {
        if !out.iter().any(|q| same_phase(*q, d.phase)) {
            out.push(d.phase.rem_euclid(2.0 * PI));
        }
    }
    out
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
