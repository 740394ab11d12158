//! The rigid-stroke limit of the microscopic model (k0 → ∞): each dumbbell's length follows
//! L(t) = ℓ + λ sin(ωt + φ) exactly, and the spring tensions become constraint forces.
//!
//! State per swimmer as in the averaged model: ΔR_H and unit N (the length is known). With
//! tension T_τ on dumbbell τ (force +T N on sphere 1, −T N on sphere 2), the velocity of every
//! sphere is linear in the tensions, and the constraint d(|X₂ − X₁|)/dt = L̇ for every dumbbell is an
//! S×S linear system A T = L̇ − N·(v^b₂ − v^b₁) with
//! A_στ = N_σ · [(H_{2σ,1τ} − H_{1σ,1τ}) − (H_{2σ,2τ} − H_{1σ,2τ})] N_τ,
//! where v^b = M F^b are the sphere velocities of the body forces (steric repulsion between
//! swimmers, a wall's repulsion, external forces; zero without them).
//! Then, as in the spring model, dR_H/dt = (a1 u₁ + a2 u₂)/(a1+a2) (the drag parts cancel exactly)
//! and dN/dt = (I − NNᵀ)(u₂ − u₁)/L, u the interaction velocities. Nothing is stiff any more: the
//! step is set by the stroke, not by the spring.
//!
//! A = −K with K = BᵀMB symmetric positive definite; how it is solved (elimination, or conjugate
//! gradients on a matrix or over mobility products, by boundary and size) is
//! [`super::tensions`].

use super::boundary::Boundary;
use super::contacts::Contacts;
use super::error::{self, unsupported, EngineError, Setting};
use super::integrators::{
    time_scale_of, IntegratorSpec, OdeSystem, Problem, Reach, DEFAULT_AUTO_TOL, DEFAULT_RIGID_RTOL,
};
use super::mobility::Mobility;
use super::model::{
    set_vec3, vec3, DeviceKernel, Model, SceneView, SwimmerModel, STATE_PER_SWIMMER,
};
use super::spheres::Spheres;
use super::swimmer::{shortest_period, Dumbbell};
use super::tensions::{tension_rtol_for, Tensions};
use nalgebra::{DVector, Vector3};

/// The rigid-stroke right-hand side with its scratch buffers.
#[derive(Debug, Clone)]
pub struct RigidSystem {
    swimmers: Vec<Dumbbell>,
    base: Vec<Vector3<f64>>,
    spheres: Spheres,
    /// The constraint solve, its scratch and earlier tensions.
    tensions: Tensions,
    /// The stroke rates less the body forces' part, then the tensions.
    rate: DVector<f64>,
    /// The orientations of the last placement.
    n: Vec<Vector3<f64>>,
    /// Scratch: the sphere velocities of the body forces alone.
    body: Vec<Vector3<f64>>,
    /// How far the centres may go (unbounded until set).
    reach: Reach,
}

impl RigidSystem {
    /// A system for these swimmers, base positions, viscosity and mobility, its spheres in
    /// contact as `contacts` says: overlaps allowed or not, and the steric repulsion between
    /// swimmers, a body force like a wall's repulsion (its velocities leave the tensions less of
    /// each stroke's rate to make up).
    pub fn new(
        swimmers: &[Dumbbell],
        base: &[Vector3<f64>],
        mu: f64,
        mobility: Mobility,
        contacts: Contacts,
    ) -> Self {
        let s = swimmers.len();
        RigidSystem {
            swimmers: swimmers.to_vec(),
            base: base.to_vec(),
            spheres: Spheres::new(swimmers, mu, mobility, contacts),
            tensions: Tensions::new(&Boundary::Open, s),
            rate: DVector::zeros(s),
            n: vec![Vector3::zeros(); s],
            body: Vec::new(),
            reach: Reach::default(),
        }
    }

    /// Hold the centres within `reach`: a step beyond it fails.
    pub fn set_reach(&mut self, reach: Reach) {
        self.reach = reach;
    }

    fn place(&mut self, t: f64, y: &[f64]) {
        for (s, d) in self.swimmers.iter().enumerate() {
            let rh = self.base[s] + vec3(y, STATE_PER_SWIMMER * s);
            let n = vec3(y, STATE_PER_SWIMMER * s + 3);
            let (x1, x2) = d.sphere_positions(rh, n, d.rest_length(t));
            self.spheres.pos[2 * s] = x1;
            self.spheres.pos[2 * s + 1] = x2;
        }
    }

