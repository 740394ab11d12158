//! What both kernels share: the prefactors of the pair tensor, and the scalar pass that adds
//! the overlapping pairs' terms.

use super::soa::SoaSpheres;
use crate::engine::mobility::Mobility;
use std::f64::consts::PI;

/// Prefactors 1/(8πμ) and, for RPY, 1/(24πμ) (0 for Oseen).
pub(super) fn prefactors(m: Mobility, mu: f64) -> (f64, f64) {
    let c3 = match m {
        Mobility::Rpy => 1.0 / (24.0 * PI * mu),
        Mobility::Oseen => 0.0,
    };
    (1.0 / (8.0 * PI * mu), c3)
}

/// The kernel's constants: the mobility with μ, and its prefactors.
#[derive(Clone, Copy)]
pub(super) struct Kernel {
    pub(super) m: Mobility,
    pub(super) mu: f64,
    pub(super) c1: f64,
    pub(super) c3: f64,
}

/// Adds the terms of the spheres overlapping sphere `i` (skipped by the vector loop) to `out`.
#[cold]
pub(super) fn add_overlapping(s: &SoaSpheres, k: Kernel, i: usize, out: &mut [f64; 3]) {
    let xi = nalgebra::Vector3::new(s.x[i], s.y[i], s.z[i]);
    for j in 0..s.len() {
        let r = xi - nalgebra::Vector3::new(s.x[j], s.y[j], s.z[j]);
        let r2 = r.norm_squared();
        let contact = if k.c3 != 0.0 { s.a[i] + s.a[j] } else { 0.0 };
        if j != i && r2 <= contact * contact {
            let f = nalgebra::Vector3::new(s.fx[j], s.fy[j], s.fz[j]);
            let v = k.m.pair_apply(k.mu, &r, s.a[i], s.a[j], &f);
            out[0] += v.x;
            out[1] += v.y;
            out[2] += v.z;
        }
    }
}
