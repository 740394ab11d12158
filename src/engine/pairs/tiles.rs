//! The each-pair-once kernel: spheres in tiles, every tile with itself and then every two tiles
//! in the rounds of a round-robin tournament, one evaluation giving both ends' terms.

use super::soa::SoaSpheres;
use super::tensor::{add_overlapping, prefactors, Kernel};
use crate::engine::mobility::Mobility;
use crate::engine::simd::{block, lane_sum, vector_dispatch, InvSqrt, LANES};
use rayon::prelude::*;

/// Spheres per tile of the symmetric kernel: n/32, within these bounds (multiples of [`LANES`]).
/// Larger tiles cost a little less serially (fewer tile edges), but a round has only tiles/2
/// pairs of tiles to run in parallel: n/32 keeps 16 at n = 4,096.
const MIN_TILE: usize = 128;
/// See [`MIN_TILE`].
const MAX_TILE: usize = 256;

/// The velocity accumulators of a run of spheres starting at sphere `base`.
struct Cols<'a> {
    base: usize,
    x: &'a mut [f64],
    y: &'a mut [f64],
    z: &'a mut [f64],
}

/// What the each-pair-once kernel reads: the spheres and, per sphere, the
/// radius counted for overlaps (zero for Oseen) and (c3/c1)·a², the finite-size term scaled by
/// 8πμ. The sums carry H/c1 (c1 = 1/(8πμ)): the far-field coefficient is then 1/r itself, and
/// the result is scaled by c1 once per sphere.
#[derive(Clone, Copy)]
struct Tiled<'a> {
    s: &'a SoaSpheres,
    reach_a: &'a [f64],
    a2s: &'a [f64],
}