    /// The constant external force on every sphere (N; none when empty).
    pub fn set_external(&mut self, external: Vec<Vector3<f64>>) {
        self.spheres.set_external(external);
    }

    /// Put the spheres in `boundary`, whose mobility is `operator` (open space until set).
    pub fn set_boundary(
        &mut self,
        boundary: Boundary,
        operator: Box<dyn crate::engine::mobility::MobilityOperator>,
    ) {
        let rtol = self.tensions.rtol();
        self.tensions = Tensions::new(&boundary, self.swimmers.len());
        self.tensions.set_rtol(rtol);
        self.spheres.set_boundary(boundary, operator);
    }

    /// Stop the tension iteration at residual `rtol` of the stroke rates
    /// ([`super::tensions::tension_rtol_for`] the run's step tolerance).
    pub fn set_tension_rtol(&mut self, rtol: f64) {
        self.tensions.set_rtol(rtol);
    }

    /// The constraint tensions at time `t` (N), in swimmer order.
    pub fn tensions(&mut self, t: f64, y: &[f64]) -> Vec<f64> {
        self.place(t, y);
        self.solve(t, y);
        self.rate.iter().copied().collect()
    }

    /// Fill `self.rate` with the tensions (solving A T = L̇).
    fn solve(&mut self, t: f64, y: &[f64]) {
        for (s, n) in self.n.iter_mut().enumerate() {
            *n = vec3(y, STATE_PER_SWIMMER * s + 3);
        }
        for (sg, d) in self.swimmers.iter().enumerate() {
            self.rate[sg] = d.lambda * d.omega * (d.omega * t + d.phase).cos();
        }
        // Body forces (steric repulsion, a wall's repulsion, external forces) move the spheres
        // too: the tensions make up what their velocities leave of L̇.
        if self.spheres.body_velocities(&mut self.body) {
            for (sg, ns) in self.n.iter().enumerate() {
                self.rate[sg] -= ns.dot(&(self.body[2 * sg + 1] - self.body[2 * sg]));
            }
        }
        self.tensions.solve(
            &mut self.spheres,
            &self.swimmers,
            &self.n,
            t,
            &mut self.rate,
        );
    }

    /// The tension solve's route and the mobility products its last solve took.
    pub fn tension_solver(&self) -> &Tensions {
        &self.tensions
    }
}

impl OdeSystem for RigidSystem {
    fn dim(&self) -> usize {
        STATE_PER_SWIMMER * self.swimmers.len()
    }

    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        self.place(t, y);
        self.solve(t, y);
        let tension = &self.rate;
        self.spheres
            .interact(|s| tension[s] * vec3(y, STATE_PER_SWIMMER * s + 3));
        for (s, d) in self.swimmers.iter().enumerate() {
            let n = vec3(y, STATE_PER_SWIMMER * s + 3);
            let drh = self.spheres.center_rate(s, d);
            let rel = self.spheres.relative_rate(s);
            let dn = (rel - n * n.dot(&rel)) / d.rest_length(t);
            set_vec3(dy, STATE_PER_SWIMMER * s, &drh);
            set_vec3(dy, STATE_PER_SWIMMER * s + 3, &dn);
        }
    }

    /// As the spring model: centres against the closest pair's drift scale, orientations against
    /// the stroke's relative size λ/ℓ.
    fn error_scale(&self, _y: &[f64], scale: &mut [f64]) {
        for (s, d) in self.swimmers.iter().enumerate() {
            let i = STATE_PER_SWIMMER * s;
            scale[i..i + 3].fill(d.drift_scale());
            scale[i + 3..i + 6].fill(d.stroke_scale() / d.ell);
        }
    }

    /// The shortest stroke period (0 without swimmers: no scale).
    fn time_scale(&self) -> f64 {
        time_scale_of(shortest_period(&self.swimmers))
    }

    /// Rejects centres beyond the reach and overlapping spheres.
    fn check(&mut self, t: f64, y: &[f64]) -> Result<(), Problem> {
        for (s, b) in self.base.iter().enumerate() {
            self.reach.check(s, &(b + vec3(y, STATE_PER_SWIMMER * s)))?;
        }
        self.place(t, y);
        match self.spheres.first_overlap() {
            Some(p) => Err(p),
            None => Ok(()),
        }
    }

    fn project(&self, y: &mut [f64]) {
        for s in 0..self.swimmers.len() {
            let i = STATE_PER_SWIMMER * s + 3;
            let n = vec3(y, i).normalize();
            set_vec3(y, i, &n);
        }
    }
}

