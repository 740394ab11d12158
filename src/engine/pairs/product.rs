//! The product both kernels compute, u_i = Σ_{j≠i} H_ij F_j, by rows or each pair once as the
//! sphere count decides.

use super::rows::row_velocities;
use super::soa::SoaSpheres;
use super::tiles::symmetric_velocities;
use crate::engine::mobility::Mobility;

/// From this many spheres [`interaction_velocities`] evaluates each pair once
/// ([`symmetric_velocities`]); below, short tiles' scalar tails cost more than the halved
/// arithmetic saves, and it runs by rows ([`row_velocities`]).
pub const SYMMETRIC_SPHERES: usize = 512;

/// u_i = Σ_{j≠i} H_ij F_j for every sphere: [`symmetric_velocities`] from [`SYMMETRIC_SPHERES`]
/// spheres, [`row_velocities`] below.
pub fn interaction_velocities(
    m: Mobility,
    mu: f64,
    s: &SoaSpheres,
    u: &mut [[f64; 3]],
    parallel: bool,
) {
    if s.len() >= SYMMETRIC_SPHERES {
        symmetric_velocities(m, mu, s, u, parallel)
    } else {
        row_velocities(m, mu, s, u, parallel)
    }
}
