//! Continuum fields and the structure factor: a lattice's S(k) vanishes below its Bragg peak and
//! equals N on it; an ideal gas has S ≈ 1; density fields integrate to the count; aligned
//! swimmers have |Π| = 1 and S = 1; a VTK image written and read back.

use nalgebra::Vector3;
use swimlab::engine::build::{random_suspension, Orientations, Phases};
use swimlab::engine::fields::{Field, FieldKind, FieldSpec, FieldStat};
use swimlab::engine::structure::structure_factor;
use swimlab::engine::{Dumbbell, Model, Scene};

/// A simple cubic lattice of n³ averaged swimmers filling a box of side `l`.
fn lattice(n: usize, l: f64) -> Scene {
    let mut s = Scene::new();
    s.set_model(Model::Averaged);
    s.set_box(Some([l; 3])).unwrap();
    let h = l / n as f64;
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let c = Vector3::new(i as f64, j as f64, k as f64).add_scalar(0.5) * h
                    - Vector3::repeat(0.5 * l);
                s.add(Dumbbell::default(), c, Vector3::x()).unwrap();
            }
        }
    }
    s
}

/// A 4×4×4 lattice (N = 64): S(k) is 0 for every wave vector below the Bragg peak at 2π·4/L and
/// N on it. The bins are narrower than the gaps between |n|² = 14, 16 and 17 (the peak's shell
/// |n| = 4 holds only the six Bragg vectors, three per half space), so the peak's bin holds the
/// peak alone. Tolerance: the phases are sums of 64 unit complex numbers, exact to ~1e-13.
#[test]
fn a_cubic_lattice_scatters_only_at_its_bragg_peak() {
    let l = 400e-6;
    let s = lattice(4, l);
    let kb = 2.0 * std::f64::consts::PI * 4.0 / l;
    let sf = structure_factor(&s, 200, Some(1.1 * kb)).unwrap();
    let mut peak = false;
    for ((k, v), c) in sf.k.iter().zip(&sf.s).zip(&sf.count) {
        if (k / kb - 1.0).abs() < 1e-9 {
            assert_eq!(*c, 3, "the Bragg shell holds three vectors per half space");
            assert!((v - 64.0).abs() < 1e-9, "S at the Bragg peak {v}");
            peak = true;
        } else if *k < kb {
            assert!(v.abs() < 1e-12, "S({k:e}) = {v:e} below the peak");
        }
    }
    assert!(peak, "no bin at the Bragg peak: {:?}", sf.k);
}

/// Swimmers placed at random (volume fraction 2e-4: nearly an ideal gas): S(k) ≈ 1. Each wave
/// vector's S is exponentially distributed with mean 1, so the mean over the ~2,000 wave vectors
/// has a standard error of ~0.02; required within 0.1. Each bin of ≥ 100 vectors within 0.4 (4
/// standard errors).
#[test]
fn an_ideal_gas_has_a_flat_structure_factor() {
    let d = Dumbbell::default();
    let l = 1.5e-3;
    let mut s = Scene::new();
    s.set_model(Model::Averaged);
    s.set_box(Some([l; 3])).unwrap();
    random_suspension(
        &mut s,
        1000,
        d,
        [l; 3],
        Orientations::Random,
        Phases::Random,
        5,
    )
    .unwrap();
    let sf = structure_factor(&s, 16, None).unwrap();
    let total: usize = sf.count.iter().sum();
    let mean =
        sf.s.iter()
            .zip(&sf.count)
            .map(|(v, c)| v * *c as f64)
            .sum::<f64>()
            / total as f64;
    assert!(total > 1000, "{total} wave vectors");
    assert!((mean - 1.0).abs() < 0.1, "mean S {mean}");
    for ((k, v), c) in sf.k.iter().zip(&sf.s).zip(&sf.count) {
        if *c >= 100 {
            assert!((v - 1.0).abs() < 0.4, "S({k:e}) = {v} over {c} vectors");
        }
    }
}

