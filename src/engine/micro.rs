//! The microscopic model (e:langevin, e:Mazur, e:swimmer_potential): spheres moved by spring forces
//! through the mobility, dX_α/dt = Σ_β H_αβ F_β.
//!
//! In the state variables of [`super::model`] (ΔR_H and b = X₂ − X₁ per dumbbell), with interaction
//! velocities u_α = Σ_{β≠α} H_αβ F_β and spring force f = k0 (|b| − L) b̂ on sphere 1 (−f on sphere 2):
//! - dR_H/dt = (a1 u₁ + a2 u₂)/(a1+a2): the Stokes-drag parts a_α F_α/(6πμa_α) cancel exactly
//!   because the dumbbell is force-free, so they are never added (no cancellation in floating point);
//! - db/dt = −f (1/γ₁ + 1/γ₂) + u₂ − u₁, γ = 6πμa.

use super::boundary::Boundary;
use super::contacts::Contacts;
use super::error::{self, invalid};
use super::integrators::{
    noisy_euler, time_scale_of, IntegratorSpec, Noise, OdeSystem, Problem, Reach, DEFAULT_AUTO_TOL,
};
use super::mobility::{self_mobility, Mobility};
use super::model::{
    set_vec3, vec3, DeviceKernel, Model, SceneView, SwimmerModel, STATE_PER_SWIMMER,
};
use super::spheres::Spheres;
use super::swimmer::{shortest_period, Dumbbell};
use super::thermal::{lanczos, NoiseRoot, Thermal};
use nalgebra::{DMatrix, Vector3};

/// The microscopic right-hand side with its scratch buffers.
#[derive(Debug, Clone)]
pub struct MicroSystem {
    swimmers: Vec<Dumbbell>,
    base: Vec<Vector3<f64>>,
    spheres: Spheres,
    /// Thermal noise, if the temperature is above 0.
    thermal: Option<Thermal>,
    /// Sphere displacements of one step's noise (scratch, 3 per sphere).
    kicks: Vec<f64>,
    /// The rest lengths L(t) at the time `rest_t`: stages share times (RK4's middle two, a step's
    /// end and the next one's start), and the sine is a sizeable part of a small scene's rates.
    rest: Vec<f64>,
    rest_t: f64,
    /// How far the centres may go (unbounded until set).
    reach: Reach,
}

impl MicroSystem {
    /// A system for these swimmers, base positions, viscosity and mobility.
    pub fn new(
        swimmers: &[Dumbbell],
        base: &[Vector3<f64>],
        mu: f64,
        mobility: Mobility,
        contacts: Contacts,
    ) -> Self {
        MicroSystem {
            swimmers: swimmers.to_vec(),
            base: base.to_vec(),
            spheres: Spheres::new(swimmers, mu, mobility, contacts),
            thermal: None,
            kicks: Vec::new(),
            rest: swimmers.iter().map(|d| d.rest_length(0.0)).collect(),
            rest_t: 0.0,
            reach: Reach::default(),
        }
    }

    /// Hold the centres within `reach`: a step beyond it fails.
    pub fn set_reach(&mut self, reach: Reach) {
        self.reach = reach;
    }

    /// Bring the rest lengths to time `t`.
    fn rest_at(&mut self, t: f64) {
        if t.to_bits() != self.rest_t.to_bits() {
            for (l, d) in self.rest.iter_mut().zip(&self.swimmers) {
                *l = d.rest_length(t);
            }
            self.rest_t = t;
        }
    }

    /// Put the spheres in `boundary`, whose mobility is `operator` (open space until set). The
    /// stiff own-pair rates behind rosw's Jacobian stay open space's: a W-method needs only an
    /// approximate Jacobian, and a box longer than the swimmer changes the own pair little.
    pub fn set_boundary(
        &mut self,
        boundary: Boundary,
        operator: Box<dyn crate::engine::mobility::MobilityOperator>,
    ) {
        self.spheres.set_boundary(boundary, operator);
    }

    /// The constant external force on every sphere (N; none when empty).
    pub fn set_external(&mut self, external: Vec<Vector3<f64>>) {
        self.spheres.set_external(external);
    }