/// The half row of sphere `i` against the spheres of `c` (all different from i): adds
/// H_ij F_i / c1 to each column j's accumulators and returns Σ_j H_ij F_j / c1 and a check:
///
/// - `MASK`: pairs closer than contact (RPY: r ≤ a_i + a_j; both models: coincident spheres)
///   are masked out, and the check is their count;
/// - otherwise every pair takes the far-field form, and the check is the smallest r² met (the
///   caller redoes the tile pair masked if that could be an overlap).
///
/// Each accumulator takes its terms as two fused multiply-adds (exact in every vector width,
/// and in software without one): the sums depend on neither; 1/r is `U`'s.
#[inline(always)]
fn half_row<U: InvSqrt, const MASK: bool>(
    t: Tiled<'_>,
    i: usize,
    c: &mut Cols<'_>,
) -> ([f64; 3], f64) {
    let s = t.s;
    let (xi, yi, zi, ai, ai2) = (s.x[i], s.y[i], s.z[i], t.reach_a[i], t.a2s[i]);
    let (fxi, fyi, fzi) = (s.fx[i], s.fy[i], s.fz[i]);
    let separation = |x: f64, y: f64, z: f64| {
        let (rx, ry, rz) = (xi - x, yi - y, zi - z);
        ([rx, ry, rz], rx.mul_add(rx, ry.mul_add(ry, rz * rz)))
    };
    // Whether a pair at r² with partner reach a is counted (always, unmasked).
    let separated = |r2: f64, a: f64| {
        let contact = ai + a;
        !MASK || r2 > contact * contact
    };
    // H_ij / c1 = cf 1 + g r rᵀ from 1/r (0 for a masked pair): (cf, g (r·F_j), g (r·F_i)).
    let coefficients = |r: [f64; 3], inv_r: f64, a2: f64, f: [f64; 3]| {
        let inv_r2 = inv_r * inv_r;
        let f3 = (ai2 + a2) * inv_r * inv_r2;
        let cf = inv_r + f3;
        let g = (-3.0f64).mul_add(f3, inv_r) * inv_r2;
        let gj = g * r[0].mul_add(f[0], r[1].mul_add(f[1], r[2] * f[2]));
        let gi = g * r[0].mul_add(fxi, r[1].mul_add(fyi, r[2] * fzi));
        (cf, gj, gi)
    };
    // The check's contribution of a pair at r²: masked or not, or r² itself.
    let check = |r2: f64, counted: bool| {
        if MASK {
            if counted {
                0.0
            } else {
                1.0
            }
        } else {
            r2
        }
    };
    let fold = |acc: f64, v: f64| {
        if MASK {
            acc + v
        } else if v < acc {
            v
        } else {
            acc
        }
    };
    let n = c.x.len();
    let r = c.base..c.base + n;
    let (x, y, z) = (&s.x[r.clone()], &s.y[r.clone()], &s.z[r.clone()]);
    let (a, a2) = (&t.reach_a[r.clone()], &t.a2s[r.clone()]);
    let (fx, fy, fz) = (&s.fx[r.clone()], &s.fy[r.clone()], &s.fz[r]);
    let (ux, uy, uz) = (&mut *c.x, &mut *c.y, &mut *c.z);
    let blocks = n / LANES;
    let mut ax = [0.0; LANES];
    let mut ay = [0.0; LANES];
    let mut az = [0.0; LANES];
    let mut checks = [if MASK { 0.0 } else { f64::INFINITY }; LANES];
    for b in 0..blocks {
        let o = b * LANES;
        let l8 = o..o + LANES;
        let (Ok(cx), Ok(cy), Ok(cz)) = (
            <&mut [f64; LANES]>::try_from(&mut ux[l8.clone()]),
            <&mut [f64; LANES]>::try_from(&mut uy[l8.clone()]),
            <&mut [f64; LANES]>::try_from(&mut uz[l8]),
        ) else {
            continue;
        };
        let lanes = |v: &[f64]| block(v, o);
        let (xb, yb, zb, ab, a2b) = (lanes(x), lanes(y), lanes(z), lanes(a), lanes(a2));
        let (fxb, fyb, fzb) = (lanes(fx), lanes(fy), lanes(fz));
        let seps: [_; LANES] = std::array::from_fn(|l| separation(xb[l], yb[l], zb[l]));
        // SAFETY: `U` is the one vector_dispatch! chose for the unit this build runs on.
        let inv = unsafe { U::inv_sqrt(seps.map(|(_, r2)| r2)) };
        let (mut vx, mut vy, mut vz) = (*cx, *cy, *cz);
        for l in 0..LANES {
            let (rv, r2) = seps[l];
            let counted = separated(r2, ab[l]);
            let inv_r = if counted { inv[l] } else { 0.0 };
            let (cf, gj, gi) = coefficients(rv, inv_r, a2b[l], [fxb[l], fyb[l], fzb[l]]);
            ax[l] = gj.mul_add(rv[0], cf.mul_add(fxb[l], ax[l]));
            ay[l] = gj.mul_add(rv[1], cf.mul_add(fyb[l], ay[l]));
            az[l] = gj.mul_add(rv[2], cf.mul_add(fzb[l], az[l]));
            vx[l] = gi.mul_add(rv[0], cf.mul_add(fxi, vx[l]));
            vy[l] = gi.mul_add(rv[1], cf.mul_add(fyi, vy[l]));
            vz[l] = gi.mul_add(rv[2], cf.mul_add(fzi, vz[l]));
            checks[l] = fold(checks[l], check(r2, counted));
        }
        (*cx, *cy, *cz) = (vx, vy, vz);
    }
    for j in blocks * LANES..n {
        let (rv, r2) = separation(x[j], y[j], z[j]);
        let counted = separated(r2, a[j]);
        let inv_r = if counted { 1.0 / r2.sqrt() } else { 0.0 };
        let (cf, gj, gi) = coefficients(rv, inv_r, a2[j], [fx[j], fy[j], fz[j]]);
        ax[0] = gj.mul_add(rv[0], cf.mul_add(fx[j], ax[0]));
        ay[0] = gj.mul_add(rv[1], cf.mul_add(fy[j], ay[0]));
        az[0] = gj.mul_add(rv[2], cf.mul_add(fz[j], az[0]));
        ux[j] = gi.mul_add(rv[0], cf.mul_add(fxi, ux[j]));
        uy[j] = gi.mul_add(rv[1], cf.mul_add(fyi, uy[j]));
        uz[j] = gi.mul_add(rv[2], cf.mul_add(fzi, uz[j]));
        checks[0] = fold(checks[0], check(r2, counted));
    }
    let check = if MASK {
        lane_sum(&checks)
    } else {
        checks.into_iter().fold(f64::INFINITY, fold)
    };
    ([lane_sum(&ax), lane_sum(&ay), lane_sum(&az)], check)
}

/// The spheres of `c` that sphere `i` overlaps (the pairs [`half_row`] masks).
fn overlapping_in<'a>(
    t: Tiled<'a>,
    i: usize,
    c: &Cols<'_>,
) -> impl Iterator<Item = usize> + use<'a> {
    let s = t.s;
    (c.base..c.base + c.x.len()).filter(move |&j| {
        let (rx, ry, rz) = (s.x[i] - s.x[j], s.y[i] - s.y[j], s.z[i] - s.z[j]);
        let contact = t.reach_a[i] + t.reach_a[j];
        rx * rx + ry * ry + rz * rz <= contact * contact
    })
}

