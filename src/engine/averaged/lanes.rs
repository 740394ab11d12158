//! The averaged rows over all partners in blocks of [`LANES`]: the scalar row's arithmetic, one
//! partner per lane, with the pairs it skips (itself, a zero phase difference, beyond the cutoff)
//! masked to a zero sine instead of branched around, so the compiler maps the block onto vector
//! registers (AVX-512 or AVX2, chosen at run time; the same code, so the same sums). Each lane
//! accumulates its own partners and the lanes are summed in a fixed order: the result depends on
//! neither the thread count nor the vector width, and equals the scalar row's to the rounding of
//! another summation order.
//!
//! From [`TILED_SWIMMERS`] swimmers each pair is evaluated once for both of its swimmers
//! ([`pair_rates`]): seen from the partner, D̂ and sin(φσ − φρ) change sign and N·D̂ of the two
//! swimmers swap roles, so the distance, its powers and the brackets shared by J, K and I serve
//! both. Swimmers are tiled and the tiles paired in the rounds of the sphere kernel's
//! round-robin ([`crate::engine::pairs::tile_rounds`]), as in [`crate::engine::pairs`]; the
//! brackets are evaluated with fused multiply-adds (exact in every width).

use super::{AveragedSystem, Coef, SIN_ZERO};
use crate::engine::pairs::tile_rounds;
use crate::engine::simd::vector_dispatch;
use nalgebra::Vector3;
use rayon::prelude::*;

/// Partners per block.
pub const LANES: usize = 8;

/// Sum of the lanes in a fixed pairwise order.
#[inline(always)]
fn lane_sum(a: &[f64; LANES]) -> f64 {
    ((a[0] + a[4]) + (a[1] + a[5])) + ((a[2] + a[6]) + (a[3] + a[7]))
}

/// The prefactors of a row's J, L, I and K terms (I and K zero where the symmetric-swimmer
/// shortcut drops them).
fn prefactors(sys: &AveragedSystem, c: &Coef) -> (f64, f64, f64, f64) {
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
    (
        c.c_j * c.v0 * (9.0 / 64.0),
        c.w0 * (15.0 / 64.0) * c.big_l,
        with_i * c.a_r * c.v0 * (9.0 / 64.0) * c.big_l,
        with_k * c.a_n * c.w0 * (9.0 / 32.0) * c.big_l,
    )
}