    /// Thermal noise at `thermal`'s temperature (none at 0 K).
    pub fn set_thermal(&mut self, thermal: Thermal) {
        self.thermal = thermal.is_on().then_some(thermal);
    }

    /// The full mobility matrix at the current sphere positions and its Cholesky factor L.
    fn mobility_factor(&self) -> Result<DMatrix<f64>, Problem> {
        let m = self.spheres.mobility_matrix();
        m.cholesky().map(|c| c.unpack()).ok_or_else(not_positive)
    }

    /// Sphere displacements `dx` (flat, 3 per sphere) as state increments, scaled by `scale`, given
    /// to `add(state index, increment)`: ΔR_H = w1 Δx₁ + w2 Δx₂, Δb = Δx₂ − Δx₁.
    fn to_state(&self, dx: impl Fn(usize) -> f64, scale: f64, mut add: impl FnMut(usize, f64)) {
        for (s, d) in self.swimmers.iter().enumerate() {
            for k in 0..3 {
                let (x1, x2) = (dx(6 * s + k), dx(6 * s + 3 + k));
                add(
                    STATE_PER_SWIMMER * s + k,
                    scale * (d.w1() * x1 + d.w2() * x2),
                );
                add(STATE_PER_SWIMMER * s + 3 + k, scale * (x2 - x1));
            }
        }
    }
}

/// The mobility matrix has no Cholesky factor or square root.
fn not_positive() -> Problem {
    Problem {
        swimmer: None,
        cause: "the mobility matrix is not positive definite here, so thermal noise has no square root (the Oseen tensor loses definiteness when spheres come within about 1.5 radii)".into(),
        hint: "use the rpy mobility, which stays positive definite for any positions".into(),
        fixes: vec![crate::engine::error::Setting::Mobility("rpy")],
    }
}

impl MicroSystem {
    /// Place the spheres at the state `y`.
    fn place(&mut self, y: &[f64]) {
        for (s, d) in self.swimmers.iter().enumerate() {
            let rh = self.base[s] + vec3(y, STATE_PER_SWIMMER * s);
            let b = vec3(y, STATE_PER_SWIMMER * s + 3);
            self.spheres.pos[2 * s] = rh - d.w2() * b;
            self.spheres.pos[2 * s + 1] = rh + d.w1() * b;
        }
    }
}

impl MicroSystem {
    /// The rates of dumbbell `d` alone with vector `b` at time `t`: its spring, its drag and its
    /// own spheres' hydrodynamic interaction: the stiff part of the dynamics. With f the force on
    /// sphere 1 and H = H₁₂(b): dR_H/dt = (w2 − w1) H f, db/dt = −(1/γ1 + 1/γ2) f + 2 H f.
    fn own_rates(&self, d: &Dumbbell, t: f64, b: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
        let len = b.norm();
        let f = d.k0 * (len - d.rest_length(t)) / len * b;
        let sp = &self.spheres;
        let hf = sp.mobility.pair_apply(sp.mu, b, d.a1, d.a2, &f);
        let drag = self_mobility(sp.mu, d.a1) + self_mobility(sp.mu, d.a2);
        ((d.w2() - d.w1()) * hf, -drag * f + 2.0 * hf)
    }
}

