//! Files that survive crashes: whole-file writes go to a temporary file beside the target and are
//! renamed over it (a crash or kill leaves the old file whole), and row streams append one whole
//! line per write, flushed at once (a kill loses no row already recorded and never leaves half a
//! line).

use super::error::{invalid, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

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

/// A file that rows are appended to as they are recorded, one whole line per write.
#[derive(Debug)]
pub struct LineStream {
    file: std::fs::File,
    path: PathBuf,
}

impl LineStream {
    /// Create (or truncate) `path` and write `first` lines into it.
    pub fn create(path: &Path, first: &[String]) -> Result<Self> {
        ensure_parent(path)?;
        let file = std::fs::File::create(path).map_err(|e| write_error(path, e))?;
        let mut s = LineStream {
            file,
            path: path.to_path_buf(),
        };
        for line in first {
            s.append(line)?;
        }
        Ok(s)
    }

    /// Append one line (a newline is added) with a single write, so that the file never ends
    /// in half a line.
    pub fn append(&mut self, line: &str) -> Result<()> {
        let mut buf = String::with_capacity(line.len() + 1);
        buf.push_str(line);
        buf.push('\n');
        self.file
            .write_all(buf.as_bytes())
            .map_err(|e| write_error(&self.path, e))
    }
}