/// For every pair of the tiles `rows` and `cols` (given by their accumulators), or of the tile
/// `rows` with itself when `cols` is `None`: sphere i's half row against its partners j (those
/// of `cols`, or those after i in `rows`), `$body` with `$i` and the partners' `Cols` as `$c`,
/// whose value (the half row's sum) is added to row i's accumulators. A macro, not a closure:
/// the body must be compiled in its caller's vector unit.
macro_rules! for_half_rows {
    ($rows:expr, $cols:expr, |$i:ident, $c:ident| $body:expr) => {{
        let rows: &mut Cols<'_> = $rows;
        let base = rows.base;
        let (x, y, z) = (&mut *rows.x, &mut *rows.y, &mut *rows.z);
        match $cols {
            Some($c) => {
                for r in 0..x.len() {
                    let $i = base + r;
                    let u: [f64; 3] = $body;
                    (x[r], y[r], z[r]) = (x[r] + u[0], y[r] + u[1], z[r] + u[2]);
                }
            }
            None => {
                for r in 0..x.len() {
                    let (xr, xc) = x.split_at_mut(r + 1);
                    let (yr, yc) = y.split_at_mut(r + 1);
                    let (zr, zc) = z.split_at_mut(r + 1);
                    let $c = &mut Cols {
                        base: base + r + 1,
                        x: xc,
                        y: yc,
                        z: zc,
                    };
                    let $i = base + r;
                    let u: [f64; 3] = $body;
                    (xr[r], yr[r], zr[r]) = (xr[r] + u[0], yr[r] + u[1], zr[r] + u[2]);
                }
            }
        }
    }};
}

/// Every pair of the tiles `rows` and `cols` (or of `rows` with itself when `cols` is `None`),
/// added to both ends' accumulators; returns the spheres of pairs closer than contact, whose
/// terms the caller adds in the overlapping form.
///
/// First all pairs in the far-field form, with no masks (6 fewer vector operations a pair),
/// each row tracking the smallest r² it meets. A row that met a partner within its reach plus
/// the tile's largest is scanned for overlaps; if it has one, the accumulators are put back and
/// the tile pair is redone with the masks. Either way the sums are the same function of the
/// positions, whatever the thread count.
#[inline(always)]
fn tile_pairs<'a, U: InvSqrt>(
    t: Tiled<'_>,
    mut rows: Cols<'a>,
    mut cols: Option<Cols<'a>>,
) -> Vec<usize> {
    let mut saved: Vec<f64> = Vec::new();
    for c in std::iter::once(&rows).chain(cols.as_ref()) {
        saved.extend_from_slice(c.x);
        saved.extend_from_slice(c.y);
        saved.extend_from_slice(c.z);
    }
    let reach = |c: &Cols<'_>| {
        t.reach_a[c.base..c.base + c.x.len()]
            .iter()
            .fold(0.0f64, |m, &a| m.max(a))
    };
    let reach_cols = cols.as_ref().map_or_else(|| reach(&rows), reach);
    let mut overlap = false;
    for_half_rows!(&mut rows, cols.as_mut(), |i, c| {
        let (u, r2_min) = half_row::<U, false>(t, i, c);
        let contact = t.reach_a[i] + reach_cols;
        // A partner within reach of the tile's largest: look for an overlap (the far-field form
        // is right for every other pair); coincident spheres (r² = 0) never are clear, nor a NaN.
        let clear = r2_min > contact * contact;
        if !overlap && !clear {
            overlap = overlapping_in(t, i, c).next().is_some();
        }
        u
    });
    if !overlap {
        return Vec::new();
    }
    let mut from = saved.into_iter();
    for c in std::iter::once(&mut rows).chain(cols.as_mut()) {
        for v in [&mut *c.x, &mut *c.y, &mut *c.z] {
            v.iter_mut().zip(&mut from).for_each(|(v, s)| *v = s);
        }
    }
    let mut masked = Vec::new();
    for_half_rows!(&mut rows, cols.as_mut(), |i, c| {
        let (u, m) = half_row::<U, true>(t, i, c);
        if m > 0.0 {
            masked.push(i);
            masked.extend(overlapping_in(t, i, c));
        }
        u
    });
    masked
}

