//! The fast all-pairs kernels of the sphere models: u_i = Σ_{j≠i} H_ij F_j for thousands of spheres.
//!
//! Layout for SIMD: structure of arrays (x, y, z, radius, force components as separate f64
//! slices); a sphere runs over its partners in blocks of [`LANES`] independent accumulators,
//! which the compiler maps onto vector registers (AVX-512, AVX2+FMA or SSE2, chosen at run time).
//! Two kernels:
//!
//! - **Each pair once** ([`symmetric_velocities`], from [`SYMMETRIC_SPHERES`] spheres): H_ji =
//!   H_ij, so one evaluation (one 1/r) gives both ends' terms, the partner's added into its
//!   accumulator in the same pass. Spheres are grouped in tiles; every tile with itself, then
//!   every two tiles, in the rounds of a round-robin tournament ([`tile_rounds`]): a round's tile
//!   pairs touch disjoint accumulators, so they run in parallel with rayon. A tile pair runs
//!   without overlap masks unless one of its pairs overlaps (then it is redone with them), and
//!   in the AVX-512 build takes 1/r from the 14-bit estimate and one correction
//!   ([`crate::engine::simd::Avx512InvSqrt`]). More interactions per second than the rows (the
//!   book, "Suspensions and the CPU pair kernel"; the factor is in its design notes).
//! - **By rows** ([`row_velocities`]): each row i sums over all j, every pair evaluated from both
//!   ends; rows are independent and run in parallel.
//!
//! Either way each sphere's terms add up in an order fixed by the sphere count alone, whatever the
//! thread count (multiply-adds are fused only where written, and a fused one rounds the same in
//! every width), so results do not depend on it; the rows do not depend on the vector width
//! either, and the tiles only through the AVX-512 build's 1/r (within 2 ulp of a square root and
//! a division). The j = i term and overlapping pairs are removed by a select, not a branch, and
//! added afterwards in a scalar pass. The symmetric half-loop of
//! [`crate::engine::mobility::Mobility::interaction_velocities`] remains the reference and serves
//! small scenes.
//!
//! The sphere data in `soa`, the pair tensor's shared constants in `tensor`, the rows in `rows`,
//! each pair once in `tiles`, and the choice between the two by size in `product`.

mod product;
mod rows;
mod soa;
mod tensor;
mod tiles;

/// Independent accumulators per row.
pub use crate::engine::simd::LANES;
pub use product::{interaction_velocities, SYMMETRIC_SPHERES};
pub use rows::row_velocities;
pub use soa::SoaSpheres;
pub use tiles::{symmetric_velocities, tile_rounds};
