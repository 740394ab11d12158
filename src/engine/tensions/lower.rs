//! Products of a symmetric K from its part on and below the diagonal, in vector lanes, and for
//! a large K in runs of columns on rayon's threads.

use crate::engine::parallel::map_indices;
use crate::engine::simd::{lane_sum, vector_dispatch, LANES};
use nalgebra::{DMatrix, DVector};

/// q = K p for a symmetric K of which only the part on and below the diagonal is read (the part
/// above may hold anything): each column's lower part once, as a dot product for q_τ and an axpy
/// for the rows below it.
///
/// A large K is taken in runs of columns of about [`LOWER_PRODUCT_RUN`] entries each, on rayon's
/// threads, each into a vector of its own, and those are added in order: how many runs there are
/// depends on S alone, so the result does not depend on the threads.
pub(super) fn lower_mul_to(k: &DMatrix<f64>, p: &DVector<f64>, q: &mut DVector<f64>) {
    let count = p.len();
    let (k, p, q) = (k.as_slice(), p.as_slice(), q.as_mut_slice());
    let entries = count * (count + 1) / 2;
    let runs = (entries / LOWER_PRODUCT_RUN).clamp(1, 16);
    if runs == 1 {
        return lower_product(k, p, q, 0..count);
    }
    // Column boundaries that give each run about an equal share of the entries.
    let mut bounds = vec![0];
    let mut taken = 0;
    for tau in 0..count {
        taken += count - tau;
        if taken * runs >= entries * bounds.len() && bounds.len() < runs {
            bounds.push(tau + 1);
        }
    }
    bounds.push(count);
    let parts = map_indices(
        bounds.len() - 1,
        true,
        || (),
        |_, r| {
            let mut part = vec![0.0; count];
            lower_product(k, p, &mut part, bounds[r]..bounds[r + 1]);
            part
        },
    );
    q.fill(0.0);
    for part in &parts {
        for (qs, v) in q.iter_mut().zip(part) {
            *qs += v;
        }
    }
}

/// Entries of K's lower part per run of columns in [`lower_mul_to`] (runs from 512 rows): a run
/// reads 512 kB, tens of µs, far more than handing it to rayon's pool costs.
const LOWER_PRODUCT_RUN: usize = 1 << 16;

/// q = the columns `columns` of [`lower_mul_to`]'s product on the column-major entries `k` of an
/// S×S matrix (q is zeroed first).
#[inline(always)]
fn lower_product_body(k: &[f64], p: &[f64], q: &mut [f64], columns: std::ops::Range<usize>) {
    let count = p.len();
    q.fill(0.0);
    for tau in columns {
        let col = &k[tau * count..(tau + 1) * count];
        let (diag, below, rest) = (col[tau], &col[tau + 1..], &p[tau + 1..]);
        let pt = p[tau];
        for (qs, ks) in q[tau + 1..].iter_mut().zip(below) {
            *qs += ks * pt;
        }
        // The dot product in lanes (separate sums, so that it vectorises), then the tail.
        let mut lanes = [0.0; LANES];
        let (blocks, tail) = below.split_at(below.len() / LANES * LANES);
        for (kb, pb) in blocks.chunks_exact(LANES).zip(rest.chunks_exact(LANES)) {
            for l in 0..LANES {
                lanes[l] += kb[l] * pb[l];
            }
        }
        let mut dot = diag * pt + lane_sum(&lanes);
        for (ks, ps) in tail.iter().zip(&rest[blocks.len()..]) {
            dot += ks * ps;
        }
        q[tau] += dot;
    }
}

vector_dispatch! {
    /// [`lower_product_body`] in the widest vector unit present.
    fn lower_product(k: &[f64], p: &[f64], q: &mut [f64], columns: std::ops::Range<usize>) = lower_product_body;
}
