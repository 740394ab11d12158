//! `swimlab kernel install`: the kernelspec that tells Jupyter how to start this kernel.

use serde_json::json;
use std::path::{Path, PathBuf};

/// Where `install` writes: the user's Jupyter data folder, or a prefix's.
pub enum Target {
    /// `$JUPYTER_DATA_DIR`, else the platform's per-user folder.
    User,
    /// `DIR/share/jupyter` (an environment's prefix, e.g. a venv).
    Prefix(PathBuf),
}

fn data_dir(target: &Target) -> Result<PathBuf, String> {
    match target {
        Target::Prefix(p) => Ok(p.join("share").join("jupyter")),
        Target::User => {
            if let Some(d) = crate::repl::env_path("JUPYTER_DATA_DIR", false) {
                return Ok(d);
            }
            let home = crate::repl::env_path("HOME", false)
                .ok_or("HOME is not set (or empty); give --prefix DIR")?;
            if cfg!(target_os = "macos") {
                Ok(home.join("Library").join("Jupyter"))
            } else {
                let data = crate::repl::env_path("XDG_DATA_HOME", true)
                    .unwrap_or_else(|| home.join(".local").join("share"));
                Ok(data.join("jupyter"))
            }
        }
    }
}

/// The kernel.json of a kernel started as `exe kernel -f {connection_file}`.
pub fn kernel_json(exe: &Path) -> serde_json::Value {
    json!({
        "argv": [exe.to_string_lossy(), "kernel", "-f", "{connection_file}"],
        "display_name": "swimlab",
        "language": "swimlab",
        "interrupt_mode": "signal",
        "metadata": {"debugger": false},
    })
}

/// Write the kernelspec "swimlab" for this executable; returns its folder.
pub fn install(target: &Target) -> Result<PathBuf, String> {
    let exe = std::env::current_exe()
        .and_then(|p| p.canonicalize())
        .map_err(|e| format!("cannot tell where this swimlab executable is: {e}"))?;
    let dir = data_dir(target)?.join("kernels").join("swimlab");
    std::fs::create_dir_all(&dir).map_err(|e| format!("cannot make {}: {e}", dir.display()))?;
    let text = serde_json::to_string_pretty(&kernel_json(&exe)).unwrap_or_default();
    let path = dir.join("kernel.json");
    crate::script::write_atomically(&path, |w| w.write_all(text.as_bytes()))
        .map_err(|e| e.to_string())?;
    Ok(dir)
}
