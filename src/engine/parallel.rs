//! From how many spheres a pair sum runs on rayon's threads. One product must be long enough
//! that rayon's dispatch (a few µs) is a negligible share of it; how many spheres that takes
//! follows from the cost of one pair, so the threshold differs by the kind of pair sum (the
//! timings are in the book's design notes, "When the pair kernels take over, and when rows go
//! parallel").

/// Pairs in open space (the RPY or Oseen rows, steric forces, gaps): a pair costs a few dozen
/// flops, and a product of 256 spheres about 0.3 ms.
pub const PARALLEL_SPHERES: usize = 256;

/// Pairs summed with their images (the wall's Blake image terms; the box's Ewald sums over
/// images and waves): a pair costs several open-space pairs, so a product is long enough from
/// fewer spheres (the wall's terms about 0.1 ms at 64).
pub const PARALLEL_IMAGE_SPHERES: usize = 64;
