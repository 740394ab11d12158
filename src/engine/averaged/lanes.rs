//! The averaged rows over all partners in blocks of [`LANES`]: the scalar row's arithmetic, one
//! partner per lane, with the pairs it skips (itself, a zero phase difference, beyond the cutoff)
//! masked to a zero sine instead of branched around, so the compiler maps the block onto vector
//! registers (AVX-512 or AVX2 with FMA, chosen at run time; the same code, so the same sums).
//! The brackets are Horner-like chains of fused multiply-adds and each term is added to its
//! accumulator as one (exact in every width, and in software without one). Each lane
//! accumulates its own partners and the lanes are summed in a fixed order: the result depends on
//! neither the thread count nor the vector width, and equals the scalar row's to the rounding of
//! another summation order.

use super::system::AveragedSystem;
use super::terms::{Coef, CutoffSwitch, SIN_ZERO};
use crate::engine::simd::{lane_sum, vector_dispatch};
use nalgebra::Vector3;

/// Partners per block.
pub use crate::engine::simd::LANES;

/// The prefactors of a row's J, L, I and K terms (I and K zero where the symmetric-swimmer
/// shortcut drops them), each with its power of ℓ (ξ = ℓ/D): the lanes take powers of 1/D.
pub(super) fn prefactors(sys: &AveragedSystem, c: &Coef) -> [f64; 4] {
    let with_i = if c.a_r != 0.0 || !sys.skip_symmetric {
        1.0
    } else {
        0.0
    };
    let with_k = if c.a_n != 0.0 || !sys.skip_symmetric {
        1.0
    } else {
        0.0
    };
    let (l3, l4) = (c.ell.powi(3), c.ell.powi(4));
    [
        c.c_j * c.v0 * (9.0 / 64.0) * l4,
        c.w0 * (15.0 / 64.0) * c.big_l * l4 * c.ell,
        with_i * c.a_r * c.v0 * (9.0 / 64.0) * c.big_l * l3,
        with_k * c.a_n * c.w0 * (9.0 / 32.0) * c.big_l * l4,
    ]
}

/// The row swimmer's data for [`lane_term`].
struct Row {
    at: [f64; 3],
    n: [f64; 3],
    sin: f64,
    cos: f64,
    k: [f64; 4],
    /// |sin(φσ − φρ)| a pair must exceed to count: [`SIN_ZERO`] when zero-phase pairs are
    /// skipped, −1 (every pair) when not.
    sin_floor: f64,
    cutoff2: f64,
    switch: CutoffSwitch,
}

/// Accumulators of a row: Σ vn (the coefficient of the row's own orientation, applied once at
/// the end), Σ D̂ jd (velocity) and Σ D̂ td (torque-like).
pub(super) type Acc = [f64; 7];

/// A partner's (position, orientation, sin φ, cos φ) contributions added to the row's
/// accumulators. Skipped pairs (a zero phase difference, with `CUT` beyond the cutoff, and with
/// `OWN` the row's own swimmer where `own`) get a zero sine by a select, not a branch, per lane;
/// only the block holding the row's own swimmer pays for its mask, and only a scene with a cutoff
/// for the cutoff's.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn lane_term<const OWN: bool, const CUT: bool, const IK: bool>(
    p: &Row,
    x: f64,
    y: f64,
    z: f64,
    bx: f64,
    by: f64,
    bz: f64,
    sn: f64,
    cs: f64,
    own: bool,
    acc: Acc,
) -> Acc {
    let (dx, dy, dz) = (p.at[0] - x, p.at[1] - y, p.at[2] - z);
    let d2 = dx.mul_add(dx, dy.mul_add(dy, dz * dz));
    let raw = p.sin * cs - p.cos * sn;
    let keep = (raw.abs() > p.sin_floor) & (!CUT || d2 <= p.cutoff2) & !(OWN && own);
    let sin = if keep { raw } else { 0.0 };
    // A skipped pair may sit at distance 0 (the own swimmer always does): a 1 there keeps its
    // zero terms finite.
    let d2 = if keep { d2 } else { 1.0 };
    let inv = 1.0 / d2.sqrt();
    let sin = if CUT {
        sin * p.switch.at(d2 * inv)
    } else {
        sin
    };
    let h = [dx * inv, dy * inv, dz * inv];
    let dot = |u: [f64; 3], v: [f64; 3]| u[0].mul_add(v[0], u[1].mul_add(v[1], u[2] * v[2]));
    let (a, b) = (p.n, [bx, by, bz]);
    let (ss, rr, q) = (dot(h, a), dot(h, b), dot(a, b));
    side::<IK>(p.k, sin, inv, ss, rr, q, h, acc)
}