impl OdeSystem for MicroSystem {
    fn dim(&self) -> usize {
        STATE_PER_SWIMMER * self.swimmers.len()
    }

    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        self.rest_at(t);
        self.place(y);
        let (swimmers, rest) = (&self.swimmers, &self.rest);
        self.spheres.interact(|s| {
            let b = vec3(y, STATE_PER_SWIMMER * s + 3);
            let len = b.norm();
            swimmers[s].k0 * (len - rest[s]) / len * b
        });
        if let Some(th) = self.thermal {
            self.spheres.add_thermal_drift(th.kt());
        }
        let sp = &self.spheres;
        for (s, d) in self.swimmers.iter().enumerate() {
            let drag = self_mobility(sp.mu, d.a1) + self_mobility(sp.mu, d.a2);
            let drh = sp.center_rate(s, d);
            let db = -drag * sp.force(s) + sp.relative_rate(s);
            set_vec3(dy, STATE_PER_SWIMMER * s, &drh);
            set_vec3(dy, STATE_PER_SWIMMER * s + 3, &db);
        }
    }

    /// The fast variable of a dumbbell is its length |b| (the spring relaxes at
    /// [`Dumbbell::relaxation_rate`]); its centre R_H and direction b̂ are slow.
    fn fast_variables(&self, y: &[f64], out: &mut Vec<f64>) {
        for s in 0..self.swimmers.len() {
            out.push(vec3(y, STATE_PER_SWIMMER * s + 3).norm());
        }
    }

    fn set_fast_variables(&self, y: &mut [f64], fast: &[f64]) {
        for (s, &len) in fast.iter().enumerate() {
            let i = STATE_PER_SWIMMER * s + 3;
            let b = vec3(y, i);
            let now = b.norm();
            if now > 0.0 && now.is_finite() && len > 0.0 {
                set_vec3(y, i, &(b * (len / now)));
            }
        }
    }

    fn jacobian_block(&self) -> usize {
        STATE_PER_SWIMMER
    }

    /// Per dumbbell, ∂(own rates)/∂(ΔR_H, b) by central differences: the own rates do not depend on
    /// the position (columns 0-2 vanish); the b columns carry the spring's stiffness.
    fn jacobian_blocks(&mut self, t: f64, y: &[f64], out: &mut [f64]) {
        let n = STATE_PER_SWIMMER;
        out.fill(0.0);
        for (s, d) in self.swimmers.iter().enumerate() {
            let b = vec3(y, n * s + 3);
            let delta = 1e-6 * b.norm();
            let block = &mut out[s * n * n..(s + 1) * n * n];
            for q in 0..3 {
                let mut e = Vector3::zeros();
                e[q] = delta;
                let (rp, bp) = self.own_rates(d, t, &(b + e));
                let (rm, bm) = self.own_rates(d, t, &(b - e));
                for r in 0..3 {
                    block[r * n + 3 + q] = (rp[r] - rm[r]) / (2.0 * delta);
                    block[(r + 3) * n + 3 + q] = (bp[r] - bm[r]) / (2.0 * delta);
                }
            }
        }
    }

    /// The dumbbell vector is measured against the stroke λ (its oscillation), the centre against
    /// the drift scale λ(λ/ℓ)²(Λ/ℓ) ([`Dumbbell::drift_scale`]).
    fn error_scale(&self, _y: &[f64], scale: &mut [f64]) {
        for (s, d) in self.swimmers.iter().enumerate() {
            let i = STATE_PER_SWIMMER * s;
            scale[i..i + 3].fill(d.drift_scale());
            scale[i + 3..i + 6].fill(d.stroke_scale());
        }
    }

    fn noise(&self) -> Option<Noise> {
        self.thermal.map(|th| Noise {
            seed: th.seed,
            dim: 6 * self.swimmers.len(),
        })
    }

    /// The spheres move by √(2kT)·B·dw with B Bᵀ = M: B the Cholesky factor, or √M through the
    /// Lanczos iteration on the pair kernel (large scenes, see [`Thermal::root`]).
    fn add_noise(
        &mut self,
        _t: f64,
        y: &[f64],
        dw: &[f64],
        y_new: &mut [f64],
    ) -> Result<(), Problem> {
        let Some(th) = self.thermal else {
            return Ok(());
        };
        self.place(y);
        let scale = (2.0 * th.kt()).sqrt();
        let n = dw.len();
        if th.root.dense_for(self.spheres.pos.len()) {
            let l = self.mobility_factor()?;
            let dx = l * nalgebra::DVector::from_column_slice(dw);
            self.to_state(|i| dx[i], scale, |i, v| y_new[i] += v);
            return Ok(());
        }
        let mut kicks = std::mem::take(&mut self.kicks);
        kicks.resize(n, 0.0);
        let spheres = &mut self.spheres;
        let mut apply = |v: &[f64], out: &mut [f64]| spheres.apply_mobility(v, out);
        let outcome = lanczos::sqrt_times(&mut apply, dw, th.lanczos_tol, &mut kicks);
        let result = match outcome {
            Ok(_) => {
                self.to_state(|i| kicks[i], scale, |i, v| y_new[i] += v);
                Ok(())
            }
            Err(lanczos::LanczosFailure::NotPositive(_)) => Err(not_positive()),
            Err(lanczos::LanczosFailure::NoConvergence { steps, change }) => Err(Problem {
                swimmer: None,
                cause: format!("the Lanczos square root of the mobility did not converge in {steps} steps (last change {change:.1e})"),
                hint: "loosen the Lanczos tolerance, or take the Cholesky noise root on a small scene".into(),
                fixes: Vec::new(),
            }),
        };
        self.kicks = kicks;
        result
    }

    /// √(2kT)·T·L: the Cholesky factor L of M mapped to the state (R_H and b of each dumbbell).
    fn diffusion(&mut self, _t: f64, y: &[f64], b: &mut DMatrix<f64>) -> Result<(), Problem> {
        let Some(th) = self.thermal else {
            b.fill(0.0);
            return Ok(());
        };
        self.place(y);
        let l = self.mobility_factor()?;
        let scale = (2.0 * th.kt()).sqrt();
        for col in 0..l.ncols() {
            self.to_state(|i| l[(i, col)], scale, |i, v| b[(i, col)] = v);
        }
        Ok(())
    }

    /// The shortest stroke period (0 without swimmers: no scale).
    fn time_scale(&self) -> f64 {
        time_scale_of(shortest_period(&self.swimmers))
    }

    /// Rejects overlapping spheres, centres beyond the reach, and springs stretched or compressed
    /// by more than half a body length beyond their rest length: a stiff spring follows L(t)
    /// within ~λω/rate ≈ 1e-3 λ, so such a deviation is a numerical instability (explicit steps
    /// above the stability limit grow the spring mode geometrically), never physics.
    fn check(&mut self, t: f64, y: &[f64]) -> Result<(), Problem> {
        self.rest_at(t);
        for (s, d) in self.swimmers.iter().enumerate() {
            let len = vec3(y, STATE_PER_SWIMMER * s + 3).norm();
            let dev = len - self.rest[s];
            if dev.abs() > 0.5 * d.ell {
                return Err(Problem {
                    swimmer: Some(s),
                    cause: format!(
                        "the spring of swimmer {s} is {} by {:.3e} ell beyond its rest length (unstable step)",
                        if dev > 0.0 { "stretched" } else { "compressed" },
                        dev.abs() / d.ell
                    ),
                    hint: format!(
                        "use a smaller time step: explicit methods need dt below ~2.8/rate = {:.3e} s here (rate: the scene's stiff rate)",
                        2.785 / d.relaxation_rate(self.spheres.mu)
                    ),
                    fixes: vec![crate::engine::error::Setting::DefaultIntegrator],
                });
            }
        }
        for (s, b) in self.base.iter().enumerate() {
            self.reach.check(s, &(b + vec3(y, STATE_PER_SWIMMER * s)))?;
        }
        self.place(y);
        match self.spheres.first_overlap() {
            Some(p) => Err(p),
            None => Ok(()),
        }
    }
}

