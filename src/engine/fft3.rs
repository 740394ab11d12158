//! Three-dimensional complex FFTs on a periodic grid (rustfft along each axis, rows in
//! parallel on grids of [`PARALLEL_GRID_POINTS`] and more), shared by the spectral Ewald mobility
//! and the continuum theory.
//!
//! A field is a `Vec<Complex64>` with x fastest, then y, then z. The forward transform leaves it
//! with z fastest, then y, then x (the layout the axis passes end in, saving a transpose); the
//! inverse takes that layout back to x fastest and does not divide by the number of points.

use crate::engine::parallel::{for_chunks_mut, PARALLEL_GRID_POINTS};
use rustfft::num_complex::Complex64;
use rustfft::{Fft, FftPlanner};
use std::sync::Arc;

/// Forward and inverse plans per axis of a grid of `m` points.
#[derive(Clone)]
pub struct Fft3 {
    m: [usize; 3],
    plans: [[Arc<dyn Fft<f64>>; 2]; 3],
    /// Whether the passes run on rayon's threads (the grid has [`PARALLEL_GRID_POINTS`]).
    parallel: bool,
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
        let parallel = m.iter().product::<usize>() >= PARALLEL_GRID_POINTS;
        Fft3 { m, plans, parallel }
    }

    /// Forward transform of `grid` (x fastest) in place, into z fastest, then y, then x; `spare`
    /// is scratch of the same length.
    pub fn forward(&self, grid: &mut [Complex64], spare: &mut [Complex64]) {
        let [mx, my, mz] = self.m;
        let par = self.parallel;
        rows(&*self.plans[0][0], grid, mx * my, par);
        transpose_planes(grid, spare, mx, my, par);
        rows(&*self.plans[1][0], spare, my * mx, par);
        // (y, x, z) → (z, y, x).
        yxz_to_zyx(spare, grid, self.m, par);
        rows(&*self.plans[2][0], grid, mz * my, par);
    }

    /// Inverse transform of `grid` (z fastest) in place, back to x fastest, not normalised.
    pub fn inverse(&self, grid: &mut [Complex64], spare: &mut [Complex64]) {
        let [mx, my, mz] = self.m;
        let par = self.parallel;
        rows(&*self.plans[2][1], grid, mz * my, par);
        zyx_to_yxz(grid, spare, self.m, par);
        rows(&*self.plans[1][1], spare, my * mx, par);
        transpose_planes(spare, grid, my, mx, par);
        rows(&*self.plans[0][1], grid, mx * my, par);
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

/// Transform every contiguous row of length `fft.len()` of `data`, in chunks of `chunk` points
/// (a multiple of the row length), in parallel where `par`.
fn rows(fft: &dyn Fft<f64>, data: &mut [Complex64], chunk: usize, par: bool) {
    let scratch_len = fft.get_inplace_scratch_len();
    for_chunks_mut(
        data,
        chunk,
        par,
        || vec![Complex64::default(); scratch_len],
        |scratch, _, c| fft.process_with_scratch(c, scratch),
    );
}

/// Each plane of `src` (`rows` rows of `cols` points) transposed into `dst`: dst[r + rows·c] =
/// src[c + cols·r], plane by plane ((x, y, z) ↔ (y, x, z) layouts, each's first index fastest).
fn transpose_planes(src: &[Complex64], dst: &mut [Complex64], cols: usize, rows: usize, par: bool) {
    let plane = cols * rows;
    for_chunks_mut(
        dst,
        plane,
        par,
        || (),
        |_, k, to| {
            let from = &src[k * plane..(k + 1) * plane];
            for c in 0..cols {
                for r in 0..rows {
                    to[r + rows * c] = from[c + cols * r];
                }
            }
        },
    );
}

/// dst(z, y, x) = src(y, x, z).
fn yxz_to_zyx(src: &[Complex64], dst: &mut [Complex64], [mx, my, mz]: [usize; 3], par: bool) {
    for_chunks_mut(
        dst,
        mz * my,
        par,
        || (),
        |_, x, slab| {
            for z in 0..mz {
                let from = &src[my * (x + mx * z)..my * (x + mx * z) + my];
                for (y, v) in from.iter().enumerate() {
                    slab[z + mz * y] = *v;
                }
            }
        },
    );
}

/// dst(y, x, z) = src(z, y, x).
fn zyx_to_yxz(src: &[Complex64], dst: &mut [Complex64], [mx, my, mz]: [usize; 3], par: bool) {
    for_chunks_mut(
        dst,
        my * mx,
        par,
        || (),
        |_, z, plane| {
            for x in 0..mx {
                for y in 0..my {
                    plane[y + my * x] = src[z + mz * (y + my * x)];
                }
            }
        },
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// A field with no symmetry: each point's value from its index.
    fn field(n: usize) -> Vec<Complex64> {
        (0..n)
            .map(|i| Complex64::new((i as f64 * 0.37).sin(), (i as f64 * 0.91).cos()))
            .collect()
    }

    /// The forward transform is the direct DFT, in the layout the module states (z fastest,
    /// then y, then x), and the inverse undoes it up to the number of points; the sequential
    /// passes (a small grid) and the parallel ones (the same grid with `parallel` set) agree
    /// bit for bit, and a grid of [`PARALLEL_GRID_POINTS`] takes the parallel ones.
    #[test]
    fn forward_is_the_dft_and_both_paths_agree() {
        let m = [4, 3, 5];
        let n = 60;
        let data = field(n);
        let mut fft = Fft3::new(m);
        assert!(!fft.parallel);
        let (mut grid, mut spare) = (data.clone(), vec![Complex64::default(); n]);
        fft.forward(&mut grid, &mut spare);
        for (kx, ky, kz) in [(0, 0, 0), (1, 2, 3), (3, 1, 4), (2, 0, 1)] {
            let mut direct = Complex64::default();
            for z in 0..m[2] {
                for y in 0..m[1] {
                    for x in 0..m[0] {
                        let phase = -2.0 * PI * (kx * x) as f64 / m[0] as f64
                            - 2.0 * PI * (ky * y) as f64 / m[1] as f64
                            - 2.0 * PI * (kz * z) as f64 / m[2] as f64;
                        direct +=
                            data[x + m[0] * (y + m[1] * z)] * Complex64::from_polar(1.0, phase);
                    }
                }
            }
            let got = grid[kz + m[2] * (ky + m[1] * kx)];
            // Sums of 60 terms of size ~1: round-off ~1e-14.
            assert!((got - direct).norm() < 1e-12, "{got} vs {direct}");
        }
        fft.parallel = true;
        let (mut par, mut spare2) = (data.clone(), vec![Complex64::default(); n]);
        fft.forward(&mut par, &mut spare2);
        assert_eq!(par, grid);
        fft.inverse(&mut par, &mut spare2);
        for (a, b) in par.iter().zip(&data) {
            assert!((a / n as f64 - b).norm() < 1e-14);
        }
        assert!(Fft3::new([16, 16, 16]).parallel);
        assert!(!Fft3::new([8, 16, 16]).parallel);
    }
}
