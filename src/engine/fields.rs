//! Continuum fields of a suspension on a grid: the number density ρ, the polarization Π and the
//! nematic tensor Q of the swimmers' hydrodynamic centres, smoothed by a Gaussian kernel (the
//! structure factor S(k) is [`super::structure`]'s).
//!
//! Each swimmer σ spreads its weight over the grid cells within 4 widths of R_H^σ (by minimum
//! image in a box, the kernel then periodic) as e^{−|x − R_H|²/2w²}, normalised on the grid so
//! that Σ_cells ρ ΔV counts it exactly once:
//! ρ(x) = Σ_σ K_σ(x), Π(x) = Σ_σ N^σ K_σ(x)/ρ(x), Q(x) = Σ_σ (3N^σN^σ − I)/2 K_σ(x)/ρ(x)
//! (Π and Q are the local averages of N and of the swimmers' nematic tensor: |Π| = 1 and the
//! largest eigenvalue of Q is 1 where all swimmers are aligned; both 0 where ρ = 0).

use super::choice::{self, Choice, Named};
use super::error::{invalid, Result};
use super::scene::Scene;
use nalgebra::{Matrix3, SymmetricEigen, Vector3};
use serde::{Deserialize, Serialize};

/// Which field.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FieldKind {
    /// Number density ρ of the hydrodynamic centres (1/m³).
    Density,
    /// Polarization Π: the local mean orientation (dimensionless vector).
    Polarization,
    /// Nematic tensor Q = ⟨(3NN − I)/2⟩ locally (dimensionless, symmetric, traceless).
    Nematic,
}

impl Named for FieldKind {
    const KIND: &'static str = "field";
    const CHOICES: &'static [Choice<Self>] = &[
        Choice {
            value: FieldKind::Density,
            name: "density",
            about: "number density of the centres, 1/m^3",
        },
        Choice {
            value: FieldKind::Polarization,
            name: "polarization",
            about: "local mean orientation, a vector",
        },
        Choice {
            value: FieldKind::Nematic,
            name: "nematic",
            about: "local nematic tensor (3NN - I)/2, 3x3",
        },
    ];
}

choice::inherent_names!(FieldKind);

impl FieldKind {
    /// Values per cell: 1, 3 or 9 (Q row by row).
    pub fn components(self) -> usize {
        match self {
            FieldKind::Density => 1,
            FieldKind::Polarization => 3,
            FieldKind::Nematic => 9,
        }
    }

    /// What one swimmer of orientation `n` carries into this field, w(N): 1, N, or (3NN − I)/2
    /// row by row, in the first [`FieldKind::components`] entries.
    pub fn weight(self, n: Vector3<f64>) -> [f64; 9] {
        let mut w = [0.0; 9];
        match self {
            FieldKind::Density => w[0] = 1.0,
            FieldKind::Polarization => w[..3].copy_from_slice(n.as_slice()),
            FieldKind::Nematic => {
                for a in 0..3 {
                    for c in 0..3 {
                        w[3 * a + c] = 1.5 * n[a] * n[c] - if a == c { 0.5 } else { 0.0 };
                    }
                }
            }
        }
        w
    }
}

/// The most cells a field may have (64 MB of f64 for a nematic field).
pub const MAX_CELLS: usize = 1 << 20;

/// The most swimmer-to-cell deposits one field may take (a few seconds of work).
pub const MAX_DEPOSITS: f64 = 1e9;

/// Grid and smoothing of a field.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FieldSpec {
    /// Cells per axis.
    pub grid: [usize; 3],
    /// Width w of the Gaussian kernel (m); `None`: the largest cell side.
    pub width: Option<f64>,
}

impl Default for FieldSpec {
    fn default() -> Self {
        FieldSpec {
            grid: [32, 32, 32],
            width: None,
        }
    }
}

