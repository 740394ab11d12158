//! The stroke-averaged model (e:eom … e:eom_last): each swimmer is its hydrodynamic centre R_H and
//! unit orientation N, moved by the pairwise I, J, K, L terms:
//!
//! dR_H^σ/dt = A_R Σ_ρ I^σρ + c_J Σ_ρ J^σρ,   dN^σ/dt = −(1 − N^σN^σᵀ)(A_N Σ_ρ K^σρ + Σ_ρ L^σρ).
//!
//! With the "paper" coefficients A_R = (a2²−a1²)/(a1²+a2²) and c_J = 1; with "leading_order" ones
//! A_R = (a2−a1)/(a1+a2) and c_J = 4a1a2/(a1+a2)². A_N = (a2−a1)/(a1+a2) in both. The terms use
//! the parameters of the swimmer being moved (σ); the model assumes equal ω, λ, ℓ (the scene checks).
//!
//! What a scene does not need is skipped: pairs with sin(φσ−φρ) = 0, the I and K terms of symmetric
//! swimmers, and for an aligned scene the 3D algebra (the 1D reduction e:stroke_averaged).

use super::integrators::{OdeSystem, Problem};
use super::model::{set_vec3, vec3, Coefficients, STATE_PER_SWIMMER};
use super::swimmer::Dumbbell;
use nalgebra::Vector3;

/// |sin(Δφ)| below this counts as zero: phases given as 0 and π differ by rounding only.
const SIN_ZERO: f64 = 1e-14;

/// Which shortcuts the averaged model may take. All are exact (they skip terms that are zero or
/// evaluate the same algebra in 1D); switching them off is for tests that prove it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shortcuts {
    /// Leave out pairs with sin(φσ − φρ) = 0.
    pub skip_zero_phase_pairs: bool,
    /// Leave out the I and K terms of symmetric swimmers (A_R = A_N = 0).
    pub skip_symmetric_terms: bool,
    /// Use the 1D reduction (e:stroke_averaged) when every centre and orientation is on one line.
    pub aligned_1d: bool,
}

impl Default for Shortcuts {
    fn default() -> Self {
        Shortcuts {
            skip_zero_phase_pairs: true,
            skip_symmetric_terms: true,
            aligned_1d: true,
        }
    }
}

impl Shortcuts {
    /// No shortcut: every pair and term is evaluated in 3D.
    pub fn none() -> Self {
        Shortcuts {
            skip_zero_phase_pairs: false,
            skip_symmetric_terms: false,
            aligned_1d: false,
        }
    }
}

/// Per-swimmer constants of the averaged equations.
#[derive(Debug, Clone, Copy)]
struct Coef {
    /// Weight of the I term (A_R).
    a_r: f64,
    /// Weight of the J term (c_J).
    c_j: f64,
    /// Weight of the K term (A_N).
    a_n: f64,
    /// Λω (λ/ℓ)² (m/s): common prefactor of I and J.
    v0: f64,
    /// ω (λ/ℓ)² (1/s): common prefactor of K and L.
    w0: f64,
    /// Λ/ℓ.
    big_l: f64,
    ell: f64,
    phase: f64,
}

impl Coef {
    fn new(d: &Dumbbell, set: Coefficients) -> Self {
        let (a1, a2) = (d.a1, d.a2);
        let (a_r, c_j) = match set {
            Coefficients::Paper => ((a2 * a2 - a1 * a1) / (a1 * a1 + a2 * a2), 1.0),
            Coefficients::LeadingOrder => (
                (a2 - a1) / (a1 + a2),
                4.0 * a1 * a2 / ((a1 + a2) * (a1 + a2)),
            ),
        };
        let eps2 = (d.lambda / d.ell).powi(2);
        Coef {
            a_r,
            c_j,
            a_n: (a2 - a1) / (a1 + a2),
            v0: d.big_lambda() * d.omega * eps2,
            w0: d.omega * eps2,
            big_l: d.big_lambda() / d.ell,
            ell: d.ell,
            phase: d.phase,
        }
    }
}