/// The row of swimmer `s`, with the cutoff's mask only where there is one, and the I and K terms
/// only where their prefactors are not zero (a symmetric swimmer's are: it gets the J and L terms
/// alone, as in the scalar row).
#[inline(always)]
fn row_impl(sys: &AveragedSystem, s: usize) -> (Vector3<f64>, Vector3<f64>) {
    let k = prefactors(sys, &sys.coef[s]);
    let ik = k[2] != 0.0 || k[3] != 0.0;
    match (sys.cutoff2.is_finite(), ik) {
        (true, true) => row_with::<true, true>(sys, s, k),
        (true, false) => row_with::<true, false>(sys, s, k),
        (false, true) => row_with::<false, true>(sys, s, k),
        (false, false) => row_with::<false, false>(sys, s, k),
    }
}

#[inline(always)]
fn row_with<'a, const CUT: bool, const IK: bool>(
    sys: &'a AveragedSystem,
    s: usize,
    k: [f64; 4],
) -> (Vector3<f64>, Vector3<f64>) {
    let soa = &sys.soa;
    let n = sys.coef.len();
    let p = Row {
        at: [soa.x[s], soa.y[s], soa.z[s]],
        n: [soa.nx[s], soa.ny[s], soa.nz[s]],
        sin: sys.sin_phi[s],
        cos: sys.cos_phi[s],
        k,
        sin_floor: if sys.skip_zero_phase { SIN_ZERO } else { -1.0 },
        cutoff2: sys.cutoff2,
        switch: sys.switch,
    };
    let mut acc = [[0.0; LANES]; 7];
    let blocks = n / LANES;
    // Whole blocks of each array (exact chunks: no bounds checks in the loop).
    let chunks = |v: &'a [f64]| v[..blocks * LANES].chunks_exact(LANES);
    let partners = chunks(&soa.x)
        .zip(chunks(&soa.y))
        .zip(chunks(&soa.z))
        .zip(chunks(&soa.nx))
        .zip(chunks(&soa.ny))
        .zip(chunks(&soa.nz))
        .zip(chunks(&sys.sin_phi))
        .zip(chunks(&sys.cos_phi));
    // Every lane of a block through `lane_term::<OWN, CUT, IK>` (a macro: the block must be compiled
    // inline, in the caller's vector unit, and a large closure is not always inlined).
    macro_rules! block_of {
        ($own:literal, $o:expr, $x:expr, $y:expr, $z:expr, $bx:expr, $by:expr, $bz:expr, $sn:expr, $cs:expr) => {{
            let o = $o;
            let arr = |v: &[f64]| -> [f64; LANES] { v.try_into().unwrap_or([0.0; LANES]) };
            let (x, y, z) = (arr($x), arr($y), arr($z));
            let (bx, by, bz, sn, cs) = (arr($bx), arr($by), arr($bz), arr($sn), arr($cs));
            for l in 0..LANES {
                let t = lane_term::<$own, CUT, IK>(
                    &p,
                    x[l],
                    y[l],
                    z[l],
                    bx[l],
                    by[l],
                    bz[l],
                    sn[l],
                    cs[l],
                    o + l == s,
                    std::array::from_fn(|m| acc[m][l]),
                );
                for m in 0..7 {
                    acc[m][l] = t[m];
                }
            }
        }};
    }
    for (b, (((((((x, y), z), bx), by), bz), sn), cs)) in partners.enumerate() {
        let o = b * LANES;
        if (o..o + LANES).contains(&s) {
            block_of!(true, o, x, y, z, bx, by, bz, sn, cs);
        } else {
            block_of!(false, o, x, y, z, bx, by, bz, sn, cs);
        }
    }
    for r in blocks * LANES..n {
        let t = lane_term::<true, CUT, IK>(
            &p,
            soa.x[r],
            soa.y[r],
            soa.z[r],
            soa.nx[r],
            soa.ny[r],
            soa.nz[r],
            sys.sin_phi[r],
            sys.cos_phi[r],
            r == s,
            std::array::from_fn(|m| acc[m][0]),
        );
        for m in 0..7 {
            acc[m][0] = t[m];
        }
    }
    let [vn, v0, v1, v2, t0, t1, t2] = acc.map(|a| lane_sum(&a));
    let n = p.n;
    (
        Vector3::new(
            n[0].mul_add(vn, v0),
            n[1].mul_add(vn, v1),
            n[2].mul_add(vn, v2),
        ),
        Vector3::new(t0, t1, t2),
    )
}