impl FieldSpec {
    /// Check the grid and width.
    pub fn check(&self) -> Result<()> {
        let cells: usize = self.grid.iter().product();
        if self.grid.contains(&0) || cells > MAX_CELLS {
            return Err(invalid!(
                "a field grid needs 1 or more cells per axis and at most {MAX_CELLS} cells in all, got {:?}; e.g. grid: [32, 32, 32]",
                self.grid
            ));
        }
        if let Some(w) = self.width {
            if !(w.is_finite() && w > 0.0) {
                return Err(invalid!(
                    "a field's smoothing width must be a positive length in m, got {w}; e.g. width: 10e-6, or leave it out for one cell"
                ));
            }
        }
        Ok(())
    }
}

/// Refuse a smoothing width the grid cannot carry: narrower than 1/32 of the widest cell, the
/// kernel's weight at the nearest cell centre (half a cell away at most) can fall below e^-128,
/// and far narrower underflows to nothing (a swimmer would deposit 0/0); wider than the reach of
/// positions, the open-space grid's cells overflow.
fn check_width(width: f64, spacing: [f64; 3], scene: &Scene) -> Result<()> {
    let h = spacing[0].max(spacing[1]).max(spacing[2]);
    if width < h / 32.0 {
        return Err(invalid!(
            "a field's smoothing width of {width:e} m is below 1/32 of the grid's widest cell, {h:e} m: the kernel's weights at the cell centres would underflow; give a width of at least {:e} m, or a finer grid",
            h / 32.0
        ));
    }
    let reach = scene.reach();
    if !(width <= reach.limit && h.powi(3).is_finite()) {
        return Err(invalid!(
            "a field's smoothing width of {width:e} m is beyond the {:e} m that positions may reach ({}); give a width below that",
            reach.limit,
            reach.why
        ));
    }
    Ok(())
}

/// A field on a regular grid; cell (i, j, k) is centred at origin + (i, j, k)·spacing.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    /// Which field.
    pub kind: FieldKind,
    /// Cells per axis.
    pub grid: [usize; 3],
    /// Centre of cell (0, 0, 0) (m).
    pub origin: [f64; 3],
    /// Cell sides (m).
    pub spacing: [f64; 3],
    /// The kernel's width (m).
    pub width: f64,
    /// Whether the grid is a periodic box's.
    pub periodic: bool,
    /// `kind.components()` values per cell, cells x fastest, then y, then z.
    pub values: Vec<f64>,
}

impl Field {
    /// The field of `kind` of `scene`'s swimmers on the grid of `spec`: in a box the box's cells,
    /// in open space a grid over the centres' bounding box padded by 4 widths.
    pub fn of(scene: &Scene, kind: FieldKind, spec: &FieldSpec) -> Result<Field> {
        spec.check()?;
        if scene.count() == 0 {
            return Err(invalid!(
                "the scene has no swimmers, so no field; add some first"
            ));
        }
        let centres: Vec<Vector3<f64>> = (0..scene.count())
            .map(|i| scene.center(i).map(|c| scene.shown(c)))
            .collect::<Result<_>>()?;
        let dirs: Vec<Vector3<f64>> = (0..scene.count())
            .map(|i| scene.dir(i))
            .collect::<Result<_>>()?;
        let n = spec.grid;
        let (origin, spacing, width) = match scene.periodic() {
            Some(b) => {
                let l = b.sides();
                let h: [f64; 3] = std::array::from_fn(|d| l[d] / n[d] as f64);
                let w = spec.width.unwrap_or(h[0].max(h[1]).max(h[2]));
                (std::array::from_fn(|d| -0.5 * l[d] + 0.5 * h[d]), h, w)
            }
            None => {
                let lo: [f64; 3] = std::array::from_fn(|d| {
                    centres.iter().map(|c| c[d]).fold(f64::INFINITY, f64::min)
                });
                let hi: [f64; 3] = std::array::from_fn(|d| {
                    centres
                        .iter()
                        .map(|c| c[d])
                        .fold(f64::NEG_INFINITY, f64::max)
                });
                let ell = scene.swimmers()[0].ell;
                let w = spec.width.unwrap_or_else(|| {
                    let h = (0..3)
                        .map(|d| (hi[d] - lo[d]) / n[d] as f64)
                        .fold(0.0, f64::max);
                    if h > 0.0 {
                        h
                    } else {
                        ell
                    }
                });
                let h: [f64; 3] = std::array::from_fn(|d| (hi[d] - lo[d] + 8.0 * w) / n[d] as f64);
                (std::array::from_fn(|d| lo[d] - 4.0 * w + 0.5 * h[d]), h, w)
            }
        };
        check_width(width, spacing, scene)?;
        let mut f = Field {
            kind,
            grid: n,
            origin,
            spacing,
            width,
            periodic: scene.periodic().is_some(),
            values: vec![0.0; n[0] * n[1] * n[2] * kind.components()],
        };
        // Cells each swimmer touches: 8 widths across per axis, at most the grid.
        let touched: f64 = (0..3)
            .map(|d| ((8.0 * width / spacing[d]).ceil() + 1.0).min(n[d] as f64))
            .product();
        if touched * centres.len() as f64 > MAX_DEPOSITS {
            return Err(invalid!(
                "a field of {} swimmers with width {width:e} m on this grid spreads each swimmer over {touched:.0} cells, {:.1e} deposits in all (more than {MAX_DEPOSITS:e}, minutes of work); use a smaller width or a coarser grid",
                centres.len(),
                touched * centres.len() as f64
            ));
        }
        let sides = scene.periodic().map(|b| b.sides());
        f.deposit(&centres, &dirs, sides);
        Ok(f)
    }