#[inline(always)]
fn row_impl(sys: &AveragedSystem, s: usize) -> (Vector3<f64>, Vector3<f64>) {
    let c = &sys.coef[s];
    let soa = &sys.soa;
    let n = sys.coef.len();
    let (xs, ys, zs) = (soa.x[s], soa.y[s], soa.z[s]);
    let (ax, ay, az) = (soa.nx[s], soa.ny[s], soa.nz[s]);
    let (sin_s, cos_s) = (sys.sin_phi[s], sys.cos_phi[s]);
    let (skip_zero, cutoff2) = (sys.skip_zero_phase, sys.cutoff2);
    let (kj, kl, ki, kk) = prefactors(sys, c);
    // A partner's contributions to v and t, from its values (the block's loads stay outside).
    #[allow(clippy::too_many_arguments)]
    let term = |x: f64,
                y: f64,
                z: f64,
                bx: f64,
                by: f64,
                bz: f64,
                sn: f64,
                cs: f64,
                own: bool|
     -> [f64; 6] {
        let (dx, dy, dz) = (xs - x, ys - y, zs - z);
        let d2 = dx * dx + dy * dy + dz * dz;
        let raw = sin_s * cs - cos_s * sn;
        // Non-short-circuit: a select, not a branch, per lane.
        let keep = !own & ((raw.abs() > SIN_ZERO) | !skip_zero) & (d2 <= cutoff2);
        let sin = if keep { raw } else { 0.0 };
        let d2 = if keep { d2 } else { 1.0 };
        let dist = d2.sqrt();
        let inv = 1.0 / dist;
        let (hx, hy, hz) = (dx * inv, dy * inv, dz * inv);
        let ss = hx * ax + hy * ay + hz * az;
        let rr = hx * bx + hy * by + hz * bz;
        let q = ax * bx + ay * by + az * bz;
        let xi = c.ell * inv;
        let xi3 = xi * xi * xi;
        let xi4 = xi3 * xi;
        let (ss2, rr2) = (ss * ss, rr * rr);
        let jk = 1.0 + 2.0 * q * q - 5.0 * ss2 - 5.0 * rr2 - 20.0 * q * ss * rr + 35.0 * ss2 * rr2;
        let j = kj * sin * xi4;
        let jn = j * (2.0 * ss + 4.0 * q * rr - 10.0 * ss * rr2);
        let jd = j * jk;
        let l = kl
            * sin
            * xi4
            * xi
            * (3.0 * ss + 6.0 * rr * q + 6.0 * ss * q * q
                - 7.0 * ss2 * ss
                - 21.0 * ss * rr2
                - 42.0 * q * ss2 * rr
                + 63.0 * ss2 * ss * rr2);
        let i_br = 1.0 - 3.0 * rr2 - 3.0 * ss2 - 6.0 * q * ss * rr + 15.0 * ss2 * rr2;
        let vn = jn + ki * sin * xi3 * i_br;
        let td = l + kk * sin * xi4 * jk;
        [
            ax * vn + hx * jd,
            ay * vn + hy * jd,
            az * vn + hz * jd,
            hx * td,
            hy * td,
            hz * td,
        ]
    };
    let (mut v0, mut v1, mut v2) = ([0.0; LANES], [0.0; LANES], [0.0; LANES]);
    let (mut t0, mut t1, mut t2) = ([0.0; LANES], [0.0; LANES], [0.0; LANES]);
    let blocks = n / LANES;
    let block = |v: &[f64], o: usize| -> [f64; LANES] {
        v[o..o + LANES].try_into().unwrap_or([0.0; LANES])
    };
    for b in 0..blocks {
        let o = b * LANES;
        let (x, y, z) = (block(&soa.x, o), block(&soa.y, o), block(&soa.z, o));
        let (bx, by, bz) = (block(&soa.nx, o), block(&soa.ny, o), block(&soa.nz, o));
        let (sn, cs) = (block(&sys.sin_phi, o), block(&sys.cos_phi, o));
        for l in 0..LANES {
            let t = term(
                x[l],
                y[l],
                z[l],
                bx[l],
                by[l],
                bz[l],
                sn[l],
                cs[l],
                o + l == s,
            );
            v0[l] += t[0];
            v1[l] += t[1];
            v2[l] += t[2];
            t0[l] += t[3];
            t1[l] += t[4];
            t2[l] += t[5];
        }
    }
    for r in blocks * LANES..n {
        let t = term(
            soa.x[r],
            soa.y[r],
            soa.z[r],
            soa.nx[r],
            soa.ny[r],
            soa.nz[r],
            sys.sin_phi[r],
            sys.cos_phi[r],
            r == s,
        );
        v0[0] += t[0];
        v1[0] += t[1];
        v2[0] += t[2];
        t0[0] += t[3];
        t1[0] += t[4];
        t2[0] += t[5];
    }
    (
        Vector3::new(lane_sum(&v0), lane_sum(&v1), lane_sum(&v2)),
        Vector3::new(lane_sum(&t0), lane_sum(&t1), lane_sum(&t2)),
    )
}

vector_dispatch! {
    /// dR_H/dt of swimmer σ and the torque-like sum T over all partners, in lanes.
    pub(super) fn row(sys: &AveragedSystem, s: usize) -> (Vector3<f64>, Vector3<f64>) = row_impl;
}

/// From this many swimmers the all-pairs rates evaluate each pair once ([`pair_rates`]).
pub const TILED_SWIMMERS: usize = 512;

/// Swimmers per tile of [`pair_rates`] (as the sphere kernel's, [`crate::engine::pairs`]).
const TILE: usize = 128;

/// Per-swimmer constants of a row: the prefactors of J, L, I and K (zero where a shortcut drops
/// the term) and ℓ.
struct RowConstants {
    kj: Vec<f64>,
    kl: Vec<f64>,
    ki: Vec<f64>,
    kk: Vec<f64>,
    ell: Vec<f64>,
}

impl RowConstants {
    fn new(sys: &AveragedSystem) -> Self {
        let mut k = RowConstants {
            kj: Vec::with_capacity(sys.coef.len()),
            kl: Vec::with_capacity(sys.coef.len()),
            ki: Vec::with_capacity(sys.coef.len()),
            kk: Vec::with_capacity(sys.coef.len()),
            ell: Vec::with_capacity(sys.coef.len()),
        };
        for c in &sys.coef {
            let (kj, kl, ki, kk) = prefactors(sys, c);
            k.kj.push(kj);
            k.kl.push(kl);
            k.ki.push(ki);
            k.kk.push(kk);
            k.ell.push(c.ell);
        }
        k
    }
}

