//! The vectorised, parallel pair kernels (by rows, and each pair once in tiles) against the
//! reference half-loop, and their independence of the thread count.

use nalgebra::Vector3;
use swimlab::bench::pairs::lattice;
use swimlab::engine::gaps::min_gap;
use swimlab::engine::pairs::{
    interaction_velocities, row_velocities, symmetric_velocities, tile_rounds, SoaSpheres,
    SYMMETRIC_SPHERES,
};
use swimlab::engine::Mobility;

fn reference(m: Mobility, s: &swimlab::engine::pairs::SoaSpheres) -> Vec<Vector3<f64>> {
    let n = s.len();
    let pos: Vec<_> = (0..n)
        .map(|i| Vector3::new(s.x[i], s.y[i], s.z[i]))
        .collect();
    let radii = s.a.clone();
    let f: Vec<_> = (0..n)
        .map(|i| Vector3::new(s.fx[i], s.fy[i], s.fz[i]))
        .collect();
    let mut u = vec![Vector3::zeros(); n];
    m.interaction_velocities(1e-3, &pos, &radii, &f, &mut u);
    u
}

/// The kernels by name.
type Kernel = fn(Mobility, f64, &SoaSpheres, &mut [[f64; 3]], bool);
const KERNELS: [(&str, Kernel); 3] = [
    ("by rows", row_velocities),
    ("each pair once", symmetric_velocities),
    ("chosen by size", interaction_velocities),
];

/// The largest component difference from the reference, and the largest reference component.
fn error_against(r: &[Vector3<f64>], u: &[[f64; 3]]) -> (f64, f64) {
    let scale = r.iter().map(|v| v.amax()).fold(0.0, f64::max);
    let err = (0..r.len())
        .flat_map(|i| (0..3).map(move |k| (i, k)))
        .map(|(i, k)| (u[i][k] - r[i][k]).abs())
        .fold(0.0, f64::max);
    (err, scale)
}

// The kernels sum the same ~N terms in different orders and group the RPY coefficients
// differently (and the tiled one fuses multiply-adds): each u differs by a few ulps of the largest
// term, far below 1e-12 of |u|max. The sizes take partial lane blocks, one tile, several tiles
// with a short last one, and both sides of SYMMETRIC_SPHERES.
#[test]
fn fast_kernels_match_the_reference_to_round_off() {
    const { assert!(300 < SYMMETRIC_SPHERES && SYMMETRIC_SPHERES < 1100) };
    for m in [Mobility::Rpy, Mobility::Oseen] {
        for n in [5usize, 67, 300, 1100] {
            let s = lattice(n);
            let r = reference(m, &s);
            for (name, kernel) in KERNELS {
                for parallel in [false, true] {
                    let mut u = vec![[0.0; 3]; n];
                    kernel(m, 1e-3, &s, &mut u, parallel);
                    let (err, scale) = error_against(&r, &u);
                    assert!(
                        err <= 1e-12 * scale,
                        "{name}, {m:?} n = {n}: {err:e} of {scale:e}"
                    );
                }
            }
        }
    }
}

// Every sphere's terms add up in a fixed order whatever runs them: serial, 1, 2 or 3 threads
// give the same bits, by rows and by tiles (33 tiles at n = 4,200: rounds of 16 tile pairs).
#[test]
fn results_do_not_depend_on_the_thread_count() {
    for n in [1000, 4200] {
        let s = lattice(n);
        for (name, kernel) in KERNELS {
            let mut serial = vec![[0.0; 3]; n];
            kernel(Mobility::Rpy, 1e-3, &s, &mut serial, false);
            for threads in [1, 2, 3] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                let mut u = vec![[0.0; 3]; n];
                pool.install(|| kernel(Mobility::Rpy, 1e-3, &s, &mut u, true));
                assert_eq!(u, serial, "{name}, n = {n}, {threads} threads");
            }
        }
    }
}

// The rounds pair every two tiles exactly once, and no tile twice in a round (so a round's tile
// pairs write disjoint accumulators).
#[test]
fn tile_rounds_meet_every_pair_once() {
    for t in 0..=13 {
        let mut met = vec![vec![0; t]; t];
        for round in tile_rounds(t) {
            let mut busy = vec![false; t];
            for (a, b) in round {
                assert!(a < b && b < t, "t = {t}: ({a}, {b})");
                assert!(!busy[a] && !busy[b], "t = {t}: a tile twice in a round");
                busy[a] = true;
                busy[b] = true;
                met[a][b] += 1;
            }
        }
        for (a, row) in met.iter().enumerate() {
            for (b, &count) in row.iter().enumerate().skip(a + 1) {
                assert_eq!(count, 1, "t = {t}: tiles {a} and {b}");
            }
        }
    }
}

#[test]
fn min_gap_finds_the_closest_pair() {
    let mut s = lattice(200);
    s.x[150] = s.x[17] + 1.1e-6;
    s.y[150] = s.y[17];
    s.z[150] = s.z[17];
    let radii = s.a.clone();
    let brute = (0..200)
        .flat_map(|i| (i + 1..200).map(move |j| (i, j)))
        .map(|(i, j)| {
            let d =
                ((s.x[i] - s.x[j]).powi(2) + (s.y[i] - s.y[j]).powi(2) + (s.z[i] - s.z[j]).powi(2))
                    .sqrt();
            d - radii[i] - radii[j]
        })
        .fold(f64::INFINITY, f64::min);
    for parallel in [false, true] {
        let (gap, i, j) = min_gap(&s, &radii, parallel).unwrap();
        assert_eq!(gap, brute);
        assert_eq!((i, j), (17, 150));
    }
}