    /// Spread every swimmer's weight and orientation terms over the cells, then divide Π and Q
    /// by ρ.
    fn deposit(
        &mut self,
        centres: &[Vector3<f64>],
        dirs: &[Vector3<f64>],
        sides: Option<[f64; 3]>,
    ) {
        let n = self.grid;
        let comps = self.kind.components();
        let dv = self.spacing[0] * self.spacing[1] * self.spacing[2];
        let axis = |c: f64, d: usize| -> Vec<(usize, f64)> {
            gaussian_axis(
                c,
                self.spacing[d],
                self.origin[d],
                self.width,
                n[d],
                sides.map(|l| l[d]),
            )
        };
        let mut rho = vec![0.0; n[0] * n[1] * n[2]];
        for (c, dir) in centres.iter().zip(dirs) {
            let (gx, gy, gz) = (axis(c.x, 0), axis(c.y, 1), axis(c.z, 2));
            let total: f64 = gx.iter().map(|g| g.1).sum::<f64>()
                * gy.iter().map(|g| g.1).sum::<f64>()
                * gz.iter().map(|g| g.1).sum::<f64>();
            let terms = self.kind.weight(*dir);
            for &(k, fz) in &gz {
                for &(j, fy) in &gy {
                    for &(i, fx) in &gx {
                        let cell = i + n[0] * (j + n[1] * k);
                        let weight = fx * fy * fz / (total * dv);
                        rho[cell] += weight;
                        if comps == 1 {
                            self.values[cell] += weight;
                        } else {
                            for (v, t) in self.values[comps * cell..comps * (cell + 1)]
                                .iter_mut()
                                .zip(&terms)
                            {
                                *v += weight * t;
                            }
                        }
                    }
                }
            }
        }
        if comps > 1 {
            for (cell, r) in rho.iter().enumerate() {
                let v = &mut self.values[comps * cell..comps * (cell + 1)];
                if *r > 0.0 {
                    v.iter_mut().for_each(|x| *x /= r);
                } else {
                    v.fill(0.0);
                }
            }
        }
    }

    /// The number of cells.
    pub fn cells(&self) -> usize {
        self.grid.iter().product()
    }

