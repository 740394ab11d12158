//! The averaged model's terms: each swimmer's constants (the I, J, K, L weights and the stroke),
//! the smooth switch of a far-field cutoff, and the phase weight of a pair.

use crate::engine::model::Coefficients;
use crate::engine::swimmer::Dumbbell;

/// |sin(Δφ)| below this counts as zero: phases given as 0 and π differ by rounding only.
pub(super) const SIN_ZERO: f64 = 1e-14;

/// Per-swimmer constants of the averaged equations.
#[derive(Debug, Clone, Copy)]
pub(super) struct Coef {
    /// Weight of the I term (A_R).
    pub(super) a_r: f64,
    /// Weight of the J term (c_J).
    pub(super) c_j: f64,
    /// Weight of the K term (A_N).
    pub(super) a_n: f64,
    /// Λω (λ/ℓ)² (m/s): common prefactor of I and J.
    pub(super) v0: f64,
    /// ω (λ/ℓ)² (1/s): common prefactor of K and L.
    pub(super) w0: f64,
    /// Λ/ℓ.
    pub(super) big_l: f64,
    pub(super) ell: f64,
    pub(super) phase: f64,
}

impl Coef {
    pub(super) fn new(d: &Dumbbell, set: Coefficients) -> Self {
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

/// The far-field cutoff's switch, as a fraction of the cutoff D_c: see [`CutoffSwitch`].
pub const CUTOFF_SWITCH_WIDTH: f64 = 0.1;

/// The far-field cutoff's switch: a pair's terms are weighed by S(D) = 1 below (1 − w)D_c, 0 from
/// D_c on, and between them the smoothstep S = 1 − x⁴(35 − 84x + 70x² − 20x³),
/// x = (D − (1 − w)D_c)/(w D_c), whose first three derivatives vanish at both ends (w =
/// [`CUTOFF_SWITCH_WIDTH`]). The rates are then three times continuously differentiable as
/// pairs cross the cutoff: the integrators keep their orders (RK4's needs that much) and their
/// error estimates stay meaningful, where a pair leaving at once would jump the rates and stall
/// every adaptive step that straddles the crossing.
#[derive(Debug, Clone, Copy)]
pub struct CutoffSwitch {
    /// (1 − w) D_c (m); 0 without a cutoff.
    inner: f64,
    /// 1/(w D_c) (1/m); 0 without a cutoff (every pair weighs 1).
    inv_width: f64,
}

impl CutoffSwitch {
    pub(crate) fn new(cutoff: Option<f64>) -> Self {
        match cutoff {
            Some(c) if c.is_finite() => CutoffSwitch {
                inner: (1.0 - CUTOFF_SWITCH_WIDTH) * c,
                inv_width: 1.0 / (CUTOFF_SWITCH_WIDTH * c),
            },
            _ => CutoffSwitch {
                inner: 0.0,
                inv_width: 0.0,
            },
        }
    }

    /// S(D) for a pair at distance `d` (m, finite).
    #[inline(always)]
    pub fn at(&self, d: f64) -> f64 {
        let x = ((d - self.inner) * self.inv_width).clamp(0.0, 1.0);
        let x2 = x * x;
        let p = x.mul_add(x.mul_add((-20.0f64).mul_add(x, 70.0), -84.0), 35.0);
        (-(x2 * x2)).mul_add(p, 1.0)
    }

    /// Where the switch starts, (1 − w) D_c (m): pairs beyond weigh less than 1.
    pub fn inner(&self) -> f64 {
        self.inner
    }
}

/// sin(φσ − φρ) from the phases' sines and cosines if the pair interacts: not the same swimmer,
/// and not a zero phase difference when `skip_zero` (the neighbour lists' pair weight).
#[inline]
pub(super) fn pair_weight(
    sin: &[f64],
    cos: &[f64],
    skip_zero: bool,
    s: usize,
    r: usize,
) -> Option<f64> {
    let v = sin[s] * cos[r] - cos[s] * sin[r];
    (s != r && (v.abs() > SIN_ZERO || !skip_zero)).then_some(v)
}