/// The spring model's answers to the model seam: its state holds the dumbbell vector
/// b = X₂ − X₁, the springs are stiff, and the device runs it.
#[derive(Debug, Clone, Copy, Default)]
pub struct Springs;

impl SwimmerModel for Springs {
    fn choice(&self) -> Model {
        Model::Micro
    }

    fn initial_vector(&self, n: &Vector3<f64>, len: f64) -> Vector3<f64> {
        n * len
    }

    fn converted_vector(&self, v: &Vector3<f64>, len: f64) -> Vector3<f64> {
        v * len
    }

    fn check_vector(&self, i: usize, v: &Vector3<f64>) -> error::Result<()> {
        if v.norm() <= 0.0 {
            return Err(invalid!(
                "swimmer {i}: its dumbbell vector X2 - X1 is zero; a dumbbell needs two distinct spheres"
            ));
        }
        Ok(())
    }

    fn length(&self, _d: &Dumbbell, v: &Vector3<f64>, _t: f64) -> f64 {
        v.norm()
    }

    fn sphere_positions(
        &self,
        d: &Dumbbell,
        rh: Vector3<f64>,
        v: Vector3<f64>,
        _t: f64,
    ) -> (Vector3<f64>, Vector3<f64>) {
        (rh - d.w2() * v, rh + d.w1() * v)
    }

