//! The scene's settings: the fluid (viscosity, pair tensor, contacts), the model and its
//! coefficients, the averaged model's cutoff, the box's Ewald sums, thermal noise and the
//! backend.

use super::*;

impl Scene {
    /// Viscosity μ (Pa s).
    pub fn mu(&self) -> f64 {
        self.mu
    }

    /// Set the viscosity μ (Pa s).
    pub fn set_mu(&mut self, mu: f64) -> Result<()> {
        require_positive("mu", mu, "Pa s")?;
        self.mu = mu;
        Ok(())
    }

    /// The model in use.
    pub fn model(&self) -> Model {
        self.model
    }

    /// Switch the model, converting the state: micro → averaged keeps R_H and N of each dumbbell;
    /// averaged → micro rebuilds each dumbbell at its rest length L(t) of the current time.
    pub fn set_model(&mut self, model: Model) {
        if model == self.model {
            return;
        }
        let target = models::of(model);
        for (s, d) in self.swimmers.iter().enumerate() {
            let i = STATE_PER_SWIMMER * s + 3;
            let v = vec3(&self.state, i);
            let new = target.converted_vector(&v, d.rest_length(self.time));
            set_vec3(&mut self.state, i, &new);
        }
        self.model = model;
    }

    /// The mobility tensor of the microscopic model.
    pub fn mobility(&self) -> Mobility {
        self.mobility
    }

    /// Set the mobility tensor of the microscopic model.
    pub fn set_mobility(&mut self, m: Mobility) {
        self.mobility = m;
    }

    /// Coefficient set of the averaged model.
    pub fn coefficients(&self) -> Coefficients {
        self.coefficients
    }

    /// Set the coefficient set of the averaged model.
    pub fn set_coefficients(&mut self, c: Coefficients) {
        self.coefficients = c;
    }

    /// Contact handling: overlaps between swimmers and steric repulsion.
    pub fn contacts(&self) -> Contacts {
        self.contacts
    }

    /// Let spheres of different swimmers overlap (RPY's overlapping form) instead of stopping.
    pub fn set_allow_overlap(&mut self, allow: bool) {
        self.contacts.allow_overlap = allow;
    }

    /// What touching spheres of different swimmers do.
    pub fn set_overlaps(&mut self, o: Overlaps) {
        self.set_allow_overlap(o == Overlaps::Allow);
    }

    /// Switch the steric repulsion between swimmers on (`Some`) or off.
    pub fn set_steric(&mut self, steric: Option<Steric>) {
        self.contacts.steric = steric;
    }

    /// The averaged model's far-field cutoff (m), if any.
    pub fn cutoff(&self) -> Option<f64> {
        self.cutoff
    }

    /// Leave pairs further apart than `cutoff` (m) out of the averaged model's sums; `None`: keep
    /// every pair (the default). The error this makes is bounded in [`crate::engine::averaged::AveragedSystem`].
    pub fn set_cutoff(&mut self, cutoff: Option<f64>) -> Result<()> {
        if let Some(c) = cutoff {
            if !(c.is_finite() && c > 0.0) {
                return Err(invalid!(
                    "the cutoff must be a positive distance in m (e.g. 2e-4, twenty ell), got {c}; or none for every pair"
                ));
            }
        }
        self.cutoff = cutoff;
        Ok(())
    }

    /// Tolerance of the box's Ewald sums, relative to a sphere's Stokes mobility: the one set,
    /// or else the one that serves the run's integrator ([`ewald_tol_for`] its drift
    /// tolerance: a tenth of it, and [`crate::engine::ewald::DEFAULT_EWALD_TOL`] for fixed steps).
    pub fn ewald_tol(&self) -> f64 {
        self.ewald_tol
            .unwrap_or_else(|| ewald_tol_for(self.integrator().drift_tol()))
    }

    /// The Ewald tolerance set on this scene; `None` when it follows the run's integrator.
    pub fn ewald_tol_setting(&self) -> Option<f64> {
        self.ewald_tol
    }

    /// Set the tolerance of the box's Ewald sums (1e-15 to 1e-2), or `None` to follow the
    /// run's integrator again.
    pub fn set_ewald_tol(&mut self, tol: Option<f64>) -> Result<()> {
        if let Some(t) = tol {
            crate::engine::ewald::check_tol(t)?;
        }
        self.ewald_tol = tol;
        Ok(())
    }

    /// How the box's mobility products are summed: "auto", "beenakker" or "spectral".
    pub fn ewald_method(&self) -> EwaldMethod {
        self.ewald_method
    }

    /// Set how the box's mobility products are summed.
    pub fn set_ewald_method(&mut self, method: EwaldMethod) {
        self.ewald_method = method;
    }

    /// Temperature, noise seed and how the noise's square root is taken.
    pub fn thermal(&self) -> Thermal {
        self.thermal
    }

    /// Set the temperature (K); 0 turns thermal noise off.
    pub fn set_temperature(&mut self, kelvin: f64) -> Result<()> {
        self.thermal.temperature = Thermal::check_temperature(kelvin)?;
        Ok(())
    }

    /// Seed the noise: runs from the same state and seed draw the same noise.
    pub fn set_seed(&mut self, seed: u64) {
        self.thermal.seed = seed;
    }

    /// How √M·ξ is computed: dense Cholesky, Lanczos, or by size.
    pub fn set_noise_root(&mut self, root: NoiseRoot) {
        self.thermal.root = root;
    }

    /// The Lanczos iteration's tolerance.
    pub fn set_lanczos_tol(&mut self, tol: f64) -> Result<()> {
        self.thermal.lanczos_tol = Thermal::check_lanczos_tol(tol)?;
        Ok(())
    }

    /// Where the dynamics run.
    pub fn backend(&self) -> Backend {
        self.backend
    }

    /// Choose where the dynamics run (checked when the scene runs: see [`crate::engine::plan`]).
    pub fn set_backend(&mut self, b: Backend) {
        self.backend = b;
    }
}