/// A swimmer's constants as the GPU kernel reads them: A_R, c_J, A_N, v0, w0, Λ/ℓ, ℓ, φ.
pub(crate) fn pair_constants(d: &Dumbbell, set: Coefficients) -> [f64; 8] {
    let c = Coef::new(d, set);
    [c.a_r, c.c_j, c.a_n, c.v0, c.w0, c.big_l, c.ell, c.phase]
}

/// The stroke-averaged right-hand side.
#[derive(Debug, Clone)]
pub struct AveragedSystem {
    coef: Vec<Coef>,
    base: Vec<Vector3<f64>>,
    /// Interacting ordered pairs (σ, ρ, sin(φσ − φρ)); pairs with sin = 0 are left out.
    pairs: Vec<(usize, usize, f64)>,
    /// The common axis when every centre and orientation lies on one line.
    axis: Option<Vector3<f64>>,
    scale_r: Vec<f64>,
    scale_n: Vec<f64>,
    torque: Vec<Vector3<f64>>,
    skip_symmetric: bool,
}

impl AveragedSystem {
    /// A system for these swimmers with every shortcut; `y` is the current state (used to detect an
    /// aligned scene).
    pub fn new(swimmers: &[Dumbbell], base: &[Vector3<f64>], set: Coefficients, y: &[f64]) -> Self {
        Self::with_shortcuts(swimmers, base, set, y, Shortcuts::default())
    }

    /// A system taking only the given shortcuts.
    pub fn with_shortcuts(
        swimmers: &[Dumbbell],
        base: &[Vector3<f64>],
        set: Coefficients,
        y: &[f64],
        shortcuts: Shortcuts,
    ) -> Self {
        let coef: Vec<Coef> = swimmers.iter().map(|d| Coef::new(d, set)).collect();
        let mut pairs = Vec::new();
        for (s, cs) in coef.iter().enumerate() {
            for (r, cr) in coef.iter().enumerate() {
                let sin = (cs.phase - cr.phase).sin();
                if s != r && (sin.abs() > SIN_ZERO || !shortcuts.skip_zero_phase_pairs) {
                    pairs.push((s, r, sin));
                }
            }
        }
        let mut sys = AveragedSystem {
            scale_r: swimmers.iter().map(Dumbbell::drift_scale).collect(),
            // The matching rotation scale (λ/ℓ)²(Λ/ℓ).
            scale_n: swimmers
                .iter()
                .map(|d| d.drift_scale() / d.stroke_scale())
                .collect(),
            coef,
            base: base.to_vec(),
            pairs,
            axis: None,
            torque: vec![Vector3::zeros(); swimmers.len()],
            skip_symmetric: shortcuts.skip_symmetric_terms,
        };
        if shortcuts.aligned_1d {
            sys.axis = sys.common_axis(y);
        }
        sys
    }

    /// Whether the 1D reduction is in use.
    pub fn is_aligned(&self) -> bool {
        self.axis.is_some()
    }

    fn center(&self, y: &[f64], s: usize) -> Vector3<f64> {
        self.base[s] + vec3(y, STATE_PER_SWIMMER * s)
    }

    /// The line through all centres, if every orientation lies along it (to 1e-12).
    fn common_axis(&self, y: &[f64]) -> Option<Vector3<f64>> {
        let n = self.coef.len();
        if n < 2 || y.len() < STATE_PER_SWIMMER * n {
            return None;
        }
        let axis = vec3(y, 3).normalize();
        let c0 = self.center(y, 0);
        (0..n)
            .all(|s| {
                let dn = vec3(y, STATE_PER_SWIMMER * s + 3).cross(&axis).norm();
                let dc = (self.center(y, s) - c0).cross(&axis).norm() / self.coef[s].ell;
                dn < 1e-12 && dc < 1e-12
            })
            .then_some(axis)
    }