// Overlapping pairs leave the vector loop and take the scalar overlapping-sphere (Zuk et al.)
// form; the result must still be the reference's to round-off, in every kernel, on 1 or 2
// threads alike. At n = 1,100 the pairs lie within a tile (17, 40-41, 90-91) and across tiles
// (150 with 17, 1050 with 3).
#[test]
fn overlapping_spheres_take_the_overlap_form_in_the_fast_kernels() {
    for n in [300, 1100] {
        let mut s = lattice(n);
        // 17 and 150 overlap partly; 40 sits inside 41 (|r| < |a40 − a41|); 90 and 91 at one point;
        // 201 (radius 0.5 µm) is 0.1 µm clear of 200 (1 µm): within the reach the tiled kernel
        // scans for overlaps, not overlapping.
        let mut moves = vec![
            (150, 17, 0.6e-6),
            (40, 41, 0.05e-6),
            (90, 91, 0.0),
            (201, 200, 1.6e-6),
        ];
        if n > 1050 {
            moves.push((1050, 3, 0.3e-6));
        }
        for (j, i, dx) in moves {
            s.x[j] = s.x[i] + dx;
            s.y[j] = s.y[i];
            s.z[j] = s.z[i];
        }
        s.set_radius(41, 1.0e-6);
        s.set_radius(40, 0.5e-6);
        s.set_radius(200, 1.0e-6);
        s.set_radius(201, 0.5e-6);
        let r = reference(Mobility::Rpy, &s);
        for (name, kernel) in KERNELS {
            for parallel in [false, true] {
                let mut u = vec![[0.0; 3]; n];
                kernel(Mobility::Rpy, 1e-3, &s, &mut u, parallel);
                let (err, scale) = error_against(&r, &u);
                assert!(
                    err <= 1e-12 * scale,
                    "{name}, n = {n}: {err:e} of {scale:e}"
                );
            }
        }
    }
}

// The overlap guard through cell lists names the pair min_gap names whenever that pair overlaps,
// and nothing otherwise: 3,000 spheres (above the cell-list threshold) with several overlaps,
// ties included, and with none.
#[test]
fn closest_overlap_through_cell_lists_is_min_gaps_answer() {
    use swimlab::engine::gaps::{closest_overlap, CELL_LIST_SPHERES};
    let n = 3000;
    assert!(n >= CELL_LIST_SPHERES);
    let clear = lattice(n);
    let radii = clear.a.clone();
    let mut s = clear.clone();
    for (j, i, dx) in [
        (2500, 17, 0.6e-6),
        (40, 41, 0.05e-6),
        (1999, 1000, 0.6e-6),
        (7, 8, 0.0),
    ] {
        s.x[j] = s.x[i] + dx;
        s.y[j] = s.y[i];
        s.z[j] = s.z[i];
    }
    for parallel in [false, true] {
        let expected = min_gap(&s, &radii, parallel).filter(|g| g.0 <= 0.0);
        assert!(expected.is_some());
        assert_eq!(closest_overlap(&s, &radii, parallel), expected);
        let none = min_gap(&clear, &radii, parallel).filter(|g| g.0 <= 0.0);
        assert_eq!(none, None);
        assert_eq!(closest_overlap(&clear, &radii, parallel), None);
    }
}

// min_gap through cell lists (3,000 spheres, above the threshold) is the all-pairs answer: the
// same gap bits and the same pair, clear of overlaps and with them, and on a line of spheres
// (a flat bounding box).
#[test]
fn min_gap_through_cell_lists_is_the_all_pairs_answer() {
    let n = 3000;
    let s = lattice(n);
    let radii = s.a.clone();
    let brute = |s: &swimlab::engine::pairs::SoaSpheres| {
        let mut best = (f64::INFINITY, 0, 0);
        for i in 0..n {
            for j in i + 1..n {
                let (rx, ry, rz) = (s.x[i] - s.x[j], s.y[i] - s.y[j], s.z[i] - s.z[j]);
                let gap = (rx * rx + ry * ry + rz * rz).sqrt() - radii[i] - radii[j];
                if gap < best.0 {
                    best = (gap, i, j);
                }
            }
        }
        best
    };
    let mut moved = s.clone();
    moved.x[2500] = moved.x[17] + 2.9e-6;
    moved.y[2500] = moved.y[17];
    moved.z[2500] = moved.z[17];
    let mut line = s.clone();
    for i in 0..n {
        (line.x[i], line.y[i], line.z[i]) = (i as f64 * 3e-6 + (i % 7) as f64 * 1e-8, 0.0, 0.0);
    }
    for case in [&s, &moved, &line] {
        let expected = brute(case);
        for parallel in [false, true] {
            assert_eq!(min_gap(case, &radii, parallel), Some(expected));
        }
    }
}
