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

use super::periodic::PeriodicBox;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// A fast hash of cell keys (a multiply and a rotation per word, as rustc's own `FxHasher`): the
/// keys are small integers the program makes itself, so the default hasher's resistance to
/// chosen collisions buys nothing, and a search hashes up to 27 keys a point.
#[derive(Debug, Clone, Copy, Default)]
struct CellHasher(u64);

impl Hasher for CellHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        // A key's integers come as their bytes, one word at a time.
        let mut words = bytes.chunks_exact(8);
        for w in &mut words {
            self.write_u64(u64::from_le_bytes(w.try_into().unwrap_or_default()));
        }
        for b in words.remainder() {
            self.write_u64(u64::from(*b));
        }
    }

    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }

    fn write_i64(&mut self, x: i64) {
        self.write_u64(x as u64);
    }

    fn write_usize(&mut self, x: usize) {
        self.write_u64(x as u64);
    }
}

/// Maps keyed by cell.
type CellTable<V> = HashMap<[i64; 3], V, BuildHasherDefault<CellHasher>>;

/// How points are binned: cubic cells of side `size`, or in a periodic box its tiling by
/// n_d = ⌊L_d/size⌋ cells of side L_d/n_d ≥ size per axis.
#[derive(Debug, Clone, Copy, Default)]
struct Binning {
    size: f64,
    /// In a box: its sides and the cells per axis.
    periodic: Option<([f64; 3], [i64; 3])>,
}

impl Binning {
    fn new(size: f64, periodic: Option<&PeriodicBox>) -> Self {
        let periodic = periodic.map(|b| {
            let l = b.sides();
            (l, l.map(|side| ((side / size).floor() as i64).max(1)))
        });
        Binning { size, periodic }
    }

    fn key(&self, x: f64, y: f64, z: f64) -> [i64; 3] {
        match self.periodic {
            None => [x, y, z].map(|c| (c / self.size).floor() as i64),
            Some((l, n)) => {
                let c = [x, y, z];
                std::array::from_fn(|d| {
                    let f = (c[d] / l[d] + 0.5).rem_euclid(1.0);
                    ((f * n[d] as f64).floor() as i64).clamp(0, n[d] - 1)
                })
            }
        }
    }

    /// The 27 cells around the cell `key` (wrapped in a box, each once), in a fixed order, until
    /// `visit` returns false.
    fn around(&self, key: [i64; 3], mut visit: impl FnMut([i64; 3]) -> bool) {
        let [i, j, k] = key;
        // Fewer than 3 cells along an axis: the wrapped neighbours repeat.
        let repeats = self.periodic.is_some_and(|(_, n)| n.iter().any(|&n| n < 3));
        let mut seen: Vec<[i64; 3]> = Vec::new();
        for di in -1..=1 {
            for dj in -1..=1 {
                for dk in -1..=1 {
                    let mut cell = [i + di, j + dj, k + dk];
                    if let Some((_, n)) = self.periodic {
                        // A key lies in 0..n, so its neighbours are at most one period out.
                        for (c, n) in cell.iter_mut().zip(n) {
                            if *c < 0 {
                                *c += n;
                            } else if *c >= n {
                                *c -= n;
                            }
                        }
                        if repeats {
                            if seen.contains(&cell) {
                                continue;
                            }
                            seen.push(cell);
                        }
                    }
                    if !visit(cell) {
                        return;
                    }
                }
            }
        }
    }
}

/// Points binned into cubic cells of side `size`, and ordered cell by cell.
///
/// In a periodic box the cells tile the box (n_d = ⌊L_d/size⌋ of side L_d/n_d ≥ size per axis) and
/// the neighbours wrap around its faces; a pass measures its pairs by their minimum image. Every
/// point within `size` ≤ L/2 of another is then among the 27 cells around it.
#[derive(Debug, Clone, Default)]
pub struct CellGrid {
    binning: Binning,
    /// The point indices, cell by cell (ascending within a cell).
    pub order: Vec<u32>,
    /// Each occupied cell's run `start..end` in `order`.
    runs: CellTable<(u32, u32)>,
}

impl CellGrid {
    /// [`CellGrid::build`] in periodic box `periodic`, if any.
    pub fn build_in(
        x: &[f64],
        y: &[f64],
        z: &[f64],
        size: f64,
        periodic: Option<&PeriodicBox>,
    ) -> Self {
        let mut grid = CellGrid {
            binning: Binning::new(size, periodic),
            order: (0..x.len() as u32).collect(),
            runs: CellTable::default(),
        };
        let keys: Vec<[i64; 3]> = (0..x.len())
            .map(|i| grid.binning.key(x[i], y[i], z[i]))
            .collect();
        grid.order.sort_by_key(|&i| (keys[i as usize], i));
        let order = &grid.order;
        let mut start = 0;
        for k in 1..=order.len() {
            if k == order.len() || keys[order[k] as usize] != keys[order[start] as usize] {
                grid.runs
                    .insert(keys[order[start] as usize], (start as u32, k as u32));
                start = k;
            }
        }
        grid
    }

