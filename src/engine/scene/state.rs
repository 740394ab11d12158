//! The swimmers' state and its plain reading: adding a swimmer's state, the stroke phases, the
//! centres, orientations, lengths and sphere positions, and the sphere velocities for given
//! forces.

use super::*;

impl Scene {
    /// Add swimmer `d` (valid) with hydrodynamic centre `center` and unit orientation `n`, its room
    /// checked by the caller (random placement keeps its own cell lists). Returns its index.
    pub(in crate::engine) fn push(
        &mut self,
        d: Dumbbell,
        center: Vector3<f64>,
        n: Vector3<f64>,
    ) -> usize {
        let len = d.rest_length(self.time);
        self.swimmers.push(d);
        self.base.push(center);
        let v = self.swimmer_model().initial_vector(&n, len);
        self.state
            .extend_from_slice(&[0.0, 0.0, 0.0, v.x, v.y, v.z]);
        self.origins.push(Origin {
            displacement: Vector3::zeros(),
            dir: v.normalize(),
        });
        self.swimmers.len() - 1
    }

    /// Where swimmer `i`'s displacement and orientation are measured from: its placement, or the
    /// last [`Scene::reset_origins`].
    pub fn origin(&self, i: usize) -> Result<Origin> {
        self.check_index(i)?;
        Ok(self.origins[i])
    }

    /// Measure every swimmer's displacement (`msd()`) and orientation autocorrelation from its
    /// state now, as if all were placed now: a run's transient left out of what is measured.
    pub fn reset_origins(&mut self) {
        for i in 0..self.count() {
            let k = STATE_PER_SWIMMER * i;
            self.origins[i] = Origin {
                displacement: vec3(&self.state, k),
                dir: vec3(&self.state, k + 3).normalize(),
            };
        }
    }

    /// Displacement of R_H of swimmer `i` since its origin ([`Scene::origin`]) (m).
    pub fn displacement_since_origin(&self, i: usize) -> Result<Vector3<f64>> {
        Ok(self.displacement(i)? - self.origins[i].displacement)
    }

    /// The length at which swimmer `d`'s spheres sit now: L(t), or ℓ in the averaged model, whose
    /// swimmers are stroke-averaged (its contact guard and steric repulsion use ℓ too).
    pub(in crate::engine) fn contact_length(&self, d: &Dumbbell) -> f64 {
        self.swimmer_model().contact_length(d, self.time)
    }

    /// Set the stroke phase φ of swimmer `i` (rad). Where the phase places the spheres (the
    /// rigid-stroke and averaged models), a phase that would put one into the wall is refused and
    /// the scene kept.
    pub fn set_phase(&mut self, i: usize, phase: f64) -> Result<()> {
        self.check_index(i)?;
        require_finite("phase", phase)?;
        let old = self.swimmers[i].phase;
        self.swimmers[i].phase = phase;
        self.keep_clear(|s| s.swimmers[i].phase = old)
    }

    /// All stroke phases φ (rad), in swimmer order.
    pub fn phases(&self) -> Vec<f64> {
        self.swimmers.iter().map(|d| d.phase).collect()
    }

    /// Set all stroke phases at once; the length must match the number of swimmers.
    pub fn set_phases(&mut self, phases: &[f64]) -> Result<()> {
        if phases.len() != self.swimmers.len() {
            return Err(invalid!(
                "phases: got {} values for {} swimmers; give one phase per swimmer",
                phases.len(),
                self.swimmers.len()
            ));
        }
        for (i, p) in phases.iter().enumerate() {
            require_finite(&format!("phases[{i}]"), *p)?;
        }
        let old = self.phases();
        for (d, p) in self.swimmers.iter_mut().zip(phases) {
            d.phase = *p;
        }
        self.keep_clear(|s| {
            for (d, p) in s.swimmers.iter_mut().zip(old) {
                d.phase = p;
            }
        })
    }

    /// Number of swimmers.
    pub fn count(&self) -> usize {
        self.swimmers.len()
    }

