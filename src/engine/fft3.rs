//! Three-dimensional complex FFTs on a periodic grid (rustfft along each axis, rows in
//! parallel), shared by the spectral Ewald mobility and the continuum theory.
//!
//! A field is a `Vec<Complex64>` with x fastest, then y, then z. The forward transform leaves it
//! with z fastest, then y, then x (the layout the axis passes end in, saving a transpose); the
//! inverse takes that layout back to x fastest and does not divide by the number of points.

use rayon::prelude::*;
use rustfft::num_complex::Complex64;
use rustfft::{Fft, FftPlanner};
use std::sync::Arc;

/// Forward and inverse plans per axis of a grid of `m` points.
#[derive(Clone)]
pub struct Fft3 {
    m: [usize; 3],
    plans: [[Arc<dyn Fft<f64>>; 2]; 3],
}

impl Fft3 {
    /// Plans for a grid of `m` = [mx, my, mz] points.
    pub fn new(m: [usize; 3]) -> Self {
        let mut planner = FftPlanner::new();
        let plans = [0, 1, 2].map(|a| {
            [
                planner.plan_fft_forward(m[a]),
                planner.plan_fft_inverse(m[a]),
            ]
        });
        Fft3 { m, plans }
    }

    /// Forward transform of `grid` (x fastest) in place, into z fastest, then y, then x; `spare`
    /// is scratch of the same length.
    pub fn forward(&self, grid: &mut [Complex64], spare: &mut [Complex64]) {
        let [mx, my, mz] = self.m;
        rows(&*self.plans[0][0], grid, mx * my);
        transpose_planes(grid, spare, mx, my);
        rows(&*self.plans[1][0], spare, my * mx);
        // (y, x, z) → (z, y, x).
        yxz_to_zyx(spare, grid, self.m);
        rows(&*self.plans[2][0], grid, mz * my);
    }

    /// Inverse transform of `grid` (z fastest) in place, back to x fastest, not normalised.
    pub fn inverse(&self, grid: &mut [Complex64], spare: &mut [Complex64]) {
        let [mx, my, mz] = self.m;
        rows(&*self.plans[2][1], grid, mz * my);
        zyx_to_yxz(grid, spare, self.m);
        rows(&*self.plans[1][1], spare, my * mx);
        transpose_planes(spare, grid, my, mx);
        rows(&*self.plans[0][1], grid, mx * my);
    }
}

/// The wave index of FFT output `i` of `n`: i up to n/2, i − n above.
pub fn signed_mode(i: usize, n: usize) -> f64 {
    if i <= n / 2 {
        i as f64
    } else {
        i as f64 - n as f64
    }
}

/// Transform every contiguous row of length `fft.len()` of `data`, in parallel chunks of
/// `chunk` points (a multiple of the row length).
fn rows(fft: &dyn Fft<f64>, data: &mut [Complex64], chunk: usize) {
    let scratch_len = fft.get_inplace_scratch_len();
    data.par_chunks_mut(chunk).for_each_init(
        || vec![Complex64::default(); scratch_len],
        |scratch, c| fft.process_with_scratch(c, scratch),
    );
}

/// Each plane of `src` (`rows` rows of `cols` points) transposed into `dst`: dst[r + rows·c] =
/// src[c + cols·r], plane by plane ((x, y, z) ↔ (y, x, z) layouts, each's first index fastest).
fn transpose_planes(src: &[Complex64], dst: &mut [Complex64], cols: usize, rows: usize) {
    dst.par_chunks_mut(cols * rows)
        .zip(src.par_chunks(cols * rows))
        .for_each(|(to, from)| {
            for c in 0..cols {
                for r in 0..rows {
                    to[r + rows * c] = from[c + cols * r];
                }
            }
        });
}

/// dst(z, y, x) = src(y, x, z).
fn yxz_to_zyx(src: &[Complex64], dst: &mut [Complex64], [mx, my, mz]: [usize; 3]) {
    dst.par_chunks_mut(mz * my)
        .enumerate()
        .for_each(|(x, slab)| {
            for z in 0..mz {
                let from = &src[my * (x + mx * z)..my * (x + mx * z) + my];
                for (y, v) in from.iter().enumerate() {
                    slab[z + mz * y] = *v;
                }
            }
        });
}

/// dst(y, x, z) = src(z, y, x).
fn zyx_to_yxz(src: &[Complex64], dst: &mut [Complex64], [mx, my, mz]: [usize; 3]) {
    dst.par_chunks_mut(my * mx)
        .enumerate()
        .for_each(|(z, plane)| {
            for x in 0..mx {
                for y in 0..my {
                    plane[y + my * x] = src[z + mz * (y + my * x)];
                }
            }
        });
}
