//! `swimlab make-figures`: the paper's figure scripts, built into the binary, run in turn; their
//! pictures copied to a folder (e.g. docs/src/figures for the book).

use super::engine_builder::run_source_with;
use super::params::RunOptions;

/// The paper's figure scripts, built in for `swimlab make-figures`.
pub const PAPER_SCRIPTS: &[(&str, &str)] = &[
    (
        "scripts/paper/fig1a.rhai",
        include_str!("../../scripts/paper/fig1a.rhai"),
    ),
    (
        "scripts/paper/fig1b.rhai",
        include_str!("../../scripts/paper/fig1b.rhai"),
    ),
    (
        "scripts/paper/fig2a.rhai",
        include_str!("../../scripts/paper/fig2a.rhai"),
    ),
    (
        "scripts/paper/fig2b.rhai",
        include_str!("../../scripts/paper/fig2b.rhai"),
    ),
    (
        "scripts/paper/fig3.rhai",
        include_str!("../../scripts/paper/fig3.rhai"),
    ),
    (
        "scripts/paper/fig4.rhai",
        include_str!("../../scripts/paper/fig4.rhai"),
    ),
];

/// Run the built-in figure scripts and copy their pictures to `out`.
pub fn make_figures(quick: bool, out: Option<&std::path::Path>) -> Result<(), String> {
    let options = RunOptions {
        quick,
        sets: Vec::new(),
    };
    for (name, source) in PAPER_SCRIPTS {
        let start = std::time::Instant::now();
        run_source_with(name, source, &options)?;
        super::console::emit_line(&format!("{name}: {:.1} s", start.elapsed().as_secs_f64()))?;
    }
    if let Some(dir) = out {
        std::fs::create_dir_all(dir).map_err(|e| {
            format!(
                "cannot create folder {}: {e}; choose a folder you can write to",
                dir.display()
            )
        })?;
        let entries =
            std::fs::read_dir("out/paper").map_err(|e| format!("cannot read out/paper: {e}"))?;
        for entry in entries.flatten() {
            let path = entry.path();
            if path.extension().is_some_and(|e| e == "png") {
                let to = dir.join(entry.file_name());
                std::fs::copy(&path, &to)
                    .map_err(|e| format!("cannot copy to {}: {e}", to.display()))?;
                super::console::emit_line(&format!("copied {}", to.display()))?;
            }
        }
    }
    Ok(())
}