/// The density integrates to the number of swimmers (to rounding), in a box and in open space,
/// whatever the grid and width.
#[test]
fn density_fields_integrate_to_the_count() {
    let d = Dumbbell::default();
    let l = 300e-6;
    let mut boxed = Scene::new();
    boxed.set_model(Model::Averaged);
    boxed.set_box(Some([l, 1.3 * l, 0.9 * l])).unwrap();
    random_suspension(
        &mut boxed,
        150,
        d,
        [l, 1.3 * l, 0.9 * l],
        Orientations::Random,
        Phases::Random,
        3,
    )
    .unwrap();
    let mut open = Scene::new();
    random_suspension(
        &mut open,
        40,
        d,
        [l; 3],
        Orientations::Random,
        Phases::Random,
        4,
    )
    .unwrap();
    for s in [&boxed, &open] {
        for (grid, width) in [
            ([8, 8, 8], None),
            ([16, 12, 10], Some(30e-6)),
            ([5, 7, 3], Some(200e-6)),
        ] {
            let f = Field::of(s, FieldKind::Density, &FieldSpec { grid, width }).unwrap();
            let n = f.integral();
            assert!(
                (n / s.count() as f64 - 1.0).abs() < 1e-12,
                "{grid:?}, {width:?}: {n}"
            );
            assert!(f.values.iter().all(|v| *v >= 0.0));
        }
    }
}

/// Aligned swimmers: |Π| = 1 and Q's largest eigenvalue 1 wherever there are swimmers, 0 where
/// there are none; random orientations give |Π| well below 1 on a coarse grid.
#[test]
fn aligned_swimmers_are_fully_polar_and_nematic() {
    let d = Dumbbell::default();
    let l = 400e-6;
    let mut s = Scene::new();
    s.set_model(Model::Averaged);
    s.set_box(Some([l; 3])).unwrap();
    let n = Vector3::new(1.0, 2.0, -0.5).normalize();
    random_suspension(
        &mut s,
        60,
        d,
        [l; 3],
        Orientations::Aligned(n),
        Phases::Random,
        8,
    )
    .unwrap();
    let spec = FieldSpec {
        grid: [10, 10, 10],
        width: Some(25e-6),
    };
    let rho = Field::of(&s, FieldKind::Density, &spec).unwrap();
    let p = Field::of(&s, FieldKind::Polarization, &spec).unwrap();
    let q = Field::of(&s, FieldKind::Nematic, &spec).unwrap();
    let mut occupied = 0;
    for c in 0..p.cells() {
        if rho.values[c] > 0.0 {
            occupied += 1;
            assert!(
                (p.scalar(c) - 1.0).abs() < 1e-12,
                "cell {c}: |Π| = {}",
                p.scalar(c)
            );
            let pv = Vector3::new(p.values[3 * c], p.values[3 * c + 1], p.values[3 * c + 2]);
            assert!((pv - n).norm() < 1e-12);
            assert!(
                (q.scalar(c) - 1.0).abs() < 1e-12,
                "cell {c}: S = {}",
                q.scalar(c)
            );
        } else {
            assert_eq!(p.scalar(c), 0.0);
        }
    }
    assert!(occupied > 100);
    let mut r = Scene::new();
    r.set_model(Model::Averaged);
    r.set_box(Some([l; 3])).unwrap();
    random_suspension(
        &mut r,
        200,
        d,
        [l; 3],
        Orientations::Random,
        Phases::Random,
        9,
    )
    .unwrap();
    let coarse = FieldSpec {
        grid: [2, 2, 2],
        width: Some(100e-6),
    };
    let pr = Field::of(&r, FieldKind::Polarization, &coarse).unwrap();
    assert!(
        pr.stat(FieldStat::Max) < 0.3,
        "random orientations: |Π| up to {}",
        pr.stat(FieldStat::Max)
    );
}

