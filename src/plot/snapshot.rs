//! A picture of a scene: every swimmer's two spheres at their true radii and the rod between
//! them, projected on a coordinate plane, coloured by the in-plane direction of N (a colour wheel:
//! aligned swimmers share a colour, so order is visible at a glance). Nearer swimmers (larger
//! third coordinate) are drawn over farther ones.

use super::render::{self, Disc, ScenePicture};
use super::Format;
use crate::engine::Scene;
use plotters::style::{Color, HSLColor, RGBColor};
use std::path::Path;

/// The plane a snapshot projects on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Plane {
    /// x right, y up (looking down z).
    Xy,
    /// x right, z up.
    Xz,
    /// y right, z up.
    Yz,
}

impl Plane {
    /// Parse "xy", "xz" or "yz".
    pub fn parse(name: &str) -> Result<Self, String> {
        match name {
            "xy" => Ok(Plane::Xy),
            "xz" => Ok(Plane::Xz),
            "yz" => Ok(Plane::Yz),
            other => Err(format!(
                "unknown plane \"{other}\"; use \"xy\", \"xz\" or \"yz\""
            )),
        }
    }

    /// Indices of the (right, up, depth) coordinates.
    fn axes(self) -> (usize, usize, usize) {
        match self {
            Plane::Xy => (0, 1, 2),
            Plane::Xz => (0, 2, 1),
            Plane::Yz => (1, 2, 0),
        }
    }
}

/// What a snapshot shows.
#[derive(Debug, Clone, PartialEq)]
pub struct SnapshotOptions {
    /// Projection plane.
    pub plane: Plane,
    /// Caption ("" for none).
    pub title: String,
    /// Picture size in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

impl Default for SnapshotOptions {
    fn default() -> Self {
        SnapshotOptions {
            plane: Plane::Xy,
            title: String::new(),
            width: 700,
            height: 600,
        }
    }
}

/// The widest scene a snapshot draws, in radii of its largest sphere (a sphere of 1 µm in a
/// scene a kilometre across).
pub const MAX_EXTENT_IN_RADII: f64 = 1e9;

/// Draw `scene` to `path` (SVG or PNG by extension); folders are created.
pub fn snapshot(scene: &Scene, opts: &SnapshotOptions, path: &Path) -> Result<(), String> {
    let format = Format::of(path)?;
    for (w, what) in [(opts.width, "width"), (opts.height, "height")] {
        if !(100..=8000).contains(&w) {
            return Err(format!(
                "snapshot {what} must be 100 to 8000 pixels, got {w}"
            ));
        }
    }
    if scene.count() == 0 {
        return Err("the scene has no swimmers to draw; add some first".into());
    }
    let (a, b, depth) = opts.plane.axes();
    let um = 1e6;
    let mut order: Vec<usize> = (0..scene.count()).collect();
    let depth_of = |i: usize| {
        let (p, q) = scene.spheres(i);
        (p[depth] + q[depth]) / 2.0
    };
    order.sort_by(|&i, &j| depth_of(i).total_cmp(&depth_of(j)));
    let mut discs = Vec::with_capacity(2 * scene.count());
    let mut rods = Vec::with_capacity(scene.count());
    for i in order {
        let (p1, p2) = scene.spheres(i);
        let d = &scene.swimmers()[i];
        let n = scene.dir(i).map_err(|e| e.to_string())?;
        let hue = (n[b].atan2(n[a]) / (2.0 * std::f64::consts::PI)).rem_euclid(1.0);
        // Out-of-plane swimmers fade to grey.
        let sat = (n[a] * n[a] + n[b] * n[b]).sqrt().clamp(0.0, 1.0) * 0.75;
        let (r1, g1, b1) = HSLColor(hue, sat, 0.40).to_rgba().rgb();
        let (r2, g2, b2) = HSLColor(hue, sat, 0.68).to_rgba().rgb();
        let k = discs.len();
        discs.push(Disc {
            x: p1[a] * um,
            y: p1[b] * um,
            r: d.a1 * um,
            fill: RGBColor(r1, g1, b1),
        });
        discs.push(Disc {
            x: p2[a] * um,
            y: p2[b] * um,
            r: d.a2 * um,
            fill: RGBColor(r2, g2, b2),
        });
        rods.push((k, k + 1));
    }
    let (lo, hi, r_max) = discs.iter().fold(
        (f64::INFINITY, f64::NEG_INFINITY, 0.0f64),
        |(lo, hi, r), d| (lo.min(d.x.min(d.y)), hi.max(d.x.max(d.y)), r.max(d.r)),
    );
    if !((hi - lo).is_finite() && hi - lo <= MAX_EXTENT_IN_RADII * r_max) {
        return Err(format!(
            "the swimmers span {:.3e} m in this plane, over {MAX_EXTENT_IN_RADII:e} times their largest sphere: every sphere would be below a pixel; draw a scene of the region of interest (s.copy() and fewer swimmers)",
            (hi - lo) / um
        ));
    }
    let names = ["x [µm]", "y [µm]", "z [µm]"];
    crate::engine::files::ensure_parent(path).map_err(|e| e.to_string())?;
    render::scene(
        &ScenePicture {
            title: &opts.title,
            axes: (names[a], names[b]),
            size: (opts.width, opts.height),
            discs,
            rods,
        },
        path,
        format,
    )
}
