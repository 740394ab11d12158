//! The averaged rows over a neighbour list ([`crate::engine::neighbours`]): the all-pairs lanes'
//! arithmetic ([`super::lanes::side`]) over each row's far partners, [`LANES`] at a time. A block
//! gathers its partners' slot positions and orientations; the pair's phase sine is the list's
//! weight, fixed at the build; pairs beyond the cutoff (the list holds the skin too) and the pad
//! get 1/D = 0 by a select, which zeroes every term; the cutoff's switch weighs the rest. Slot positions already carry the image each pair is met at, so a
//! pair is a plain difference. Each lane accumulates its own partners and the lanes are summed
//! in a fixed order: a row depends on neither the thread count nor the vector width.

use super::arrays::{SlotConst, Soa};
use super::lanes::{side, Acc};
use super::system::AveragedSystem;
use super::terms::CutoffSwitch;
use crate::engine::neighbours::NeighbourList;
use crate::engine::simd::{lane_sum, vector_dispatch, LANES};
use nalgebra::Vector3;

/// One partner's terms added to the row's accumulators: the row at `at` with orientation `n` and
/// prefactors `k`, the partner at (x, y, z) with orientation (bx, by, bz) and phase sine `sin`.
#[inline(always)]
fn list_term<const IK: bool>(
    at: &[f64; 3],
    n: &[f64; 3],
    k: [f64; 4],
    cutoff2: f64,
    switch: CutoffSwitch,
    p: [f64; 7],
    acc: Acc,
) -> Acc {
    let [x, y, z, bx, by, bz, sin] = p;
    let (dx, dy, dz) = (at[0] - x, at[1] - y, at[2] - z);
    let d2 = dx.mul_add(dx, dy.mul_add(dy, dz * dz));
    // A pair beyond the cutoff (or the pad, whose d² is infinite) gets 1/D = 0: every term
    // carries a power of 1/D, and D̂ = 0 keeps the brackets finite.
    let inv = if d2 <= cutoff2 { 1.0 / d2.sqrt() } else { 0.0 };
    let sin = sin * switch.at(d2 * inv);
    let h = [dx * inv, dy * inv, dz * inv];
    let dot = |u: [f64; 3], v: [f64; 3]| u[0].mul_add(v[0], u[1].mul_add(v[1], u[2] * v[2]));
    let b = [bx, by, bz];
    let (ss, rr, q) = (dot(h, *n), dot(h, b), dot(*n, b));
    side::<IK>(k, sin, inv, ss, rr, q, h, acc)
}

#[inline(always)]
fn row_impl(
    sys: &AveragedSystem,
    list: &NeighbourList,
    slots: &Soa,
    consts: &[SlotConst],
    k: usize,
) -> (Vector3<f64>, Vector3<f64>) {
    let pre = consts[k].pre;
    if pre[2] != 0.0 || pre[3] != 0.0 {
        row_with::<true>(sys, list, slots, k, pre)
    } else {
        row_with::<false>(sys, list, slots, k, pre)
    }
}

#[inline(always)]
fn row_with<const IK: bool>(
    sys: &AveragedSystem,
    list: &NeighbourList,
    slots: &Soa,
    k: usize,
    pre: [f64; 4],
) -> (Vector3<f64>, Vector3<f64>) {
    let at = [slots.x[k], slots.y[k], slots.z[k]];
    let n = [slots.nx[k], slots.ny[k], slots.nz[k]];
    let (partners, weights) = list.far_row(k);
    let mut acc = [[0.0; LANES]; 7];
    let fields = [
        &slots.x[..],
        &slots.y[..],
        &slots.z[..],
        &slots.nx[..],
        &slots.ny[..],
        &slots.nz[..],
    ];
    for (idx, w) in partners
        .chunks_exact(LANES)
        .zip(weights.chunks_exact(LANES))
    {
        // The block's partners, gathered field by field.
        let mut p = [[0.0; LANES]; 7];
        for (f, src) in fields.iter().enumerate() {
            for l in 0..LANES {
                debug_assert!((idx[l] as usize) < src.len());
                // SAFETY: every partner is a slot of the list, and the slot arrays hold all
                // slots (`NeighbourList::fill_positions`, `fill_values`).
                p[f][l] = unsafe { *src.get_unchecked(idx[l] as usize) };
            }
        }
        p[6].copy_from_slice(w);
        for l in 0..LANES {
            let t = list_term::<IK>(
                &at,
                &n,
                pre,
                sys.cutoff2,
                sys.switch,
                std::array::from_fn(|f| p[f][l]),
                std::array::from_fn(|m| acc[m][l]),
            );
            for m in 0..7 {
                acc[m][l] = t[m];
            }
        }
    }
    let [vn, v0, v1, v2, t0, t1, t2] = acc.map(|a| lane_sum(&a));
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
    /// dR_H/dt of the swimmer in slot `k` and its torque-like sum T over its far partners.
    pub(super) fn row(sys: &AveragedSystem, list: &NeighbourList, slots: &Soa, consts: &[SlotConst], k: usize) -> (Vector3<f64>, Vector3<f64>) = row_impl;
}
