//! K filled: entry by entry from the boundary's blocks (a few swimmers, and the fallback), or
//! from the pair coefficients in vector lanes, its part on and below the diagonal (open space,
//! a box's minimum images for the preconditioner, and above a wall with the image's terms).

use crate::engine::boundary::PairTerms;
use crate::engine::mobility::{self_mobility, Mobility};
use crate::engine::parallel::{PARALLEL_IMAGE_SPHERES, PARALLEL_SPHERES};
use crate::engine::periodic::separation;
use crate::engine::simd::vector_dispatch;
use crate::engine::spheres::Spheres;
use crate::engine::wall::image_coefficients;
use nalgebra::{DMatrix, Vector3};
use rayon::prelude::*;

/// K_στ from the boundary's blocks: 4 per pair of dumbbells.
pub(super) fn k_entry(spheres: &Spheres, n: &[Vector3<f64>], sg: usize, tau: usize) -> f64 {
    let (i1, i2, j1, j2) = (2 * sg, 2 * sg + 1, 2 * tau, 2 * tau + 1);
    let nt = n[tau];
    let h = |a, b| spheres.block_apply(a, b, &nt);
    n[sg].dot(&((h(i1, j1) - h(i2, j1)) - (h(i1, j2) - h(i2, j2))))
}

/// K filled from the boundary's blocks.
pub(super) fn fill_blocks(spheres: &Spheres, n: &[Vector3<f64>], k: &mut DMatrix<f64>) {
    let count = n.len();
    for tau in 0..count {
        for sg in 0..=tau {
            let v = k_entry(spheres, n, sg, tau);
            k[(sg, tau)] = v;
            k[(tau, sg)] = v;
        }
    }
}

/// The dumbbells as a K fill reads them: sphere centres (above a wall: relative to it, lifted),
/// radii, squared radii, damping factors (1 off a wall) and orientations in lanes, and the
/// constants of the pair tensor.
struct KLanes {
    p1: [Vec<f64>; 3],
    p2: [Vec<f64>; 3],
    n: [Vec<f64>; 3],
    a1: Vec<f64>,
    a2: Vec<f64>,
    q1: Vec<f64>,
    q2: Vec<f64>,
    d1: Vec<f64>,
    d2: Vec<f64>,
    /// 1/(8πμ).
    c8: f64,
    /// 1/3 for RPY (its a² term), 0 for Oseen; above a wall 3 × it scales the image radii (RPY's
    /// are the radii, Oseen's image is a point force's).
    finite: f64,
    /// The box's sides and their inverses for minimum images (zeros elsewhere).
    l: [f64; 3],
    inv_l: [f64; 3],
}

/// A sphere as [`k_term`] reads it: its centre, radius, squared radius and damping factor.
type KSphere = ([f64; 3], f64, f64, f64);

/// One sphere pair's term of a K entry, N_σ·H_ab N_τ (with `WALL` the image term and the
/// damping), for sphere `a` of σ (whose velocity the row takes) and `b` of τ (whose force the
/// column applies), orientations `ns`, `nt` (`nn` their product); and d² − (a_a + a_b)².
#[inline(always)]
fn k_term<const WALL: bool>(
    l: &KLanes,
    ns: [f64; 3],
    nt: [f64; 3],
    nn: f64,
    (a, aa, qa, da): KSphere,
    (b, ab, qb, db): KSphere,
) -> (f64, f64) {
    let c8 = l.c8;
    // The minimum image (zeros outside a box); a tie between two images takes either, and the
    // term is even in r. `round_ties_even` is one vector instruction, `round` a call.
    let mut r = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    for d in 0..3 {
        r[d] -= l.l[d] * (r[d] * l.inv_l[d]).round_ties_even();
    }
    let d2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    let inv_d2 = 1.0 / d2;
    let o = c8 * inv_d2.sqrt();
    let f = l.finite * (qa + qb) * inv_d2 * o;
    let nsr = ns[0] * r[0] + ns[1] * r[1] + ns[2] * r[2];
    let ntr = nt[0] * r[0] + nt[1] * r[1] + nt[2] * r[2];
    let mut value = (o + f) * nn + (o - 3.0 * f) * nsr * ntr * inv_d2;
    if WALL {
        // R = x_a − x_b*: the in-plane separation, and the heights' sum.
        let sized = 3.0 * l.finite;
        let r3 = a[2] + b[2];
        let q = 1.0 / (r[0] * r[0] + r[1] * r[1] + r3 * r3).sqrt();
        let (ca, cb, cc, cd, ce) = image_coefficients(r3, b[2], sized * qa, sized * qb, q);
        let rs = ns[0] * r[0] + ns[1] * r[1];
        let rt = nt[0] * r[0] + nt[1] * r[1];
        let w = ca * (ns[0] * nt[0] + ns[1] * nt[1])
            + rs * (cb * rt + cc * nt[2])
            + ns[2] * (cd * rt + ce * nt[2]);
        value = (value + c8 * w) * (da * db);
    }
    let sum = aa + ab;
    (value, d2 - sum * sum)
}