    /// Into `out` (cleared first), the runs in [`CellGrid::order`] of the 27 cells around
    /// (x, y, z), in a fixed order: they hold every point within `size` of it.
    pub fn neighbour_runs(&self, x: f64, y: f64, z: f64, out: &mut Vec<(u32, u32)>) {
        out.clear();
        self.binning.around(self.binning.key(x, y, z), |cell| {
            if let Some(&r) = self.runs.get(&cell) {
                out.push(r);
            }
            true
        });
    }
}

/// Points binned into cells as they come, for a set that grows while it is searched (random
/// placement, relisting): the points within `size` of a point are among those [`CellMap::near`]
/// visits. Each cell keeps its points' positions beside their ids, so a search reads each cell
/// as one contiguous run (the points' own arrays, read by id, would miss the caches in a large
/// scene).
#[derive(Debug, Clone, Default)]
pub struct CellMap {
    binning: Binning,
    cells: Cells,
}

/// A cell's points: ids and positions.
type Points = Vec<(u32, [f64; 3])>;

/// The cells of a [`CellMap`]: an array of a box's cells ([`CellMap::for_points`]), or the occupied
/// ones by key.
#[derive(Debug, Clone)]
enum Cells {
    Dense(Vec<Points>),
    Sparse(CellTable<Points>),
}

impl Default for Cells {
    fn default() -> Self {
        Cells::Sparse(CellTable::default())
    }
}

/// Most cells a box's [`CellMap`] holds as an array (24 MB of empty cells).
const MAX_DENSE_CELLS: i64 = 1 << 20;

impl CellMap {
    /// An empty map of cells of side `size` (m, positive and finite), in `periodic` if any.
    pub fn new(size: f64, periodic: Option<&PeriodicBox>) -> Self {
        CellMap {
            binning: Binning::new(size, periodic),
            cells: Cells::default(),
        }
    }

    /// [`CellMap::new`] for about `points` points: in a box of not many more cells than that
    /// (at most [`MAX_DENSE_CELLS`]), an array of all its cells, which a search reads by index
    /// instead of by key.
    pub fn for_points(size: f64, periodic: Option<&PeriodicBox>, points: usize) -> Self {
        let mut map = Self::new(size, periodic);
        let limit = (8 * points as i64)
            .saturating_add(4096)
            .min(MAX_DENSE_CELLS);
        if let Some((_, n)) = map.binning.periodic {
            let cells = n.iter().try_fold(1i64, |a, &k| a.checked_mul(k));
            if let Some(c) = cells.filter(|&c| c <= limit) {
                map.cells = Cells::Dense(vec![Vec::new(); c as usize]);
            }
        }
        map
    }

    /// The index of cell `key` in a dense map (keys in a box lie in 0..n per axis).
    fn index(&self, key: [i64; 3]) -> usize {
        let n = self.binning.periodic.map_or([0; 3], |(_, n)| n);
        (key[0] + n[0] * (key[1] + n[1] * key[2])) as usize
    }

    fn cell(&self, key: [i64; 3]) -> Option<&Points> {
        match &self.cells {
            Cells::Dense(all) => all.get(self.index(key)),
            Cells::Sparse(map) => map.get(&key),
        }
    }

    fn cell_mut(&mut self, key: [i64; 3]) -> &mut Points {
        let at = self.index(key);
        match &mut self.cells {
            Cells::Dense(all) => &mut all[at],
            Cells::Sparse(map) => map.entry(key).or_default(),
        }
    }

    /// Add point `id` at (x, y, z).
    pub fn insert(&mut self, x: f64, y: f64, z: f64, id: u32) {
        let key = self.binning.key(x, y, z);
        self.cell_mut(key).push((id, [x, y, z]));
    }

    /// Take point `id` at (x, y, z) out (where it was inserted).
    pub fn remove(&mut self, x: f64, y: f64, z: f64, id: u32) {
        let key = self.binning.key(x, y, z);
        let at = self.index(key);
        let ids = match &mut self.cells {
            Cells::Dense(all) => all.get_mut(at),
            Cells::Sparse(map) => map.get_mut(&key),
        };
        if let Some(ids) = ids {
            ids.retain(|p| p.0 != id);
        }
    }

    /// Call `visit` with every point (its id and where it was inserted) in the 27 cells around
    /// (x, y, z), each once, until it returns false; returns whether it never did.
    pub fn near(
        &self,
        x: f64,
        y: f64,
        z: f64,
        mut visit: impl FnMut(u32, [f64; 3]) -> bool,
    ) -> bool {
        let mut go_on = true;
        self.binning.around(self.binning.key(x, y, z), |cell| {
            if let Some(ids) = self.cell(cell) {
                go_on = ids.iter().all(|&(id, p)| visit(id, p));
            }
            go_on
        });
        go_on
    }
}
