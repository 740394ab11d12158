//! The averaged model as an [`OdeSystem`]: its rates, the suspension stepper's stiff groups and
//! error norm, the guards, thermal noise and the projection onto unit orientations.

use super::system::{AveragedSystem, LIST_SWIMMERS, PARALLEL_SWIMMERS};
use crate::engine::integrators::{
    time_scale_of, ErrorMeasure, GroupJacobian, Noise, OdeSystem, Partitioned, Problem,
};
use crate::engine::model::{set_vec3, vec3, STATE_PER_SWIMMER};
use nalgebra::Vector3;
use rayon::prelude::*;

impl OdeSystem for AveragedSystem {
    fn dim(&self) -> usize {
        STATE_PER_SWIMMER * self.coef.len()
    }

    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) {
        match self.axis {
            Some(axis) => {
                // Centre coordinates along the axis in `x`, the orientation's in `nx`.
                for s in 0..self.coef.len() {
                    self.soa.x[s] = self.center(y, s).dot(&axis);
                    self.soa.nx[s] = vec3(y, STATE_PER_SWIMMER * s + 3).dot(&axis);
                }
            }
            None => self.fill(y),
        }
        if self.uses_lists() {
            self.update_list();
            if let Some(st) = self.contacts.steric {
                self.steric_by_list(st);
            }
            return self.rows_by_list(dy);
        }
        if let Some(st) = self.contacts.steric {
            // The sphere models' pair force, on the spheres at length ℓ.
            self.steric_f.fill(Vector3::zeros());
            let parallel = self.coef.len() >= PARALLEL_SWIMMERS;
            let periodic = self.periodic.as_ref();
            st.add_forces(
                &self.sphere_pos,
                &self.radii,
                periodic,
                &mut self.steric_f,
                parallel,
            );
        }
        self.rows_into(y, dy);
    }

    fn autonomous(&self) -> bool {
        true
    }

    fn time_scale(&self) -> f64 {
        time_scale_of(self.period)
    }

    fn stiff_groups(&mut self, _t: f64, y: &[f64]) -> GroupJacobian {
        self.contact_jacobian(y)
    }

    fn step_error_norm(
        &self,
        _y: &[f64],
        _y_new: &[f64],
        err: &[f64],
        h: f64,
        f0: &[f64],
        tol: f64,
    ) -> f64 {
        let mut e = vec![0.0; self.coef.len()];
        let m = ErrorMeasure { h, f0, tol };
        self.swimmer_errors(err, &m, None, &mut None, &mut e);
        (e.iter().map(|e| e * e).sum::<f64>() / e.len().max(1) as f64).sqrt()
    }

    fn as_partitioned(&mut self) -> Option<&mut dyn Partitioned> {
        Some(self)
    }

    /// Centres against the closest pair's per-period drift scale (as in the microscopic model),
    /// orientations against the matching rotation scale (λ/ℓ)²(Λ/ℓ).
    fn error_scale(&self, _y: &[f64], scale: &mut [f64]) {
        for s in 0..self.coef.len() {
            let i = STATE_PER_SWIMMER * s;
            scale[i..i + 3].fill(self.scale_r[s]);
            scale[i + 3..i + 6].fill(self.scale_n[s]);
        }
    }

    fn check(&mut self, _t: f64, y: &[f64]) -> Result<(), Problem> {
        self.fill(y);
        if self.uses_lists() {
            self.update_list();
            return self.check_by_list();
        }
        let soa = &self.soa;
        let n = self.coef.len();
        let parallel = n >= PARALLEL_SWIMMERS;
        let shared_centre = |s: usize| {
            (s + 1..n)
                .find(|&r| {
                    soa.x[s] == soa.x[r]
                        && soa.y[s] == soa.y[r]
                        && soa.z[s] == soa.z[r]
                        && self.pair_sin(s, r).is_some()
                })
                .map(|r| (s, r))
        };
        let found = if n >= LIST_SWIMMERS {
            // Only swimmers with bitwise equal centres share one: group them, O(S).
            let mut groups: std::collections::HashMap<[u64; 3], Vec<usize>> =
                std::collections::HashMap::new();
            for i in 0..n {
                // + 0.0 makes −0.0 the key of 0.0, as == treats them.
                let key = [soa.x[i], soa.y[i], soa.z[i]].map(|c| (c + 0.0).to_bits());
                groups.entry(key).or_default().push(i);
            }
            groups
                .values()
                .filter(|g| g.len() > 1)
                .flat_map(|g| {
                    g.iter()
                        .enumerate()
                        .flat_map(move |(k, &s)| g[k + 1..].iter().map(move |&r| (s, r)))
                })
                .filter(|&(s, r)| self.pair_sin(s, r).is_some())
                .min()
        } else if parallel {
            (0..n).into_par_iter().find_map_first(shared_centre)
        } else {
            (0..n).find_map(shared_centre)
        };
        if let Some((s, r)) = found {
            return Err(shared_centre_problem(s, r));
        }
        if self.contacts.allow_overlap {
            return Ok(());
        }
        // The sphere models' contact guard, on the spheres at length ℓ.
        let g = &mut self.gap_soa;
        g.resize(self.sphere_pos.len());
        for (i, p) in self.sphere_pos.iter().enumerate() {
            (g.x[i], g.y[i], g.z[i]) = (p.x, p.y, p.z);
        }
        match crate::engine::gaps::closest_overlap(g, &self.radii, parallel) {
            Some((gap, a, b)) => Err(crate::engine::spheres::overlap_problem(gap, a, b)),
            None => Ok(()),
        }
    }

    fn noise(&self) -> Option<Noise> {
        self.thermal.as_ref().map(|(seed, _)| Noise {
            seed: *seed,
            dim: STATE_PER_SWIMMER * self.coef.len(),
        })
    }

    /// Each swimmer's centre of mobility C = R_H + z_c N takes a step √(2D_∥)(N·ξ)N +
    /// √(2D_⊥)(1 − NNᵀ)ξ, its orientation turns to (N + √(2D_r)(1 − NNᵀ)ξ')/|…| (the
    /// normalisation carries the Itô drift −2D_r N dt of rotational diffusion), and R_H = C − z_c N
    /// follows: translation and rotation are independent about C, not about R_H.
    fn add_noise(
        &mut self,
        _t: f64,
        y: &[f64],
        dw: &[f64],
        y_new: &mut [f64],
    ) -> Result<(), Problem> {
        let Some((_, diffusion)) = &self.thermal else {
            return Ok(());
        };
        for (s, d) in diffusion.iter().enumerate() {
            let i = STATE_PER_SWIMMER * s;
            let n = vec3(y, i + 3).normalize();
            let (xi, xr) = (vec3(dw, i), vec3(dw, i + 3));
            let along = n * n.dot(&xi);
            let dc =
                (2.0 * d.parallel).sqrt() * along + (2.0 * d.perpendicular).sqrt() * (xi - along);
            let n_det = vec3(y_new, i + 3).normalize();
            let turned = (vec3(y_new, i + 3) + (2.0 * d.rotation).sqrt() * (xr - n * n.dot(&xr)))
                .normalize();
            let r = vec3(y_new, i) + dc - d.offset * (turned - n_det);
            set_vec3(y_new, i, &r);
            set_vec3(y_new, i + 3, &turned);
        }
        Ok(())
    }

    /// Renormalise every N (the projector keeps dN/dt tangent; the step leaves it off by O(h²)).
    fn project(&self, y: &mut [f64]) {
        for s in 0..self.coef.len() {
            let i = STATE_PER_SWIMMER * s + 3;
            let n = vec3(y, i).normalize();
            set_vec3(y, i, &n);
        }
    }
}

/// The guard's error for swimmers `s` and `r` at the same centre.
pub(super) fn shared_centre_problem(s: usize, r: usize) -> Problem {
    Problem {
        swimmer: Some(s),
        cause: format!("swimmers {s} and {r} have the same centre"),
        hint: "start the swimmers apart: the averaged model is a far-field model".into(),
        fixes: Vec::new(),
    }
}
