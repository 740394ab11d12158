//! Trajectories for particle viewers: the spheres of a scene written frame by frame as a run goes,
//! one particle per sphere, on a recorder's trigger.
//!
//! - Extended XYZ (`.xyz`; ASE, OVITO): one frame after another in one file. Positions and radii
//!   in µm (the comment line says so: `length_unit=um`), with the species `a1` or `a2` (the
//!   sphere's kind), the swimmer index, the sphere (1: the a1 sphere, 2: the a2 sphere), the
//!   orientation N as `dipoles` and `Z` = 0 per particle, and the time in s.
//!   Each frame is appended with one write the moment it is due, so a kill or Ctrl-C loses no
//!   frame already written and never leaves half of one.
//! - A ParaView series (`.pvd`): one VTK PolyData file (`.vtp`, written by the vtkio crate) per
//!   frame in the folder `<name>_frames/` beside it, with the same data as point arrays (radius
//!   and N, the active vectors, for glyphs) and the length unit as field data, and the `.pvd`
//!   collection listing every frame with its time. Each frame costs the same however many came
//!   before: the `.vtp` is written under a temporary name in the frames folder and renamed when
//!   whole (a frame's name only ever holds a whole frame),
//!   then its entry and the collection's closing lines are written with one write over the old
//!   closing lines. A kill leaves a `.pvd` that lists every whole frame and ends in its closing
//!   lines, and at most the temporary file of the frame being written, inside the frames
//!   folder, which the next trajectory of that name clears.
//!
//! A trajectory claims its file while it lives ([`super::files::Claim`]): a second one on the
//! same path in this process is refused instead of mixing its frames into the first's.

use super::error::{invalid, Result};
use super::files::{ensure_parent, Claim, LineStream};
use super::scene::Scene;
use std::fmt::Write as _;
use std::io::{Seek, SeekFrom, Write as _};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// Metres to the files' µm.
const UM: f64 = 1e6;

/// The file formats, by the path's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Extended XYZ.
    Xyz,
    /// A ParaView `.pvd` collection of `.vtp` frames.
    Pvd,
}

/// What holds a trajectory's file, for a second writer's error.
const HOLDER: &str = "a trajectory";

/// The `.pvd` collection's first lines.
const PVD_HEAD: &str = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n";

/// The `.pvd` collection's closing lines.
const PVD_TAIL: &str = "  </Collection>\n</VTKFile>\n";

/// A `.pvd` collection kept open, appended in place.
#[derive(Debug)]
struct Collection {
    file: std::fs::File,
    /// Where its closing lines start (bytes).
    tail_at: u64,
    claim: Claim,
}

/// A trajectory being written.
#[derive(Debug)]
pub struct Trajectory {
    format: Format,
    path: PathBuf,
    /// The XYZ stream.
    stream: Option<LineStream>,
    /// The `.pvd` collection.
    collection: Option<Collection>,
    /// Frames written.
    frames: usize,
}

impl Trajectory {
    /// Start a trajectory at `path` (created or truncated): `.xyz` or `.pvd`; `retiring` is its
    /// owner's flag ([`Claim::take`]).
    pub fn create(path: &Path, retiring: Option<Arc<AtomicBool>>) -> Result<Self> {
        let format = match path.extension().and_then(|e| e.to_str()) {
            Some("xyz") => Format::Xyz,
            Some("pvd") => Format::Pvd,
            _ => {
                return Err(invalid!(
                    "trajectory {}: the file name must end in .xyz (extended XYZ, for ASE and OVITO) or .pvd (a ParaView series of .vtp frames)",
                    path.display()
                ))
            }
        };
        let mut t = Trajectory {
            format,
            path: path.to_path_buf(),
            stream: None,
            collection: None,
            frames: 0,
        };
        match format {
            Format::Xyz => t.stream = Some(LineStream::create(path, &[], HOLDER, retiring)?),
            Format::Pvd => {
                ensure_parent(path)?;
                // Claimed before anything is cleared: a second trajectory on this path must not
                // remove the first one's frames.
                let claim = Claim::take(path, HOLDER, retiring)?;
                let dir = t.frame_dir();
                if dir.exists() {
                    // Frames of an earlier trajectory of this name would mix with the new ones.
                    std::fs::remove_dir_all(&dir).map_err(|e| {
                        invalid!("cannot clear the old frames in {}: {e}", dir.display())
                    })?;
                }
                let mut file = std::fs::File::create(path).map_err(|e| write_error(path, e))?;
                file.write_all(format!("{PVD_HEAD}{PVD_TAIL}").as_bytes())
                    .map_err(|e| write_error(path, e))?;
                t.collection = Some(Collection {
                    file,
                    tail_at: PVD_HEAD.len() as u64,
                    claim,
                });
            }
        }
        Ok(t)
    }

