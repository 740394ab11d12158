//! A picture of a scene: every swimmer's two spheres at their true radii and the rod between
//! them, projected on a coordinate plane, coloured by the in-plane direction of N (a colour wheel:
//! aligned swimmers share a colour, so order is visible at a glance). Nearer swimmers (larger
//! third coordinate) are drawn over farther ones.

use super::image::{Format, Image};
use super::render::{self, Disc, ScenePicture};
use crate::engine::boundary::MAX_EXTENT_IN_RADII;
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
/// scene a kilometre across): ten times the reach that the engine holds positions to
/// ([`MAX_EXTENT_IN_RADII`], in radii of the smallest sphere), so every scene whose centres the
/// engine holds is drawn, and only swimmers far longer than that (ℓ is unbounded) are refused.
pub const WIDEST_IN_RADII: f64 = 10.0 * MAX_EXTENT_IN_RADII;

/// Draw `scene` to `path` (SVG or PNG by extension); folders are created.
pub fn snapshot(scene: &Scene, opts: &SnapshotOptions, path: &Path) -> Result<(), String> {
    let format = Format::of(path)?;
    let picture = picture(scene, opts)?;
    crate::engine::files::ensure_parent(path).map_err(|e| e.to_string())?;
    render::scene(&picture, path, format)
}

/// A picture of `scene` drawn in memory (PNG and SVG), as [`snapshot`] draws it to a file.
pub fn scene_image(scene: &Scene, opts: &SnapshotOptions) -> Result<Image, String> {
    let picture = picture(scene, opts)?;
    render::in_memory(picture.size, &picture)
}

/// An animated GIF of a scene as it runs: a frame per [`SceneFilm::frame`], every frame showing
/// the region of the first (so the picture holds still while the swimmers move).
pub struct SceneFilm {
    film: render::Film,
    opts: SnapshotOptions,
    view: Option<(f64, f64, f64, f64)>,
    frames: usize,
}

impl SceneFilm {
    /// A GIF at `path` (it must end in .gif; folders are created), `fps` frames a second.
    pub fn create(path: &Path, opts: &SnapshotOptions, fps: f64) -> Result<Self, String> {
        if path.extension().and_then(|e| e.to_str()) != Some("gif") {
            return Err(format!(
                "{}: an animation is written as GIF: give a path ending in .gif",
                path.display()
            ));
        }
        if !(fps.is_finite() && (0.5..=100.0).contains(&fps)) {
            return Err(format!("fps must be 0.5 to 100 frames a second, got {fps}"));
        }
        check_size(opts)?;
        crate::engine::files::ensure_parent(path).map_err(|e| e.to_string())?;
        Ok(SceneFilm {
            film: render::Film::create(path, (opts.width, opts.height), (1000.0 / fps) as u32)?,
            opts: opts.clone(),
            view: None,
            frames: 0,
        })
    }

    /// Draw the scene now as the next frame (written to the file at once).
    pub fn frame(&mut self, scene: &Scene) -> Result<(), String> {
        let mut p = picture(scene, &self.opts)?;
        if let Some(v) = self.view {
            p.view = Some(v);
        } else {
            // Hold the first frame's region, widened by a fifth for the motion to come.
            let (x0, x1, y0, y1) = render::scene_view(&p);
            let (dx, dy) = (0.1 * (x1 - x0), 0.1 * (y1 - y0));
            p.view = Some((x0 - dx, x1 + dx, y0 - dy, y1 + dy));
        }
        self.view = Some(self.film.frame(&p)?);
        self.frames += 1;
        Ok(())
    }

    /// Frames written.
    pub fn frames(&self) -> usize {
        self.frames
    }
}

fn check_size(opts: &SnapshotOptions) -> Result<(), String> {
    for (w, what) in [(opts.width, "width"), (opts.height, "height")] {
        if !(100..=8000).contains(&w) {
            return Err(format!(
                "snapshot {what} must be 100 to 8000 pixels, got {w}"
            ));
        }
    }
    Ok(())
}

/// The picture of `scene`: discs and rods in µm, nearer swimmers last.
fn picture<'a>(scene: &Scene, opts: &'a SnapshotOptions) -> Result<ScenePicture<'a>, String> {
    check_size(opts)?;
    if scene.count() == 0 {
        return Err("the scene has no swimmers to draw; add some first".into());
    }
    let (a, b, depth) = opts.plane.axes();
    let um = 1e6;
    let mut order: Vec<usize> = (0..scene.count()).collect();
    let depth_of = |i: usize| {
        let (p, q) = scene.shown_spheres(i);
        (p[depth] + q[depth]) / 2.0
    };
    order.sort_by(|&i, &j| depth_of(i).total_cmp(&depth_of(j)));
    let mut discs = Vec::with_capacity(scene.sphere_count());
    let mut rods = Vec::with_capacity(scene.count());
    for i in order {
        let (p1, p2) = scene.shown_spheres(i);
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
    if !((hi - lo).is_finite() && hi - lo <= WIDEST_IN_RADII * r_max) {
        return Err(format!(
            "the swimmers span {:.3e} m in this plane, over {WIDEST_IN_RADII:e} times their largest sphere: every sphere would be below a pixel; draw a scene of the region of interest (s.copy() and fewer swimmers)",
            (hi - lo) / um
        ));
    }
    const NAMES: [&str; 3] = ["x [µm]", "y [µm]", "z [µm]"];
    Ok(ScenePicture {
        title: &opts.title,
        axes: (NAMES[a], NAMES[b]),
        size: (opts.width, opts.height),
        discs,
        rods,
        view: None,
    })
}