vector_dispatch! {
    /// [`tile_pairs`] in the widest vector unit present.
    fn tile_pairs_dispatch(t: Tiled<'_>, r: Cols<'_>, c: Option<Cols<'_>>) -> Vec<usize> = tile_pairs::<InvSqrt>;
}

/// The accumulators split into tiles of `tile` spheres.
fn tiles<'a>(
    x: &'a mut [f64],
    y: &'a mut [f64],
    z: &'a mut [f64],
    tile: usize,
) -> Vec<Option<Cols<'a>>> {
    x.chunks_mut(tile)
        .zip(y.chunks_mut(tile))
        .zip(z.chunks_mut(tile))
        .enumerate()
        .map(|(c, ((x, y), z))| {
            Some(Cols {
                base: c * tile,
                x,
                y,
                z,
            })
        })
        .collect()
}

/// The rounds of a round-robin tournament of `t` tiles: in each round every tile meets at most
/// one other, so a round's tile pairs write disjoint accumulators and run in parallel, and every
/// sphere's sum runs in the same order whatever the thread count. Every pair of distinct tiles
/// meets in exactly one round (the circle method).
pub fn tile_rounds(t: usize) -> Vec<Vec<(usize, usize)>> {
    let players = t + t % 2;
    (0..players.saturating_sub(1))
        .map(|r| {
            (0..players / 2)
                .map(|q| {
                    let m = players - 1;
                    let a = (r + q) % m;
                    let b = if q == 0 { m } else { (r + m - q) % m };
                    (a.min(b), a.max(b))
                })
                .filter(|&(_, b)| b < t)
                .collect()
        })
        .collect()
}

/// u_i = Σ_{j≠i} H_ij F_j evaluating each pair once (H_ji = H_ij, so one evaluation gives both
/// ends' terms): spheres in tiles ([`MIN_TILE`]); first every tile with itself, then the rounds of
/// [`tile_rounds`], each round's tile pairs in parallel (on rayon's pool) when `parallel`. The
/// order in which each sphere's terms add up is fixed by the tiles and rounds alone, so the
/// result does not depend on the thread count.
pub fn symmetric_velocities(
    m: Mobility,
    mu: f64,
    s: &SoaSpheres,
    u: &mut [[f64; 3]],
    parallel: bool,
) {
    let (c1, c3) = prefactors(m, mu);
    let k = Kernel { m, mu, c1, c3 };
    let n = s.len();
    // Oseen has no finite size: nothing but coincident spheres is masked.
    let reach = if c3 != 0.0 { 1.0 } else { 0.0 };
    let reach_a: Vec<f64> = s.a.iter().map(|a| a * reach).collect();
    let a2s: Vec<f64> = s.a2.iter().map(|a2| c3 / c1 * a2).collect();
    let kt = Tiled {
        s,
        reach_a: &reach_a,
        a2s: &a2s,
    };
    let (mut ux, mut uy, mut uz) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let tile = (n / 32).next_multiple_of(LANES).clamp(MIN_TILE, MAX_TILE);
    let t = n.div_ceil(tile);
    let mut masked: Vec<usize> = Vec::new();
    let run = |tasks: Vec<(Cols<'_>, Option<Cols<'_>>)>| -> Vec<usize> {
        if parallel {
            tasks
                .into_par_iter()
                .map(|(r, c)| tile_pairs_dispatch(kt, r, c))
                .flatten()
                .collect()
        } else {
            tasks
                .into_iter()
                .flat_map(|(r, c)| tile_pairs_dispatch(kt, r, c))
                .collect()
        }
    };
    let diagonal: Vec<_> = tiles(&mut ux, &mut uy, &mut uz, tile)
        .into_iter()
        .flatten()
        .map(|c| (c, None))
        .collect();
    masked.extend(run(diagonal));
    for round in tile_rounds(t) {
        let mut all = tiles(&mut ux, &mut uy, &mut uz, tile);
        let tasks: Vec<_> = round
            .iter()
            .filter_map(|&(a, b)| Some((all[a].take()?, Some(all[b].take()?))))
            .collect();
        masked.extend(run(tasks));
    }
    for (i, out) in u.iter_mut().enumerate() {
        *out = [c1 * ux[i], c1 * uy[i], c1 * uz[i]];
    }
    masked.sort_unstable();
    masked.dedup();
    for i in masked {
        add_overlapping(s, k, i, &mut u[i]);
    }
}