    fn rhs_aligned(&self, axis: &Vector3<f64>, y: &[f64], dy: &mut [f64]) {
        dy.fill(0.0);
        let x: Vec<f64> = (0..self.coef.len())
            .map(|s| self.center(y, s).dot(axis))
            .collect();
        for &(s, r, sin) in &self.pairs {
            let c = &self.coef[s];
            let d = x[s] - x[r];
            let xi = c.ell / d.abs();
            let n = vec3(y, STATE_PER_SWIMMER * s + 3).dot(axis).signum();
            let v = 9.0 / 16.0
                * c.v0
                * sin
                * (c.a_r * c.big_l * xi.powi(3) * n + c.c_j * xi.powi(4) * d.signum());
            let i = STATE_PER_SWIMMER * s;
            for k in 0..3 {
                dy[i + k] += v * axis[k];
            }
        }
    }
}

impl OdeSystem for AveragedSystem {
    fn dim(&self) -> usize {
        STATE_PER_SWIMMER * self.coef.len()
    }

    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) {
        if let Some(axis) = self.axis {
            return self.rhs_aligned(&axis, y, dy);
        }
        dy.fill(0.0);
        let mut torque = std::mem::take(&mut self.torque);
        torque.fill(Vector3::zeros());
        for &(s, r, sin) in &self.pairs {
            let c = &self.coef[s];
            let dvec = self.center(y, s) - self.center(y, r);
            let dist = dvec.norm();
            let dh = dvec / dist;
            let ns = vec3(y, STATE_PER_SWIMMER * s + 3);
            let nr = vec3(y, STATE_PER_SWIMMER * r + 3);
            let (ss, rr, q) = (dh.dot(&ns), dh.dot(&nr), ns.dot(&nr));
            let xi = c.ell / dist;
            let (xi3, xi4) = (xi.powi(3), xi.powi(4));
            // The bracket shared by J and K.
            let jk = 1.0 + 2.0 * q * q - 5.0 * ss * ss - 5.0 * rr * rr - 20.0 * q * ss * rr
                + 35.0 * ss * ss * rr * rr;
            let mut v = c.c_j
                * c.v0
                * sin
                * (9.0 / 64.0)
                * xi4
                * (ns * (2.0 * ss + 4.0 * q * rr - 10.0 * ss * rr * rr) + dh * jk);
            let l = c.w0
                * sin
                * (15.0 / 64.0)
                * c.big_l
                * xi4
                * xi
                * (3.0 * ss + 6.0 * rr * q + 6.0 * ss * q * q
                    - 7.0 * ss.powi(3)
                    - 21.0 * ss * rr * rr
                    - 42.0 * q * ss * ss * rr
                    + 63.0 * ss.powi(3) * rr * rr);
            let mut t = dh * l;
            if c.a_r != 0.0 || !self.skip_symmetric {
                let i_br = 1.0 - 3.0 * rr * rr - 3.0 * ss * ss - 6.0 * q * ss * rr
                    + 15.0 * ss * ss * rr * rr;
                v += ns * (c.a_r * c.v0 * sin * (9.0 / 64.0) * c.big_l * xi3 * i_br);
            }
            if c.a_n != 0.0 || !self.skip_symmetric {
                t += dh * (c.a_n * c.w0 * sin * (9.0 / 32.0) * c.big_l * xi4 * jk);
            }
            let i = STATE_PER_SWIMMER * s;
            for k in 0..3 {
                dy[i + k] += v[k];
            }
            torque[s] += t;
        }
        for (s, t) in torque.iter().enumerate() {
            let n = vec3(y, STATE_PER_SWIMMER * s + 3);
            let dn = -(t - n * n.dot(t));
            set_vec3(dy, STATE_PER_SWIMMER * s + 3, &dn);
        }
        self.torque = torque;
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
        for &(s, r, _) in &self.pairs {
            if s < r && (self.center(y, s) - self.center(y, r)).norm() == 0.0 {
                return Err(Problem {
                    swimmer: Some(s),
                    cause: format!("swimmers {s} and {r} have the same centre"),
                    hint: "start the swimmers apart: the averaged model is a far-field model"
                        .into(),
                });
            }
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