/// The rigid-stroke model's answers to the model seam: its state holds the unit orientation N,
/// its constraint solve takes blocks (Beenakker's sums in a box) and dumbbell tensions only, and
/// it runs on the CPU.
#[derive(Debug, Clone, Copy, Default)]
pub struct RigidStrokes;

/// The rigid-stroke system of scene `s`: the one every run and the tensions use.
fn rigid_system(s: &dyn SceneView) -> error::Result<RigidSystem> {
    let mut sys = RigidSystem::new(s.swimmers(), s.base(), s.mu(), s.mobility(), s.contacts());
    // Products by the scene's Ewald method; blocks (a few swimmers' elimination) are
    // Beenakker's sums whatever it is.
    sys.set_boundary(*s.boundary(), s.mobility_operator_by(s.ewald_method())?);
    sys.set_external(s.sphere_forces());
    sys.set_reach(s.reach());
    sys.set_tension_rtol(tension_rtol_for(step_tol(s)));
    Ok(sys)
}

/// The relative tolerance of the adaptive method that steps scene `s`'s rigid model: the
/// integrator's own, or for stroboscopic averaging (`auto` among it) its inner method's;
/// `None` for fixed steps.
fn step_tol(s: &dyn SceneView) -> Option<f64> {
    let inner = match s.integrator() {
        IntegratorSpec::Auto { tol } | IntegratorSpec::Stroboscopic { tol, inner: None } => {
            RigidStrokes.stroboscopic_inner(s, tol)
        }
        IntegratorSpec::Stroboscopic {
            inner: Some(inner), ..
        } => inner.into(),
        spec => spec,
    };
    match inner {
        IntegratorSpec::Dopri5 { rtol } | IntegratorSpec::Rosw { rtol } => Some(rtol),
        _ => None,
    }
}

impl SwimmerModel for RigidStrokes {
    fn choice(&self) -> Model {
        Model::Rigid
    }

    fn system(&self, s: &dyn SceneView) -> error::Result<Box<dyn OdeSystem>> {
        Ok(Box::new(rigid_system(s)?))
    }

    /// The constraint tension of the S×S solve.
    fn tension(&self, s: &dyn SceneView, i: usize) -> error::Result<f64> {
        Ok(rigid_system(s)?.tensions(s.time(), s.state())[i])
    }

    fn default_integrator(&self, _s: &dyn SceneView) -> IntegratorSpec {
        IntegratorSpec::Auto {
            tol: DEFAULT_AUTO_TOL,
        }
    }

    /// Its default: the model refuses noise when it runs.
    fn default_noisy_integrator(&self, _s: &dyn SceneView) -> IntegratorSpec {
        IntegratorSpec::Dopri5 {
            rtol: DEFAULT_RIGID_RTOL,
        }
    }

    /// dopri5 a hundred times tighter than `tol` (its step choice makes the map only piecewise
    /// smooth, at the level of its tolerance).
    fn stroboscopic_inner(&self, _s: &dyn SceneView, tol: f64) -> IntegratorSpec {
        IntegratorSpec::Dopri5 {
            rtol: (tol * 1e-2).clamp(1e-12, DEFAULT_RIGID_RTOL),
        }
    }

    fn refuses_noise(&self, t: f64) -> Option<EngineError> {
        Some(unsupported(
            format!("thermal noise (temperature {t} K) is not available in the rigid-stroke model: Brownian motion under a rigid constraint needs the metric (Fixman) drift, which changes the equilibrium this model would sample"),
            &[Setting::Model("micro"), Setting::Model("averaged"), Setting::NoNoise],
        ))
    }

