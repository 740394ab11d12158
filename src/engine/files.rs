//! Files that survive crashes: whole-file writes go to a temporary file beside the target and are
//! renamed over it (a crash or kill leaves the old file whole), and row streams append one whole
//! line per write, flushed at once (a kill loses no row already recorded and never leaves half a
//! line).
//!
//! A file that a writer keeps open (a row stream, a trajectory) is claimed for as long as the
//! writer lives: no other writer of this process may open it, and no whole-file write may replace
//! it, so two recorders never interleave their lines in one file. One exception: the writer of
//! an owner that is being replaced (a scene a shell input declares anew, see
//! [`super::simulation::Simulation::set_retiring`]) gives its file up to a new writer and writes
//! no more.

use super::error::{invalid, Result};
use std::io::{Seek, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

/// A file claimed by a writer of this process.
struct Held {
    key: PathBuf,
    /// What holds it, in words.
    holder: String,
    /// Whether the holder's owner is being replaced (its file may be taken over).
    retiring: Option<Arc<AtomicBool>>,
    /// Set when another writer took the file over.
    taken: Arc<AtomicBool>,
}

/// Files claimed by the writers of this process.
static CLAIMED: Mutex<Vec<Held>> = Mutex::new(Vec::new());

/// Where `path` is, the same for every spelling of it: its folder's canonical path and its name
/// (`None` if the folder does not exist).
fn claim_key(path: &Path) -> Option<PathBuf> {
    let name = path.file_name()?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    Some(std::fs::canonicalize(dir).ok()?.join(name))
}

/// What holds `path`, if a writer of this process claimed it.
fn holder(path: &Path) -> Option<String> {
    let key = claim_key(path)?;
    let claimed = CLAIMED.lock().unwrap_or_else(|e| e.into_inner());
    claimed
        .iter()
        .find(|h| h.key == key)
        .map(|h| h.holder.clone())
}

fn held_error(path: &Path, holder: &str) -> super::error::EngineError {
    invalid!(
        "{} is being written by {holder} in this session; a second writer would mix its lines into that file: give this one another path",
        path.display()
    )
}

/// A file claimed by one writer for as long as this lives (see the module docs).
#[derive(Debug)]
pub struct Claim {
    key: PathBuf,
    taken: Arc<AtomicBool>,
}

impl Claim {
    /// Claim `path` (its folder must exist) for a writer described by `what` ("a trajectory"),
    /// owned by something that may be replaced while the claim lives (`retiring`), unless
    /// another writer of this process holds it (and its owner is not being replaced).
    pub fn take(path: &Path, what: &str, retiring: Option<Arc<AtomicBool>>) -> Result<Claim> {
        let key = claim_key(path).ok_or_else(|| {
            invalid!(
                "cannot write {}: its folder does not exist; give a path such as \"out/run.csv\"",
                path.display()
            )
        })?;
        let mut claimed = CLAIMED.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(i) = claimed.iter().position(|h| h.key == key) {
            let h = &claimed[i];
            if !h
                .retiring
                .as_ref()
                .is_some_and(|r| r.load(Ordering::SeqCst))
            {
                return Err(held_error(path, &h.holder));
            }
            h.taken.store(true, Ordering::SeqCst);
            claimed.swap_remove(i);
        }
        let taken = Arc::new(AtomicBool::new(false));
        claimed.push(Held {
            key: key.clone(),
            holder: what.to_string(),
            retiring,
            taken: taken.clone(),
        });
        Ok(Claim { key, taken })
    }

    /// Whether this claim is on `path`.
    pub fn is_on(&self, path: &Path) -> bool {
        claim_key(path).is_some_and(|k| k == self.key)
    }

    /// Whether another writer took the file over (this one must write no more).
    pub fn lost(&self) -> bool {
        self.taken.load(Ordering::SeqCst)
    }
}

impl Drop for Claim {
    fn drop(&mut self) {
        let mut claimed = CLAIMED.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(i) = claimed
            .iter()
            .position(|h| Arc::ptr_eq(&h.taken, &self.taken))
        {
            claimed.swap_remove(i);
        }
    }
}

/// Create the folder that will hold `path`, with an error that names the fix.
pub fn ensure_parent(path: &Path) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| {
            invalid!(
                "cannot create folder {}: {e}; choose a path in a folder you can write to",
                dir.display()
            )
        })?;
    }
    Ok(())
}

/// File name endings of formats other than CSV that swimlab writes or that programs open by their
/// ending, with what they are.
const NOT_CSV: &[(&str, &str)] = &[
    ("png", "a PNG picture"),
    ("svg", "an SVG picture"),
    ("gif", "a GIF animation"),
    ("jpg", "a JPEG picture"),
    ("jpeg", "a JPEG picture"),
    ("pdf", "a PDF document"),
    ("vti", "VTK image data"),
    ("vtp", "VTK poly data"),
    ("vtk", "a VTK file"),
    ("pvd", "a ParaView series"),
    ("xyz", "an extended XYZ trajectory"),
    ("json", "JSON (a saved scene)"),
    ("rhai", "a script"),
];