/// A density and a polarization field written as VTK image data and read back with vtkio: a
/// grid of the cells' corners whose bounds are the box's faces (µm, f32), one value per cell as
/// cell data (f64, exactly; density in 1/µm³), under plain names.
#[test]
fn a_field_written_as_vtk_reads_back() {
    use vtkio::model::{Attribute, DataSet, Extent, Piece};
    let d = Dumbbell::default();
    let l = 300e-6;
    let mut s = Scene::new();
    s.set_model(Model::Averaged);
    s.set_box(Some([l; 3])).unwrap();
    random_suspension(
        &mut s,
        30,
        d,
        [l; 3],
        Orientations::Random,
        Phases::Random,
        2,
    )
    .unwrap();
    let dir = std::env::temp_dir().join(format!("swimlab-fields-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (kind, per) in [(FieldKind::Density, 1e18), (FieldKind::Polarization, 1.0)] {
        let f = Field::of(
            &s,
            kind,
            &FieldSpec {
                grid: [6, 5, 4],
                width: None,
            },
        )
        .unwrap();
        let path = dir.join(format!("{}.vti", kind.name()));
        std::fs::write(&path, f.to_vti().unwrap()).unwrap();
        let vtk = vtkio::Vtk::import(&path).unwrap();
        let DataSet::ImageData {
            extent,
            origin,
            spacing,
            pieces,
            ..
        } = vtk.data
        else {
            panic!("not image data");
        };
        assert_eq!(extent, Extent::Ranges([0..=6, 0..=5, 0..=4]));
        let cells = [6.0, 5.0, 4.0];
        for k in 0..3 {
            // f32 in the file: the box's faces at ±150 µm to f32's 7 digits.
            let (lo, hi) = (origin[k] as f64, (origin[k] + cells[k] * spacing[k]) as f64);
            assert!((lo + 0.5 * l * 1e6).abs() < 1e-4, "axis {k}: from {lo} µm");
            assert!((hi - 0.5 * l * 1e6).abs() < 1e-4, "axis {k}: to {hi} µm");
            assert_eq!(spacing[k], (f.spacing[k] * 1e6) as f32);
        }
        let Piece::Inline(piece) = &pieces[0] else {
            panic!("not inline");
        };
        assert!(piece.data.point.is_empty(), "values are cell data");
        let Attribute::DataArray(array) = &piece.data.cell[0] else {
            panic!("no data array");
        };
        assert_eq!(array.name, kind.name(), "a plain name");
        let got: Vec<f64> = array.data.clone().cast_into().unwrap();
        let want: Vec<f64> = f.values.iter().map(|v| v / per).collect();
        assert_eq!(got, want, "{}", kind.name());
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The structure factor needs a box, and says so.
#[test]
fn the_structure_factor_needs_a_box() {
    let mut s = Scene::new();
    s.add(Dumbbell::default(), Vector3::zeros(), Vector3::x())
        .unwrap();
    let e = structure_factor(&s, 8, None).unwrap_err().to_string();
    assert!(
        e.contains("periodic box") && e.contains("box of sides"),
        "{e}"
    );
}

/// A smoothing width the grid cannot carry is refused, never a NaN field: far below a cell the
/// kernel's weights underflow (0/0 per swimmer), far beyond the reach of positions the open-space
/// grid's cells overflow. Widths the grid resolves are taken, and their fields stay finite.
#[test]
fn widths_the_grid_cannot_carry_are_refused() {
    let boxed = lattice(2, 100e-6);
    let mut open = Scene::new();
    open.set_model(Model::Averaged);
    open.add(Dumbbell::default(), Vector3::zeros(), Vector3::x())
        .unwrap();
    open.add(
        Dumbbell::default(),
        Vector3::new(30e-6, 0.0, 0.0),
        Vector3::x(),
    )
    .unwrap();
    let spec = |width| FieldSpec {
        grid: [8, 8, 8],
        width: Some(width),
    };
    for (s, width, fragment) in [
        (&boxed, 1e-30, "below 1/32 of the grid's widest cell"),
        (&open, 1e-30, "below 1/32 of the grid's widest cell"),
        (&open, 1e300, "beyond the"),
    ] {
        let e = Field::of(s, FieldKind::Density, &spec(width)).unwrap_err();
        assert!(e.to_string().contains(fragment), "{width:e}: {e}");
    }
    for (s, width) in [(&boxed, 1e-6), (&open, 1e-6), (&open, 1e-3)] {
        let f = Field::of(s, FieldKind::Density, &spec(width)).unwrap();
        assert!(f.values.iter().all(|v| v.is_finite()), "{width:e}");
    }
}