/// The rate accumulators (v, then t, each x y z) of the swimmers from `base` on.
struct Acc<'a> {
    base: usize,
    a: [&'a mut [f64]; 6],
}

/// The rates of one side of a pair: the swimmer's own prefactors, the phase sine as seen from it,
/// ξ = ℓ/D, its ss = D̂·N_own and rr = D̂·N_partner with D̂ pointing from the partner to it, the
/// shared brackets q, J-K and I, its orientation and D̂: its accumulators of (dR_H/dt, T) with
/// the pair's terms added (as fused multiply-adds).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn side(
    k: [f64; 4],
    sin: f64,
    xi: f64,
    ss: f64,
    rr: f64,
    q: f64,
    jk: f64,
    i_br: f64,
    n: [f64; 3],
    h: [f64; 3],
    acc: [f64; 6],
) -> [f64; 6] {
    let [kj, kl, ki, kk] = k;
    let sx3 = sin * xi * xi * xi;
    let sx4 = sx3 * xi;
    let (ss2, rr2) = (ss * ss, rr * rr);
    let j = kj * sx4;
    // 2 ss + 4 q rr − 10 ss rr²
    let jn = j * (-10.0 * ss).mul_add(rr2, (4.0 * q).mul_add(rr, 2.0 * ss));
    let jd = j * jk;
    // 3 ss + 6 rr q + 6 ss q² − 7 ss³ − 21 ss rr² − 42 q ss² rr + 63 ss³ rr²
    let l_ss = (63.0 * ss2).mul_add(
        rr2,
        (-21.0f64).mul_add(rr2, (-7.0f64).mul_add(ss2, (6.0 * q).mul_add(q, 3.0))),
    );
    let l_br = ss.mul_add(l_ss, rr * q * (-42.0f64).mul_add(ss2, 6.0));
    let l = kl * sx4 * xi * l_br;
    let vn = (ki * sx3).mul_add(i_br, jn);
    let td = (kk * sx4).mul_add(jk, l);
    [
        n[0].mul_add(vn, h[0].mul_add(jd, acc[0])),
        n[1].mul_add(vn, h[1].mul_add(jd, acc[1])),
        n[2].mul_add(vn, h[2].mul_add(jd, acc[2])),
        h[0].mul_add(td, acc[3]),
        h[1].mul_add(td, acc[4]),
        h[2].mul_add(td, acc[5]),
    ]
}

/// The row swimmer's data for [`pair_term`].
struct Pivot {
    at: [f64; 3],
    n: [f64; 3],
    sin: f64,
    cos: f64,
    k: [f64; 4],
    ell: f64,
    skip_zero: bool,
    cutoff2: f64,
}

/// A partner's data in (position, orientation, sin φ, cos φ, prefactors, ℓ), (the pivot's rates
/// from it, its rates from the pivot) out.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn pair_term(
    p: &Pivot,
    x: f64,
    y: f64,
    z: f64,
    bx: f64,
    by: f64,
    bz: f64,
    sn: f64,
    cs: f64,
    kr: [f64; 4],
    ell_r: f64,
    mine: [f64; 6],
    theirs: [f64; 6],
) -> ([f64; 6], [f64; 6]) {
    let (dx, dy, dz) = (p.at[0] - x, p.at[1] - y, p.at[2] - z);
    let d2 = dx.mul_add(dx, dy.mul_add(dy, dz * dz));
    let raw = p.sin * cs - p.cos * sn;
    // Non-short-circuit: a select, not a branch, per lane.
    let keep = ((raw.abs() > SIN_ZERO) | !p.skip_zero) & (d2 <= p.cutoff2);
    let sin = if keep { raw } else { 0.0 };
    let d2 = if keep { d2 } else { 1.0 };
    let inv = 1.0 / d2.sqrt();
    let h = [dx * inv, dy * inv, dz * inv];
    let (a, b) = (p.n, [bx, by, bz]);
    let dot = |u: [f64; 3], v: [f64; 3]| u[0].mul_add(v[0], u[1].mul_add(v[1], u[2] * v[2]));
    let (ss, rr, q) = (dot(h, a), dot(h, b), dot(a, b));
    let (ss2, rr2, qsr) = (ss * ss, rr * rr, q * ss * rr);
    // 1 + 2 q² − 5 ss² − 5 rr² − 20 q ss rr + 35 ss² rr²
    let jk = (35.0 * ss2).mul_add(
        rr2,
        (-20.0f64).mul_add(qsr, (-5.0f64).mul_add(ss2 + rr2, (2.0 * q).mul_add(q, 1.0))),
    );
    // 1 − 3 rr² − 3 ss² − 6 q ss rr + 15 ss² rr²
    let i_br = (15.0 * ss2).mul_add(
        rr2,
        (-6.0f64).mul_add(qsr, (-3.0f64).mul_add(ss2 + rr2, 1.0)),
    );
    let mine = side(p.k, sin, p.ell * inv, ss, rr, q, jk, i_br, a, h, mine);
    // Seen from the partner: D̂ and the phase difference change sign, ss and rr swap roles.
    let hr = [-h[0], -h[1], -h[2]];
    let theirs = side(kr, -sin, ell_r * inv, -rr, -ss, q, jk, i_br, b, hr, theirs);
    (mine, theirs)
}