/// Refuse writing CSV text to `path` when its name says another format (a `.png` that no picture
/// viewer would open): `what` is the writer ("to_csv").
pub fn check_csv_name(path: &Path, what: &str) -> Result<()> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if let Some((e, format)) = ext.and_then(|x| NOT_CSV.iter().find(|(e, _)| *e == x)) {
        return Err(invalid!(
            "{what}: {} ends in .{e}, the name of {format}, but this writes CSV text that the programs opening .{e} files cannot read; give a name ending in .csv",
            path.display()
        ));
    }
    Ok(())
}

/// Create (or truncate) the file `path` for writing, its folder created, with errors that name
/// the path and the fix.
pub fn create(path: &Path) -> Result<std::fs::File> {
    check_target(path)?;
    std::fs::File::create(path).map_err(|e| write_error(path, e))
}

/// What a whole-file write to `path` needs first: a name, its folder (created), no folder in its
/// place, and no writer of this process holding it.
fn check_target(path: &Path) -> Result<()> {
    if path.as_os_str().is_empty() {
        return Err(invalid!(
            "cannot write a file with an empty name; give a path such as \"out/run.csv\""
        ));
    }
    ensure_parent(path)?;
    if path.is_dir() {
        return Err(invalid!(
            "cannot write {}: it is a folder; give a file name",
            path.display()
        ));
    }
    match holder(path) {
        Some(h) => Err(held_error(path, &h)),
        None => Ok(()),
    }
}

fn write_error(path: &Path, e: std::io::Error) -> super::error::EngineError {
    invalid!(
        "cannot write {}: {e}; check that the folder is writable and the disk not full",
        path.display()
    )
}

/// Write a whole file through `fill`: into a temporary file in the same folder, synced, then
/// renamed over `path`, so that `path` holds either the old content or all of the new.
pub fn write_atomically(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    check_target(path)?;
    if std::fs::metadata(path).is_ok_and(|m| !m.is_file()) {
        // A device or pipe (/dev/stdout, a FIFO) is written in place: renaming over it would
        // replace the device node.
        let result = std::fs::OpenOptions::new()
            .write(true)
            .open(path)
            .and_then(|f| {
                let mut w = std::io::BufWriter::new(f);
                fill(&mut w)?;
                w.flush()
            });
        return result.map_err(|e| write_error(path, e));
    }
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "file".into());
    let tmp: PathBuf = path.with_file_name(format!(".{name}.swimlab-{}.tmp", std::process::id()));
    let result = (|| -> std::io::Result<()> {
        let file = std::fs::File::create(&tmp)?;
        let mut w = std::io::BufWriter::new(file);
        fill(&mut w)?;
        let file = w.into_inner().map_err(|e| e.into_error())?;
        file.sync_data()?;
        std::fs::rename(&tmp, path)
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(write_error(path, e));
    }
    Ok(())
}

/// A file that rows are appended to as they are recorded, one whole line per write; claimed
/// while the stream lives. A write that fails part way (a full disk, a file size limit) is cut
/// back to the last whole line.
#[derive(Debug)]
pub struct LineStream {
    file: std::fs::File,
    path: PathBuf,
    claim: Claim,
    /// Bytes of whole lines written.
    len: u64,
}

impl LineStream {
    /// Create (or truncate) `path` and write `first` lines into it; `what` names the writer
    /// ("a trajectory") for a second writer's error, `retiring` its owner's flag ([`Claim::take`]).
    pub fn create(
        path: &Path,
        first: &[String],
        what: &str,
        retiring: Option<Arc<AtomicBool>>,
    ) -> Result<Self> {
        if path.as_os_str().is_empty() {
            return Err(invalid!(
                "cannot write a file with an empty name; give a path such as \"out/run.csv\""
            ));
        }
        ensure_parent(path)?;
        let claim = Claim::take(path, what, retiring)?;
        let file = std::fs::File::create(path).map_err(|e| write_error(path, e))?;
        let mut s = LineStream {
            file,
            path: path.to_path_buf(),
            claim,
            len: 0,
        };
        for line in first {
            s.append(line)?;
        }
        Ok(s)
    }

    /// The file written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Whether this stream writes `path`.
    pub fn is_at(&self, path: &Path) -> bool {
        self.claim.is_on(path)
    }

    /// Append one line (a newline is added) with a single write, so that a kill never leaves
    /// half a line; a write that fails part way is cut back to the last whole line (and the
    /// next append continues from there). Nothing is written once another writer took the file
    /// over.
    pub fn append(&mut self, line: &str) -> Result<()> {
        if self.claim.lost() {
            return Ok(());
        }
        let mut buf = String::with_capacity(line.len() + 1);
        buf.push_str(line);
        buf.push('\n');
        match self.file.write_all(buf.as_bytes()) {
            Ok(()) => {
                self.len += buf.len() as u64;
                Ok(())
            }
            Err(e) => {
                // Cutting back frees what the partial line took, so it succeeds on a full disk;
                // should it fail too, the write's error is still the one to tell.
                let _ = self.file.set_len(self.len);
                let _ = self.file.seek(std::io::SeekFrom::Start(self.len));
                Err(write_error(&self.path, e))
            }
        }
    }
}