/// Column τ of K for σ = τ, τ + 1, … (its part on and below the diagonal, `col[0]` the
/// diagonal) by the far-apart pair tensor (c_I = o + f, c_rr = o − 3f with o = 1/(8πμd),
/// f = (a_i² + a_j²) o/(3d²)), with `WALL` the wall's image term W_ab (its coefficients
/// [`image_coefficients`]) added and each sphere pair's term damped by d_a d_b; and in `margin`
/// the least d² − (a_i + a_j)² of the four sphere pairs (≤ 0 where a pair overlaps and the far
/// form does not hold).
#[inline(always)]
fn k_column_impl<const WALL: bool>(l: &KLanes, tau: usize, col: &mut [f64], margin: &mut [f64]) {
    let t1 = [l.p1[0][tau], l.p1[1][tau], l.p1[2][tau]];
    let t2 = [l.p2[0][tau], l.p2[1][tau], l.p2[2][tau]];
    let nt = [l.n[0][tau], l.n[1][tau], l.n[2][tau]];
    let (ta1, ta2, tq1, tq2) = (l.a1[tau], l.a2[tau], l.q1[tau], l.q2[tau]);
    let (td1, td2) = (l.d1[tau], l.d2[tau]);
    for (row, (entry, least)) in col.iter_mut().zip(margin.iter_mut()).enumerate() {
        let sg = tau + row;
        let ns = [l.n[0][sg], l.n[1][sg], l.n[2][sg]];
        let nn = ns[0] * nt[0] + ns[1] * nt[1] + ns[2] * nt[2];
        let s1 = [l.p1[0][sg], l.p1[1][sg], l.p1[2][sg]];
        let s2 = [l.p2[0][sg], l.p2[1][sg], l.p2[2][sg]];
        let (sa1, sa2, sq1, sq2) = (l.a1[sg], l.a2[sg], l.q1[sg], l.q2[sg]);
        let (sd1, sd2) = (l.d1[sg], l.d2[sg]);
        let (u1, u2) = ((s1, sa1, sq1, sd1), (s2, sa2, sq2, sd2));
        let (v1, v2) = ((t1, ta1, tq1, td1), (t2, ta2, tq2, td2));
        let (k11, m11) = k_term::<WALL>(l, ns, nt, nn, u1, v1);
        let (k12, m12) = k_term::<WALL>(l, ns, nt, nn, u1, v2);
        let (k21, m21) = k_term::<WALL>(l, ns, nt, nn, u2, v1);
        let (k22, m22) = k_term::<WALL>(l, ns, nt, nn, u2, v2);
        *entry = (k11 - k12) - (k21 - k22);
        *least = m11.min(m12).min(m21).min(m22);
    }
}

/// [`k_column_impl`] in open space (or at minimum images).
#[inline(always)]
fn k_column_body(l: &KLanes, tau: usize, col: &mut [f64], margin: &mut [f64]) {
    k_column_impl::<false>(l, tau, col, margin);
}

/// [`k_column_impl`] above a wall.
#[inline(always)]
fn k_wall_column_body(l: &KLanes, tau: usize, col: &mut [f64], margin: &mut [f64]) {
    k_column_impl::<true>(l, tau, col, margin);
}

vector_dispatch! {
    /// [`k_column_body`] in the widest vector unit present.
    fn k_column(l: &KLanes, tau: usize, col: &mut [f64], margin: &mut [f64]) = k_column_body;
}

vector_dispatch! {
    /// [`k_wall_column_body`] in the widest vector unit present.
    fn k_wall_column(l: &KLanes, tau: usize, col: &mut [f64], margin: &mut [f64]) = k_wall_column_body;
}