/// Swimmer `s` against the swimmers of `c` (all others): adds their rates from s to their
/// accumulators and returns s's from them.
#[inline(always)]
fn half_row(sys: &AveragedSystem, k: &RowConstants, s: usize, c: &mut Acc<'_>) -> [f64; 6] {
    let soa = &sys.soa;
    let p = Pivot {
        at: [soa.x[s], soa.y[s], soa.z[s]],
        n: [soa.nx[s], soa.ny[s], soa.nz[s]],
        sin: sys.sin_phi[s],
        cos: sys.cos_phi[s],
        k: [k.kj[s], k.kl[s], k.ki[s], k.kk[s]],
        ell: k.ell[s],
        skip_zero: sys.skip_zero_phase,
        cutoff2: sys.cutoff2,
    };
    let term = |x, y, z, bx, by, bz, sn, cs, kr, ell_r, mine, theirs| {
        pair_term(&p, x, y, z, bx, by, bz, sn, cs, kr, ell_r, mine, theirs)
    };
    let n = c.a[0].len();
    let r = c.base..c.base + n;
    let (x, y, z) = (&soa.x[r.clone()], &soa.y[r.clone()], &soa.z[r.clone()]);
    let (bx, by, bz) = (&soa.nx[r.clone()], &soa.ny[r.clone()], &soa.nz[r.clone()]);
    let (sn, cs) = (&sys.sin_phi[r.clone()], &sys.cos_phi[r.clone()]);
    let (kj, kl, ki, kk) = (
        &k.kj[r.clone()],
        &k.kl[r.clone()],
        &k.ki[r.clone()],
        &k.kk[r.clone()],
    );
    let ell = &k.ell[r];
    let mut acc = [[0.0; LANES]; 6];
    let blocks = n / LANES;
    for b in 0..blocks {
        let o = b * LANES;
        let lanes =
            |v: &[f64]| -> [f64; LANES] { v[o..o + LANES].try_into().unwrap_or([0.0; LANES]) };
        let (xb, yb, zb) = (lanes(x), lanes(y), lanes(z));
        let (bxb, byb, bzb) = (lanes(bx), lanes(by), lanes(bz));
        let (snb, csb) = (lanes(sn), lanes(cs));
        let (kjb, klb, kib, kkb, ellb) = (lanes(kj), lanes(kl), lanes(ki), lanes(kk), lanes(ell));
        let mut theirs = [[0.0; LANES]; 6];
        for (m, col) in theirs.iter_mut().enumerate() {
            *col = c.a[m][o..o + LANES].try_into().unwrap_or([0.0; LANES]);
        }
        for l in 0..LANES {
            let (mine, other) = term(
                xb[l],
                yb[l],
                zb[l],
                bxb[l],
                byb[l],
                bzb[l],
                snb[l],
                csb[l],
                [kjb[l], klb[l], kib[l], kkb[l]],
                ellb[l],
                std::array::from_fn(|m| acc[m][l]),
                std::array::from_fn(|m| theirs[m][l]),
            );
            for m in 0..6 {
                acc[m][l] = mine[m];
                theirs[m][l] = other[m];
            }
        }
        for (m, col) in theirs.iter().enumerate() {
            c.a[m][o..o + LANES].copy_from_slice(col);
        }
    }
    for j in blocks * LANES..n {
        let (mine, other) = term(
            x[j],
            y[j],
            z[j],
            bx[j],
            by[j],
            bz[j],
            sn[j],
            cs[j],
            [kj[j], kl[j], ki[j], kk[j]],
            ell[j],
            std::array::from_fn(|m| acc[m][0]),
            std::array::from_fn(|m| c.a[m][j]),
        );
        for m in 0..6 {
            acc[m][0] = mine[m];
            c.a[m][j] = other[m];
        }
    }
    acc.map(|a| lane_sum(&a))
}

