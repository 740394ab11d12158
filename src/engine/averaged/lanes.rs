//! The averaged rows over all partners in blocks of [`LANES`]: the scalar row's arithmetic, one
//! partner per lane, with the pairs it skips (itself, a zero phase difference, beyond the cutoff)
//! masked to a zero sine instead of branched around, so the compiler maps the block onto vector
//! registers (AVX-512 or AVX2, chosen at run time; the same code, so the same sums). Each lane
//! accumulates its own partners and the lanes are summed in a fixed order: the result depends on
//! neither the thread count nor the vector width, and equals the scalar row's to the rounding of
//! another summation order.

use super::{AveragedSystem, SIN_ZERO};
use nalgebra::Vector3;

/// Partners per block.
pub const LANES: usize = 8;

/// Sum of the lanes in a fixed pairwise order.
#[inline(always)]
fn lane_sum(a: &[f64; LANES]) -> f64 {
    ((a[0] + a[4]) + (a[1] + a[5])) + ((a[2] + a[6]) + (a[3] + a[7]))
}

#[inline(always)]
fn row_impl(sys: &AveragedSystem, s: usize) -> (Vector3<f64>, Vector3<f64>) {
    let c = &sys.coef[s];
    let soa = &sys.soa;
    let n = sys.coef.len();
    let (xs, ys, zs) = (soa.x[s], soa.y[s], soa.z[s]);
    let (ax, ay, az) = (soa.nx[s], soa.ny[s], soa.nz[s]);
    let (sin_s, cos_s) = (sys.sin_phi[s], sys.cos_phi[s]);
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
    let (skip_zero, cutoff2) = (sys.skip_zero_phase, sys.cutoff2);
    let kj = c.c_j * c.v0 * (9.0 / 64.0);
    let kl = c.w0 * (15.0 / 64.0) * c.big_l;
    let ki = with_i * c.a_r * c.v0 * (9.0 / 64.0) * c.big_l;
    let kk = with_k * c.a_n * c.w0 * (9.0 / 32.0) * c.big_l;
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

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn row_avx512(sys: &AveragedSystem, s: usize) -> (Vector3<f64>, Vector3<f64>) {
    row_impl(sys, s)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn row_avx2(sys: &AveragedSystem, s: usize) -> (Vector3<f64>, Vector3<f64>) {
    row_impl(sys, s)
}

/// dR_H/dt of swimmer σ and the torque-like sum T over all partners, in lanes.
pub(super) fn row(sys: &AveragedSystem, s: usize) -> (Vector3<f64>, Vector3<f64>) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx512f") {
            // SAFETY: the CPU has AVX-512F (checked just above).
            return unsafe { row_avx512(sys, s) };
        }
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2 (checked just above).
            return unsafe { row_avx2(sys, s) };
        }
    }
    row_impl(sys, s)
}