    /// The trajectory's file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Where the `.vtp` frames of a `.pvd` go: `<name>_frames/` beside it.
    fn frame_dir(&self) -> PathBuf {
        let stem = self
            .path
            .file_stem()
            .map_or("trajectory".into(), |s| s.to_string_lossy().into_owned());
        self.path.with_file_name(format!("{stem}_frames"))
    }

    /// Write the scene's spheres now as the next frame (nothing, once another writer took the
    /// file over).
    pub fn write_frame(&mut self, scene: &Scene) -> Result<()> {
        if self.collection.as_ref().is_some_and(|c| c.claim.lost()) {
            return Ok(());
        }
        let spheres = Spheres::of(scene);
        match self.format {
            Format::Xyz => {
                let text = spheres.xyz(scene.time());
                if let Some(s) = &mut self.stream {
                    s.append(text.trim_end_matches('\n'))?;
                }
            }
            Format::Pvd => {
                let dir = self.frame_dir();
                let file_name = format!("frame_{:06}.vtp", self.frames);
                let name = format!(
                    "{}/{file_name}",
                    dir.file_name().map_or("".into(), |d| d.to_string_lossy())
                );
                let file = dir.join(&file_name);
                ensure_parent(&file)?;
                let bytes = spheres.vtp()?;
                // Whole under its own name, or not there: the temporary name is hidden and
                // fixed, so a kill leaves at most this one.
                let tmp = dir.join(format!(".{file_name}.tmp"));
                std::fs::write(&tmp, &bytes)
                    .and_then(|()| std::fs::rename(&tmp, &file))
                    .map_err(|e| {
                        let _ = std::fs::remove_file(&tmp);
                        write_error(&file, e)
                    })?;
                self.append_entry(scene.time(), &name)?;
            }
        }
        self.frames += 1;
        Ok(())
    }

    /// List a frame in the `.pvd`: its entry and the closing lines in one write over the old
    /// closing lines, so the file always ends in them.
    fn append_entry(&mut self, time: f64, name: &str) -> Result<()> {
        let Some(c) = &mut self.collection else {
            return Ok(());
        };
        let mut text = String::new();
        let _ = writeln!(
            text,
            "    <DataSet timestep=\"{time:?}\" group=\"\" part=\"0\" file=\"{}\"/>",
            xml_escape(name)
        );
        let entry = text.len() as u64;
        text.push_str(PVD_TAIL);
        c.file
            .seek(SeekFrom::Start(c.tail_at))
            .and_then(|_| c.file.write_all(text.as_bytes()))
            .map_err(|e| write_error(&self.path, e))?;
        c.tail_at += entry;
        Ok(())
    }
}