/// Every pair of the tiles `rows` and `cols`, or of `rows` with itself when `cols` is `None`.
#[inline(always)]
fn tile_pairs(sys: &AveragedSystem, k: &RowConstants, rows: Acc<'_>, cols: Option<Acc<'_>>) {
    let Acc { base, a } = rows;
    let [a0, a1, a2, a3, a4, a5] = a;
    let mut own = [a0, a1, a2, a3, a4, a5];
    match cols {
        Some(mut c) => {
            for r in 0..own[0].len() {
                let u = half_row(sys, k, base + r, &mut c);
                for m in 0..6 {
                    own[m][r] += u[m];
                }
            }
        }
        None => {
            for r in 0..own[0].len() {
                let mut heads: Vec<&mut f64> = Vec::with_capacity(6);
                let mut tails: Vec<&mut [f64]> = Vec::with_capacity(6);
                for col in own.iter_mut() {
                    let (head, tail) = col.split_at_mut(r + 1);
                    heads.push(&mut head[r]);
                    tails.push(tail);
                }
                let Ok(a) = <[&mut [f64]; 6]>::try_from(tails) else {
                    continue;
                };
                let mut c = Acc {
                    base: base + r + 1,
                    a,
                };
                let u = half_row(sys, k, base + r, &mut c);
                for (h, v) in heads.into_iter().zip(u) {
                    *h += v;
                }
            }
        }
    }
}

vector_dispatch! {
    /// [`tile_pairs`] in the widest vector unit present.
    fn tile_pairs_dispatch(sys: &AveragedSystem, k: &RowConstants, r: Acc<'_>, c: Option<Acc<'_>>) = tile_pairs;
}

/// The accumulators split into tiles of [`TILE`] swimmers.
fn tiles(acc: &mut [Vec<f64>; 6]) -> Vec<Option<Acc<'_>>> {
    let [a0, a1, a2, a3, a4, a5] = acc;
    let mut chunks = [a0, a1, a2, a3, a4, a5].map(|v| v.chunks_mut(TILE));
    let mut out = Vec::new();
    let mut base = 0;
    loop {
        let next = chunks.each_mut().map(Iterator::next);
        let Ok(a) = <[&mut [f64]; 6]>::try_from(next.into_iter().flatten().collect::<Vec<_>>())
        else {
            return out;
        };
        let len = a[0].len();
        out.push(Some(Acc { base, a }));
        base += len;
    }
}

/// dR_H/dt and the torque-like sum T of every swimmer over all partners (v x y z, t x y z), each
/// pair evaluated once for both of its swimmers: swimmers in tiles of [`TILE`], every tile with
/// itself, then every two tiles in the rounds of [`tile_rounds`], a round's tile pairs in
/// parallel when `parallel`. Each swimmer's sum runs in an order fixed by the swimmer count.
pub(super) fn pair_rates(sys: &AveragedSystem, parallel: bool) -> [Vec<f64>; 6] {
    let n = sys.coef.len();
    let k = RowConstants::new(sys);
    let mut acc: [Vec<f64>; 6] = std::array::from_fn(|_| vec![0.0; n]);
    let run = |tasks: Vec<(Acc<'_>, Option<Acc<'_>>)>| {
        if parallel {
            tasks
                .into_par_iter()
                .for_each(|(r, c)| tile_pairs_dispatch(sys, &k, r, c));
        } else {
            for (r, c) in tasks {
                tile_pairs_dispatch(sys, &k, r, c);
            }
        }
    };
    run(tiles(&mut acc)
        .into_iter()
        .flatten()
        .map(|c| (c, None))
        .collect());
    for round in tile_rounds(n.div_ceil(TILE)) {
        let mut all = tiles(&mut acc);
        run(round
            .iter()
            .filter_map(|&(a, b)| Some((all[a].take()?, Some(all[b].take()?))))
            .collect());
    }
    acc
}
