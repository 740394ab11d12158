//! What the models say about a scene's current state: tensions and rates, and
//! the right-hand side ([`OdeSystem`]) of the chosen model that every run and query uses.

use super::*;

impl Scene {
    /// Spring tension k0 (d − L) of swimmer `i` (N), or the constraint tension in the rigid-stroke
    /// model; positive when the spring pulls the spheres together.
    pub fn tension(&self, i: usize) -> Result<f64> {
        self.check_index(i)?;
        match self.model {
            Model::Micro => {
                let d = &self.swimmers[i];
                Ok(d.k0 * (self.length(i)? - d.rest_length(self.time)))
            }
            Model::Rigid => {
                let mut sys = RigidSystem::new(
                    &self.swimmers,
                    &self.base,
                    self.mu,
                    self.mobility,
                    self.contacts.allow_overlap,
                );
                Ok(sys.tensions(self.time, &self.state)[i])
            }
            Model::Averaged => Err(unsupported(
                format!("tension({i}) does not exist in the averaged model (it has no springs)"),
                &[Setting::Model("micro"), Setting::Model("rigid")],
            )),
        }
    }

    /// Right-hand side at the current state: (dR_H/dt in m/s, dN/dt in 1/s) of swimmer `i`.
    pub fn rates(&self, i: usize) -> Result<(Vector3<f64>, Vector3<f64>)> {
        self.check_index(i)?;
        let mut sys = self.system()?;
        let mut dy = vec![0.0; self.state.len()];
        sys.rhs(self.time, &self.state, &mut dy);
        let k = STATE_PER_SWIMMER * i;
        let v = vec3(&dy, k);
        let w = vec3(&dy, k + 3);
        let spin = match self.model {
            Model::Averaged | Model::Rigid => w,
            Model::Micro => {
                let b = vec3(&self.state, k + 3);
                let n = b.normalize();
                (w - n * n.dot(&w)) / b.norm()
            }
        };
        Ok((v, spin))
    }

    /// The state vector (see [`super::model`]) and the base positions: for tests and savers.
    pub fn raw_state(&self) -> (&[f64], &[Vector3<f64>]) {
        (&self.state, &self.base)
    }

    pub(crate) fn system(&self) -> Result<Box<dyn OdeSystem>> {
        Ok(match self.model {
            Model::Micro => Box::new(MicroSystem::new(
                &self.swimmers,
                &self.base,
                self.mu,
                self.mobility,
                self.contacts,
            )),
            Model::Rigid => {
                if self.contacts.steric.is_some() {
                    return Err(unsupported(
                        "steric repulsion is not available in the rigid-stroke model (its constraint solve takes dumbbell tensions only)",
                        &[Setting::Model("micro"), Setting::Model("averaged"), Setting::NoSteric],
                    ));
                }
                Box::new(RigidSystem::new(
                    &self.swimmers,
                    &self.base,
                    self.mu,
                    self.mobility,
                    self.contacts.allow_overlap,
                ))
            }
            Model::Averaged => {
                self.check_averaged()?;
                let mut sys =
                    AveragedSystem::new(&self.swimmers, &self.base, self.coefficients, &self.state);
                sys.set_cutoff(self.cutoff);
                sys.set_contacts(self.contacts, self.mu);
                Box::new(sys)
            }
        })
    }

    /// The averaged equations describe identical strokes: ω, λ and ℓ must agree.
    pub(crate) fn check_averaged(&self) -> Result<()> {
        if let Some(first) = self.swimmers.first() {
            for (i, d) in self.swimmers.iter().enumerate() {
                if d.omega != first.omega || d.lambda != first.lambda || d.ell != first.ell {
                    return Err(unsupported(
                        format!("the averaged model needs equal omega, lambda and ell for all swimmers (swimmer {i} differs from swimmer 0)"),
                        &[Setting::Model("micro")],
                    ));
                }
            }
        }
        Ok(())
    }
}