fn write_error(path: &Path, e: std::io::Error) -> super::error::EngineError {
    invalid!(
        "cannot write {}: {e}; check that the folder is writable and the disk not full",
        path.display()
    )
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('"', "&quot;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The spheres of a scene as a frame: positions and radii in µm, swimmer, sphere (1 or 2), N.
struct Spheres {
    /// The periodic box's sides (µm), if any.
    cell: Option<[f64; 3]>,
    pos: Vec<[f64; 3]>,
    radius: Vec<f64>,
    swimmer: Vec<i32>,
    sphere: Vec<i32>,
    dir: Vec<[f64; 3]>,
}

impl Spheres {
    fn of(scene: &Scene) -> Self {
        let n = scene.sphere_count();
        let mut s = Spheres {
            cell: scene.periodic().map(|b| b.sides().map(|l| l * UM)),
            pos: Vec::with_capacity(n),
            radius: Vec::with_capacity(n),
            swimmer: Vec::with_capacity(n),
            sphere: Vec::with_capacity(n),
            dir: Vec::with_capacity(n),
        };
        for (i, d) in scene.swimmers().iter().enumerate() {
            let (x1, x2) = scene.shown_spheres(i);
            let dir = (x2 - x1).normalize();
            for (k, (x, a)) in [(x1, d.a1), (x2, d.a2)].into_iter().enumerate() {
                s.pos.push([x.x * UM, x.y * UM, x.z * UM]);
                s.radius.push(a * UM);
                s.swimmer.push(i as i32);
                s.sphere.push(k as i32 + 1);
                s.dir.push([dir.x, dir.y, dir.z]);
            }
        }
        s
    }

    /// One extended-XYZ frame (ends in a newline).
    fn xyz(&self, time: f64) -> String {
        let mut out = String::with_capacity(64 + 120 * self.pos.len());
        let _ = writeln!(out, "{}", self.pos.len());
        // A periodic box as the frame's cell (the box spans −L/2 … L/2 about the origin).
        let cell = match self.cell {
            Some([x, y, z]) => format!(
                "Lattice=\"{x:?} 0.0 0.0 0.0 {y:?} 0.0 0.0 0.0 {z:?}\" Origin=\"{:?} {:?} {:?}\" pbc=\"T T T\"",
                -0.5 * x,
                -0.5 * y,
                -0.5 * z
            ),
            None => "pbc=\"F F F\"".to_string(),
        };
        // The species names the sphere kind (a1, a2), so that viewers draw the two in two colours;
        // Z = 0 is ASE's dummy atom, which lets ASE read names that are no element's. The
        // orientation is `dipoles`: OVITO reads it as its "Dipole Orientation", ready for arrows.
        let _ = writeln!(
            out,
            "{cell} Properties=species:S:1:pos:R:3:radius:R:1:swimmer:I:1:sphere:I:1:dipoles:R:3:Z:I:1 Time={time:?} time_unit=s length_unit=um"
        );
        for k in 0..self.pos.len() {
            let (p, d) = (self.pos[k], self.dir[k]);
            let _ = writeln!(
                out,
                "a{} {:?} {:?} {:?} {:?} {} {} {:?} {:?} {:?} 0",
                self.sphere[k],
                p[0],
                p[1],
                p[2],
                self.radius[k],
                self.swimmer[k],
                self.sphere[k],
                d[0],
                d[1],
                d[2]
            );
        }
        out
    }

    /// One `.vtp` file: the spheres as vertices with point arrays radius, swimmer, sphere, N (the
    /// active vectors), and the length unit as field data.
    fn vtp(&self) -> Result<Vec<u8>> {
        use vtkio::model::{
            Attribute, Attributes, ByteOrder, DataArray, DataSet, PolyDataPiece, Version,
            VertexNumbers, Vtk,
        };
        let n = self.pos.len();
        let points: Vec<f64> = self.pos.iter().flatten().copied().collect();
        let vtk = Vtk {
            version: Version::new_xml(1, 0),
            byte_order: ByteOrder::LittleEndian,
            title: String::new(),
            file_path: None,
            data: DataSet::inline(PolyDataPiece {
                points: points.into(),
                verts: Some(VertexNumbers::XML {
                    connectivity: (0..n as u64).collect(),
                    offsets: (1..=n as u64).collect(),
                }),
                data: Attributes {
                    point: vec![
                        Attribute::DataArray(
                            DataArray::scalars("radius", 1).with_data(self.radius.clone()),
                        ),
                        Attribute::DataArray(
                            DataArray::scalars("swimmer", 1).with_data(self.swimmer.clone()),
                        ),
                        Attribute::DataArray(
                            DataArray::scalars("sphere", 1).with_data(self.sphere.clone()),
                        ),
                        Attribute::DataArray(
                            DataArray::vectors("N")
                                .with_data(self.dir.iter().flatten().copied().collect::<Vec<_>>()),
                        ),
                    ],
                    cell: Vec::new(),
                },
                ..Default::default()
            }),
        };
        super::vtk::xml_with_units(vtk, &[("length_unit", "um")], "a VTK frame")
    }
}