    /// The orientation's spin from b's rate: its part across b, over |b|.
    fn spin(&self, v: &Vector3<f64>, w: Vector3<f64>) -> Vector3<f64> {
        let n = v.normalize();
        (w - n * n.dot(&w)) / v.norm()
    }

    fn system(&self, s: &dyn SceneView) -> error::Result<Box<dyn OdeSystem>> {
        let mut sys = MicroSystem::new(s.swimmers(), s.base(), s.mu(), s.mobility(), s.contacts());
        sys.set_thermal(s.thermal());
        sys.set_boundary(*s.boundary(), s.mobility_operator_by(s.ewald_method())?);
        sys.set_external(s.sphere_forces());
        sys.set_reach(s.reach());
        Ok(Box::new(sys))
    }

    /// The spring tension k0 (|b| − L).
    fn tension(&self, s: &dyn SceneView, i: usize) -> error::Result<f64> {
        let d = &s.swimmers()[i];
        let len = vec3(s.state(), STATE_PER_SWIMMER * i + 3).norm();
        Ok(d.k0 * (len - d.rest_length(s.time())))
    }

    /// `auto(tol)` at [`DEFAULT_AUTO_TOL`]; on the gpu backend, which steps the explicit
    /// methods only, RK4 at the default step.
    fn default_integrator(&self, s: &dyn SceneView) -> IntegratorSpec {
        if s.on_gpu() {
            IntegratorSpec::Rk4 {
                dt: s.facts().rk4_step(),
            }
        } else {
            IntegratorSpec::Auto {
                tol: DEFAULT_AUTO_TOL,
            }
        }
    }

    fn default_noisy_integrator(&self, s: &dyn SceneView) -> IntegratorSpec {
        noisy_euler(s.facts().noisy_spring_step())
    }

    /// RK4 at the step of the tolerance, or rosw where the springs are stiff.
    fn stroboscopic_inner(&self, s: &dyn SceneView, tol: f64) -> IntegratorSpec {
        let facts = s.facts();
        if facts.stiff() {
            IntegratorSpec::Rosw {
                rtol: (tol * 1e-2).clamp(1e-12, 1e-6),
            }
        } else {
            facts.rk4_inner(tol)
        }
    }

    fn settling_periods(&self, s: &dyn SceneView, period: f64) -> u32 {
        s.facts().spring_settling_periods(period)
    }

    fn dense_noise_spheres(&self, root: NoiseRoot, swimmers: usize) -> Option<usize> {
        let spheres = self.spheres_per_swimmer() * swimmers;
        root.dense_for(spheres).then_some(spheres)
    }

    fn device_kernel(&self) -> std::result::Result<DeviceKernel, (&'static str, &'static str)> {
        Ok(DeviceKernel::Springs)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fast_variables_are_the_lengths() {
        let swimmers = vec![Dumbbell::default(); 2];
        let base = vec![Vector3::zeros(); 2];
        let sys = MicroSystem::new(&swimmers, &base, 1e-3, Mobility::Rpy, Contacts::default());
        let mut y = [1.5, 2.5, 3.5, 6.0, 8.0, 0.0, 4.0, 5.0, 6.0, 0.0, 0.0, 2.0];
        let mut fast = Vec::new();
        sys.fast_variables(&y, &mut fast);
        assert_eq!(fast, [10.0, 2.0]);
        // Setting the lengths keeps centres and directions.
        sys.set_fast_variables(&mut y, &[5.0, 8.0]);
        assert_eq!(
            y,
            [1.5, 2.5, 3.5, 3.0, 4.0, 0.0, 4.0, 5.0, 6.0, 0.0, 0.0, 8.0]
        );
    }
}