vector_dispatch! {
    /// dR_H/dt of swimmer σ and the torque-like sum T over all partners, in lanes.
    pub(super) fn row(sys: &AveragedSystem, s: usize) -> (Vector3<f64>, Vector3<f64>) = row_impl;
}

/// The rates a swimmer gets from one partner: its prefactors (J, L, I, K, with their powers of ℓ),
/// the phase sine, ξ = 1/D, its ss = D̂·N_own and rr = D̂·N_partner with D̂ pointing from the partner to it,
/// q = N_own·N_partner and D̂: its accumulators with the pair's terms added (as fused
/// multiply-adds). The brackets are polynomials in u = ss², v = rr², w = q ss rr, uv, u + v and
/// q², shared among them.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn side<const IK: bool>(
    k: [f64; 4],
    sin: f64,
    xi: f64,
    ss: f64,
    rr: f64,
    q: f64,
    h: [f64; 3],
    acc: Acc,
) -> Acc {
    let [kj, kl, ki, kk] = k;
    // sin ξ³ and sin ξ⁴ (ξ here 1/D: ℓ's powers are in the prefactors); the former only for I.
    let x2 = xi * xi;
    let (sx3, sx4) = if IK {
        let sx3 = sin * xi * x2;
        (sx3, sx3 * xi)
    } else {
        (0.0, sin * (x2 * x2))
    };
    let (u, v, q2, qr) = (ss * ss, rr * rr, q * q, q * rr);
    let (w, uv, sum) = (qr * ss, u * v, u + v);
    // 1 + 2 q² − 5 ss² − 5 rr² − 20 q ss rr + 35 ss² rr²
    let jk = 35.0f64.mul_add(
        uv,
        (-20.0f64).mul_add(w, (-5.0f64).mul_add(sum, 2.0f64.mul_add(q2, 1.0))),
    );
    // 1 − 3 rr² − 3 ss² − 6 q ss rr + 15 ss² rr²
    let i_br = 15.0f64.mul_add(uv, (-6.0f64).mul_add(w, (-3.0f64).mul_add(sum, 1.0)));
    // 2 ss + 4 q rr − 10 ss rr² = ss (2 − 10 rr²) + 4 q rr
    let jn_br = ss.mul_add((-10.0f64).mul_add(v, 2.0), 4.0 * qr);
    // 3 ss + 6 rr q + 6 ss q² − 7 ss³ − 21 ss rr² − 42 q ss² rr + 63 ss³ rr²
    //   = ss (3 + 6 q² − 7 ss² − 21 rr² + 63 ss² rr²) + q rr (6 − 42 ss²)
    let l_ss = 63.0f64.mul_add(
        uv,
        (-21.0f64).mul_add(v, (-7.0f64).mul_add(u, 6.0f64.mul_add(q2, 3.0))),
    );
    let l_br = ss.mul_add(l_ss, qr * (-42.0f64).mul_add(u, 6.0));
    let j = kj * sx4;
    let jd = j * jk;
    let (vn, td) = if IK {
        (
            (ki * sx3).mul_add(i_br, j * jn_br),
            sx4 * kk.mul_add(jk, kl * xi * l_br),
        )
    } else {
        (j * jn_br, sx4 * (kl * xi * l_br))
    };
    [
        acc[0] + vn,
        h[0].mul_add(jd, acc[1]),
        h[1].mul_add(jd, acc[2]),
        h[2].mul_add(jd, acc[3]),
        h[0].mul_add(td, acc[4]),
        h[1].mul_add(td, acc[5]),
        h[2].mul_add(td, acc[6]),
    ]
}
