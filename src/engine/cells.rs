//! Cell lists: points binned into cubic cells of a given size, so that the points within that
//! distance of a point are found among the 27 cells around it in O(1) per point (for a bounded
//! density) instead of O(N).
//!
//! The points are also ordered cell by cell ([`CellGrid::order`]): a pass that copies its data in
//! that order reads each neighbour cell as one contiguous run, which is what makes a large scene
//! O(N) in practice and not only in counts (random reads across the whole index range would miss
//! the caches). A pass visits the pairs cell by cell in a fixed order, so its sums depend only on
//! the points, not on the thread count; they differ from an all-pairs loop in index order by the
//! rounding of the sum's order.

use std::collections::HashMap;

/// Points binned into cubic cells of side `size`, and ordered cell by cell.
#[derive(Debug, Clone, Default)]
pub struct CellGrid {
    size: f64,
    /// The point indices, cell by cell (ascending within a cell).
    pub order: Vec<u32>,
    /// Each occupied cell's run `start..end` in `order`.
    runs: HashMap<[i64; 3], (u32, u32)>,
}

impl CellGrid {
    /// Bin the points (x[i], y[i], z[i]) into cells of side `size` (m, positive and finite).
    pub fn build(x: &[f64], y: &[f64], z: &[f64], size: f64) -> Self {
        let keys: Vec<[i64; 3]> = (0..x.len())
            .map(|i| Self::key(size, x[i], y[i], z[i]))
            .collect();
        let mut order: Vec<u32> = (0..x.len() as u32).collect();
        order.sort_by_key(|&i| (keys[i as usize], i));
        let mut runs = HashMap::new();
        let mut start = 0;
        for k in 1..=order.len() {
            if k == order.len() || keys[order[k] as usize] != keys[order[start] as usize] {
                runs.insert(keys[order[start] as usize], (start as u32, k as u32));
                start = k;
            }
        }
        CellGrid { size, order, runs }
    }

    fn key(size: f64, x: f64, y: f64, z: f64) -> [i64; 3] {
        [x, y, z].map(|c| (c / size).floor() as i64)
    }

    /// Into `out` (cleared first), the runs in [`CellGrid::order`] of the 27 cells around
    /// (x, y, z), in a fixed order: they hold every point within `size` of it.
    pub fn neighbour_runs(&self, x: f64, y: f64, z: f64, out: &mut Vec<(u32, u32)>) {
        out.clear();
        let [i, j, k] = Self::key(self.size, x, y, z);
        for di in -1..=1 {
            for dj in -1..=1 {
                for dk in -1..=1 {
                    if let Some(&r) = self.runs.get(&[i + di, j + dj, k + dk]) {
                        out.push(r);
                    }
                }
            }
        }
    }
}