    /// The implementation of the model in use.
    pub(crate) fn swimmer_model(&self) -> &'static dyn SwimmerModel {
        models::of(self.model)
    }

    /// Number of spheres: the model's spheres per swimmer, swimmer by swimmer.
    pub fn sphere_count(&self) -> usize {
        self.swimmer_model().spheres_per_swimmer() * self.count()
    }

    /// The swimmer sphere `k` belongs to.
    pub(crate) fn owner(&self, k: usize) -> usize {
        k / self.swimmer_model().spheres_per_swimmer()
    }

    /// Current time (s).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// A 64-bit checksum (FNV-1a) of the time and every state value's bits: two runs that end
    /// with the same checksum ended, all but certainly, bit for bit alike.
    pub fn checksum(&self) -> u64 {
        std::iter::once(self.time)
            .chain(self.state.iter().copied())
            .flat_map(|v| v.to_bits().to_le_bytes())
            .fold(0xcbf2_9ce4_8422_2325_u64, |h, b| {
                (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
            })
    }

    /// Work counters accumulated over all runs.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// The parameters of swimmer `i`.
    pub fn swimmer(&self, i: usize) -> Result<&Dumbbell> {
        self.check_index(i)?;
        Ok(&self.swimmers[i])
    }

    /// All swimmers' parameters.
    pub fn swimmers(&self) -> &[Dumbbell] {
        &self.swimmers
    }

    pub(super) fn check_index(&self, i: usize) -> Result<()> {
        if i < self.swimmers.len() {
            Ok(())
        } else if self.swimmers.is_empty() {
            Err(invalid!(
                "swimmer index {i} is out of range: the scene has no swimmers"
            ))
        } else {
            Err(invalid!(
                "swimmer index {i} is out of range: the scene has {} swimmers (0 to {})",
                self.swimmers.len(),
                self.swimmers.len() - 1
            ))
        }
    }

    /// Hydrodynamic centre R_H of swimmer `i` (m).
    pub fn center(&self, i: usize) -> Result<Vector3<f64>> {
        self.check_index(i)?;
        Ok(self.base[i] + vec3(&self.state, STATE_PER_SWIMMER * i))
    }

    /// Displacement of R_H of swimmer `i` since its base position, without rounding against the
    /// absolute position (m).
    pub fn displacement(&self, i: usize) -> Result<Vector3<f64>> {
        self.check_index(i)?;
        Ok(vec3(&self.state, STATE_PER_SWIMMER * i))
    }

    /// Unit orientation N of swimmer `i` (from sphere a1 to sphere a2).
    pub fn dir(&self, i: usize) -> Result<Vector3<f64>> {
        self.check_index(i)?;
        Ok(vec3(&self.state, STATE_PER_SWIMMER * i + 3).normalize())
    }

    /// Current length |X₂ − X₁| of swimmer `i` (m); in the averaged model its rest length L(t).
    pub fn length(&self, i: usize) -> Result<f64> {
        self.check_index(i)?;
        let v = vec3(&self.state, STATE_PER_SWIMMER * i + 3);
        Ok(self
            .swimmer_model()
            .length(&self.swimmers[i], &v, self.time))
    }

    /// Sphere velocities (m/s) for given sphere forces (N), one per sphere, swimmer by swimmer
    /// (the a1 sphere first), with the scene's mobility and viscosity at the present sphere
    /// positions: v_α = F_α/(6πμa_α) + Σ_{β≠α} H_αβ F_β; in a box the periodic mobility (Ewald
    /// sums, no net flow). For checks against other codes.
    pub fn sphere_velocities(&self, forces: &[Vector3<f64>]) -> Result<Vec<Vector3<f64>>> {
        let n = self.sphere_count();
        if forces.len() != n {
            return Err(invalid!(
                "sphere velocities need one force per sphere: {n} for {} swimmers (two spheres each, the a1 sphere first), got {}",
                self.count(),
                forces.len()
            ));
        }
        if let Some(k) = forces.iter().position(|f| !f.iter().all(|x| x.is_finite())) {
            return Err(invalid!(
                "the force on sphere {k} is not finite ({:?}); give finite numbers",
                forces[k].as_slice()
            ));
        }
        let mut pos = Vec::with_capacity(n);
        let mut radii = Vec::with_capacity(n);
        for (i, d) in self.swimmers.iter().enumerate() {
            let (x1, x2) = self.spheres(i);
            pos.extend([x1, x2]);
            radii.extend([d.a1, d.a2]);
        }
        let mut v = vec![Vector3::zeros(); n];
        self.mobility_operator()?
            .interaction_velocities(&pos, &radii, forces, &mut v);
        for ((vi, f), a) in v.iter_mut().zip(forces).zip(&radii) {
            *vi += f * crate::engine::mobility::self_mobility(self.mu, *a);
        }
        Ok(v)
    }

    /// Sphere centres (X₁, X₂) of swimmer `i` (m); in the averaged model at rest length L(t).
    pub fn spheres(&self, i: usize) -> (Vector3<f64>, Vector3<f64>) {
        let d = &self.swimmers[i];
        let rh = self.base[i] + vec3(&self.state, STATE_PER_SWIMMER * i);
        let v = vec3(&self.state, STATE_PER_SWIMMER * i + 3);
        self.swimmer_model().sphere_positions(d, rh, v, self.time)
    }

    /// Sphere centres of swimmer `i` as shown (snapshots, trajectories): in a box moved with its
    /// R_H into the box, the swimmer kept whole (its spheres may reach over a face).
    pub fn shown_spheres(&self, i: usize) -> (Vector3<f64>, Vector3<f64>) {
        let (x1, x2) = self.spheres(i);
        let rh = self.base[i] + vec3(&self.state, STATE_PER_SWIMMER * i);
        let shift = self.shown(rh) - rh;
        (x1 + shift, x2 + shift)
    }
}