/// K filled from the pair coefficients, each sphere pair's tensor contracted with the two
/// orientations as it is made: N_σ·H N_τ = c_I N_σ·N_τ + c_rr (N_σ·r)(N_τ·r)/r² (and above a
/// wall N_σ·W N_τ, damped). Column by column in vector lanes (in parallel for many spheres); the
/// diagonal and any entry with overlapping spheres again exactly: by the pair coefficients, and
/// above a wall by the wall mobility's own blocks.
pub(super) fn fill_pairs(
    spheres: &Spheres,
    n: &[Vector3<f64>],
    fill: &PairTerms,
    k: &mut DMatrix<f64>,
) {
    let periodic = match fill {
        PairTerms::MinimumImages(b) => Some(b),
        _ => None,
    };
    let l = periodic.map_or([0.0; 3], |b| b.sides());
    let inv_l = l.map(|v| if v > 0.0 { 1.0 / v } else { 0.0 });
    let count = n.len();
    let (mu, mobility) = (spheres.mu, spheres.mobility);
    let (pos, radii) = (&spheres.pos, &spheres.radii);
    // Each sphere as the fill reads it: lifted above a wall, with its damping factor.
    let placed: Vec<(Vector3<f64>, f64)> = pos
        .iter()
        .zip(radii)
        .map(|(x, &a)| match fill {
            PairTerms::Wall(w) => w.lift(x, a),
            _ => (*x, 1.0),
        })
        .collect();
    let lane = |f: &dyn Fn(usize) -> f64| (0..count).map(f).collect::<Vec<f64>>();
    let lanes = KLanes {
        p1: [0, 1, 2].map(|c| lane(&|s| placed[2 * s].0[c])),
        p2: [0, 1, 2].map(|c| lane(&|s| placed[2 * s + 1].0[c])),
        n: [0, 1, 2].map(|c| lane(&|s| n[s][c])),
        a1: lane(&|s| radii[2 * s]),
        a2: lane(&|s| radii[2 * s + 1]),
        q1: lane(&|s| radii[2 * s] * radii[2 * s]),
        q2: lane(&|s| radii[2 * s + 1] * radii[2 * s + 1]),
        d1: lane(&|s| placed[2 * s].1),
        d2: lane(&|s| placed[2 * s + 1].1),
        c8: 1.0 / (8.0 * std::f64::consts::PI * mu),
        finite: if mobility == Mobility::Rpy {
            1.0 / 3.0
        } else {
            0.0
        },
        l,
        inv_l,
    };
    // An entry exactly: open space's pair coefficients contracted at once (at the box's minimum
    // images for its preconditioner; the box's own blocks are whole Ewald sums), and above a wall
    // the wall mobility's own blocks.
    let exact = |sg: usize, tau: usize| {
        if let PairTerms::Wall(_) = fill {
            return k_entry(spheres, n, sg, tau);
        }
        let (ns, nt) = (n[sg], n[tau]);
        let nn = ns.dot(&nt);
        let mut sum = 0.0;
        for (a, sign_a) in [(2 * sg, 1.0), (2 * sg + 1, -1.0)] {
            for (b, sign_b) in [(2 * tau, 1.0), (2 * tau + 1, -1.0)] {
                let term = if a == b {
                    self_mobility(mu, radii[a]) * nn
                } else {
                    let r = separation(periodic, pos[a] - pos[b]);
                    let d2 = r.norm_squared();
                    let (ci, crr) = mobility.pair_coefficients(mu, d2.sqrt(), radii[a], radii[b]);
                    ci * nn + crr * ns.dot(&r) * nt.dot(&r) / d2
                };
                sum += sign_a * sign_b * term;
            }
        }
        sum
    };
    let wall = matches!(fill, PairTerms::Wall(_));
    // Only the part on and below the diagonal: K is symmetric, and its products read that part
    // alone ([`lower_mul_to`]).
    let column = |tau: usize, col: &mut [f64], margin: &mut Vec<f64>| {
        let lower = &mut col[tau..];
        margin.resize(lower.len(), 0.0);
        if wall {
            k_wall_column(&lanes, tau, lower, margin);
        } else {
            k_column(&lanes, tau, lower, margin);
        }
        for (row, (entry, m)) in lower.iter_mut().zip(margin.iter()).enumerate() {
            if row == 0 || m.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                *entry = exact(tau + row, tau);
            }
        }
    };
    let data = k.as_mut_slice();
    // The fill has the 2S² sphere pairs of a product of 2S spheres; above a wall each carries
    // the image's terms too, so it goes to rayon's threads where the wall's product does.
    let parallel_from = if wall {
        PARALLEL_IMAGE_SPHERES
    } else {
        PARALLEL_SPHERES
    };
    if 2 * count >= parallel_from {
        data.par_chunks_mut(count)
            .enumerate()
            .for_each_init(Vec::new, |margin, (tau, col)| column(tau, col, margin));
    } else {
        let mut margin = Vec::new();
        for (tau, col) in data.chunks_mut(count).enumerate() {
            column(tau, col, &mut margin);
        }
    }
}