    /// The scalar each cell shows: ρ (1/m³), |Π|, or Q's largest eigenvalue S.
    pub fn scalar(&self, cell: usize) -> f64 {
        let c = self.kind.components();
        let v = &self.values[c * cell..c * (cell + 1)];
        match self.kind {
            FieldKind::Density => v[0],
            FieldKind::Polarization => (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt(),
            FieldKind::Nematic => {
                let q = Matrix3::from_row_slice(v);
                SymmetricEigen::new(q).eigenvalues.max()
            }
        }
    }

    /// Σ_cells ρ ΔV for a density field: the number of swimmers.
    pub fn integral(&self) -> f64 {
        let dv = self.spacing[0] * self.spacing[1] * self.spacing[2];
        (0..self.cells()).map(|c| self.scalar(c)).sum::<f64>() * dv
    }

    /// The cell scalars' summary `stat`.
    pub fn stat(&self, stat: FieldStat) -> f64 {
        let n = self.cells() as f64;
        let values = (0..self.cells()).map(|c| self.scalar(c));
        match stat {
            FieldStat::Mean => values.sum::<f64>() / n,
            FieldStat::Variance => {
                let all: Vec<f64> = values.collect();
                let mean = all.iter().sum::<f64>() / n;
                all.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / n
            }
            FieldStat::Max => values.fold(f64::NEG_INFINITY, f64::max),
            FieldStat::Min => values.fold(f64::INFINITY, f64::min),
        }
    }

    /// The 2D slice of cell scalars at `index` across `axis` (0, 1, 2): rows along the next axis,
    /// columns along the one after (for z: x across, y up), with their extents (m).
    pub fn slice(&self, axis: usize, index: usize) -> Result<Slice> {
        if axis > 2 || index >= self.grid[axis] {
            return Err(invalid!(
                "the slice index {index} is outside the field's {} cells along {}; use 0 to {}",
                self.grid.get(axis).copied().unwrap_or(0),
                ["x", "y", "z"].get(axis).unwrap_or(&"?"),
                self.grid.get(axis).copied().unwrap_or(1).saturating_sub(1)
            ));
        }
        let (a, b) = match axis {
            0 => (1, 2),
            1 => (0, 2),
            _ => (0, 1),
        };
        let n = self.grid;
        let mut values = vec![0.0; n[a] * n[b]];
        for j in 0..n[b] {
            for i in 0..n[a] {
                let mut idx = [0; 3];
                idx[axis] = index;
                idx[a] = i;
                idx[b] = j;
                values[i + n[a] * j] = self.scalar(idx[0] + n[0] * (idx[1] + n[1] * idx[2]));
            }
        }
        let lo = |d: usize| self.origin[d] - 0.5 * self.spacing[d];
        let hi = |d: usize| lo(d) + n[d] as f64 * self.spacing[d];
        Ok(Slice {
            axes: (a, b),
            cols: n[a],
            rows: n[b],
            values,
            x: (lo(a), hi(a)),
            y: (lo(b), hi(b)),
        })
    }

    /// The field as VTK image data (ParaView's `.vti`): lengths in µm like the trajectories, one
    /// value per cell as cell data on a grid of the cells' corners (in a box its bounds are the
    /// box's faces, so fields and trajectories overlay), named `density` (1/µm³), `polarization`
    /// (vectors) or `Q` (tensors); the units are the file's field data (`length_unit`,
    /// `density_unit`).
    pub fn to_vti(&self) -> Result<Vec<u8>> {
        use vtkio::model::{
            Attribute, Attributes, ByteOrder, DataArray, DataSet, Extent, ImageDataPiece, Piece,
            Version, Vtk,
        };
        const UM: f64 = 1e6;
        let n = self.grid;
        let (array, unit) = match self.kind {
            FieldKind::Density => (
                DataArray::scalars("density", 1).with_data(
                    self.values
                        .iter()
                        .map(|v| v / UM.powi(3))
                        .collect::<Vec<_>>(),
                ),
                ("density_unit", "1/um^3"),
            ),
            FieldKind::Polarization => (
                DataArray::vectors("polarization").with_data(self.values.clone()),
                ("polarization_unit", "1"),
            ),
            FieldKind::Nematic => (
                DataArray::tensors("Q").with_data(self.values.clone()),
                ("Q_unit", "1"),
            ),
        };
        let extent = Extent::Ranges([0..=(n[0] as i32), 0..=(n[1] as i32), 0..=(n[2] as i32)]);
        let corner = |d: usize| self.origin[d] - 0.5 * self.spacing[d];
        let vtk = Vtk {
            version: Version::new_xml(1, 0),
            byte_order: ByteOrder::LittleEndian,
            title: String::new(),
            file_path: None,
            data: DataSet::ImageData {
                extent: extent.clone(),
                origin: [0, 1, 2].map(|d| (corner(d) * UM) as f32),
                spacing: self.spacing.map(|h| (h * UM) as f32),
                meta: None,
                pieces: vec![Piece::Inline(Box::new(ImageDataPiece {
                    extent,
                    data: Attributes {
                        point: Vec::new(),
                        cell: vec![Attribute::DataArray(array)],
                    },
                }))],
            },
        };
        super::vtk::xml_with_units(vtk, &[("length_unit", "um"), unit], "the VTK image")
    }
}

/// One axis of the separable Gaussian kernel of width `w` about coordinate `c`: the cells within
/// 4 widths (cell i centred at `origin` + i·`h`, `n` cells) and their factors e^{−dx²/2w²}, by
/// minimum image when the axis is periodic with side `side` (each cell once even where 4 widths
/// exceed half the side).
pub(crate) fn gaussian_axis(
    c: f64,
    h: f64,
    o: f64,
    w: f64,
    n: usize,
    side: Option<f64>,
) -> Vec<(usize, f64)> {
    let reach = (4.0 * w / h).ceil() as i64;
    let centre = ((c - o) / h).round() as i64;
    let (lo, hi) = match side {
        Some(_) => {
            let half = (n as i64 - 1) / 2;
            let m = reach.min(half);
            (
                centre - m,
                centre
                    + m
                    + if n.is_multiple_of(2) && reach > half {
                        1
                    } else {
                        0
                    },
            )
        }
        None => ((centre - reach).max(0), (centre + reach).min(n as i64 - 1)),
    };
    (lo..=hi)
        .map(|i| {
            let x = o + i as f64 * h;
            let dx = match side {
                Some(l) => {
                    let r = x - c;
                    r - l * (r / l).round()
                }
                None => x - c,
            };
            (
                i.rem_euclid(n as i64) as usize,
                (-dx * dx / (2.0 * w * w)).exp(),
            )
        })
        .collect()
}

/// A 2D slice of a field's cell scalars for a heat map.
#[derive(Debug, Clone, PartialEq)]
pub struct Slice {
    /// The field axes across (columns) and up (rows).
    pub axes: (usize, usize),
    /// Columns and rows.
    pub cols: usize,
    /// Rows.
    pub rows: usize,
    /// Row by row from the bottom, `cols` each.
    pub values: Vec<f64>,
    /// Extent across (m).
    pub x: (f64, f64),
    /// Extent up (m).
    pub y: (f64, f64),
}

/// A scalar summary of a field's cells (of ρ, |Π| or Q's largest eigenvalue).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FieldStat {
    /// The mean over the cells.
    Mean,
    /// The variance over the cells.
    Variance,
    /// The largest cell value.
    Max,
    /// The smallest cell value.
    Min,
}

impl Named for FieldStat {
    const KIND: &'static str = "field summary";
    const CHOICES: &'static [Choice<Self>] = &[
        Choice {
            value: FieldStat::Mean,
            name: "mean",
            about: "mean over the cells",
        },
        Choice {
            value: FieldStat::Variance,
            name: "variance",
            about: "variance over the cells",
        },
        Choice {
            value: FieldStat::Max,
            name: "max",
            about: "largest cell value",
        },
        Choice {
            value: FieldStat::Min,
            name: "min",
            about: "smallest cell value",
        },
    ];
}

choice::inherent_names!(FieldStat);