    fn device_kernel(&self) -> std::result::Result<DeviceKernel, (&'static str, &'static str)> {
        Err((
            "the rigid-stroke model",
            "its per-swimmer stroke solve has no GPU kernel",
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::contacts::{Steric, StericBody, StericLaw};
    use crate::engine::integrators::{Dopri5, Stats, Stepper};
    use crate::engine::tensions::{tension_rtol_for, Route, TENSION_RTOL};

    /// 16 of the density study's swimmers (a1 = 0.225ℓ, a2 = a1/2) in open space, as 8 side by
    /// side pairs whose big spheres start 0.3 µm apart, inside the study's rod repulsion (0.5
    /// µm, 1e-3 N/m, smooth), the pairs 3ℓ apart on a cube's corners, tilted and phased apart,
    /// integrated over 0.2 period by Dormand-Prince at `rtol`, their tensions iterated to
    /// `tension_rtol`: the final state, the right-hand sides taken and the error scale.
    fn run(rtol: f64, tension_rtol: f64) -> (Vec<f64>, u64, Vec<f64>) {
        let d = Dumbbell {
            a1: 1.125e-6,
            a2: 0.5625e-6,
            ..Dumbbell::default()
        };
        let (mut swimmers, mut base, mut y) = (Vec::new(), Vec::new(), Vec::new());
        for k in 0..8 {
            let corner = Vector3::new((k & 1) as f64, ((k >> 1) & 1) as f64, (k >> 2) as f64);
            let tilt = 0.1 * k as f64;
            let n = Vector3::new(tilt.cos(), 0.0, tilt.sin());
            for (side, phase) in [(-0.5, 0.3 * k as f64), (0.5, 0.3 * k as f64 + 1.9)] {
                swimmers.push(Dumbbell { phase, ..d });
                base.push(corner * 3.0 * d.ell + Vector3::y() * side * (2.0 * d.a1 + 0.3e-6));
                y.extend([0.0, 0.0, 0.0, n.x, n.y, n.z]);
            }
        }
        let steric = Steric::new(0.5e-6, 1e-3)
            .unwrap()
            .with_body(StericBody::Rods)
            .with_law(StericLaw::Smooth);
        let contacts = Contacts {
            allow_overlap: true,
            steric: Some(steric),
        };
        let mut sys = RigidSystem::new(&swimmers, &base, 1e-3, Mobility::Rpy, contacts);
        sys.set_tension_rtol(tension_rtol);
        assert!(matches!(sys.tension_solver().route(), Route::Pairs));
        let mut stepper = Dopri5::new(rtol);
        let mut stats = Stats::default();
        let (mut t, end) = (0.0, 0.2 * shortest_period(&swimmers));
        while t < end {
            t = stepper.step(&mut sys, t, &mut y, end, &mut stats).unwrap();
        }
        assert!(!sys.tension_solver().fell_back());
        let mut scale = vec![0.0; y.len()];
        sys.error_scale(&y, &mut scale);
        (y, stats.rhs_evals, scale)
    }

    /// The tension iteration stopped by the run's tolerance ([`tension_rtol_for`]: 1e-10 for
    /// Dormand-Prince at 1e-7) against the tight solve, on swimmers in contact: the same
    /// right-hand sides within 5% (a residual rough at the step estimate's level shortens the
    /// steps: at 10 times the step tolerance a box run took 1.46 times as many) and a state, in
    /// units of the run's error scale, off the tight run's by at most a fifth of that run's own
    /// error against dopri5(1e-10) (measured: 0.07). A rule a hundred times looser adds more
    /// than the run's own error (measured: 4.5 times), so the margin is needed.
    #[test]
    fn the_tension_rule_costs_the_run_no_accuracy_and_no_steps() {
        let rule = tension_rtol_for(Some(1e-7));
        assert_eq!(rule, 1e-10);
        assert_eq!(tension_rtol_for(None), TENSION_RTOL);
        let (reference, _, scale) = run(1e-10, TENSION_RTOL);
        let (tight, tight_rhs, _) = run(1e-7, TENSION_RTOL);
        let (loose, loose_rhs, _) = run(1e-7, rule);
        let (looser, _, _) = run(1e-7, 100.0 * rule);
        // The largest component error in units of the error scale.
        let dist = |a: &[f64], b: &[f64]| {
            (0..a.len())
                .map(|i| ((a[i] - b[i]) / scale[i]).abs())
                .fold(0.0, f64::max)
        };
        let own = dist(&tight, &reference);
        let added = dist(&loose, &tight);
        assert!(own > 0.0, "the run has no error to compare with");
        assert!(
            added <= 0.2 * own,
            "the rule's solve added {added:e} to a run error of {own:e}"
        );
        assert!(
            dist(&looser, &tight) > own,
            "a hundred times looser adds less than the run's error: the test cannot tell"
        );
        assert!(
            (loose_rhs as f64) <= 1.05 * tight_rhs as f64,
            "{loose_rhs} right-hand sides against {tight_rhs}"
        );
    }
}
