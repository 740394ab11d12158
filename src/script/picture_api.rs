//! Pictures as values: `plot(series)`, `rec.plot(x, ys)` and `s.snapshot()` without a path give
//! a `Picture`, drawn in memory as PNG and SVG. A notebook shows it inline; the REPL shows what
//! it is; `pic.save(path)` writes it.

use super::convert::{script_error, ScriptResult};
use super::doc::doc_entry;
use super::doc::Doc;
use crate::plot::Image;
use rhai::Engine;
use std::sync::Arc;

/// A drawn picture and what it shows.
#[derive(Debug, Clone)]
pub struct Picture {
    image: Arc<Image>,
    what: String,
}

impl Picture {
    /// A picture of `what` ("plot", "snapshot").
    pub fn new(image: Image, what: &str) -> Self {
        Picture {
            image: Arc::new(image),
            what: what.to_string(),
        }
    }

    /// The drawing: PNG bytes and SVG text.
    pub fn image(&self) -> &Image {
        &self.image
    }

    /// Write the picture to `path`: PNG or SVG by the extension, whole or not at all.
    pub(crate) fn save(&self, path: &str) -> ScriptResult<()> {
        let p = std::path::Path::new(path);
        let format = crate::plot::Format::of(p).map_err(script_error)?;
        let bytes: &[u8] = match format {
            crate::plot::Format::Png => &self.image.png,
            crate::plot::Format::Svg => self.image.svg.as_bytes(),
        };
        crate::engine::files::write_atomically(p, |w| w.write_all(bytes))
            .map_err(|e| script_error(e.to_string()))
    }
}

impl std::fmt::Display for Picture {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "picture ({}, {}x{} pixels): a notebook shows it; pic.save(\"file.png\") or .svg writes it",
            self.what, self.image.width, self.image.height
        )
    }
}

/// Register the `Picture` type.
pub fn register(engine: &mut Engine) {
    engine.register_fn("save", |p: &mut Picture, path: &str| p.save(path));
}

/// The help text of this file's script names (`:help NAME`), gathered by [`super::docs`].
pub(super) const DOCS: &[Doc] = &[doc_entry!(
    "Picture",
    "pictures",
    "plot(series) -> Picture\nplot(series, options) -> Picture\nrec.plot(x_column, y_columns) -> Picture\ns.snapshot() -> Picture\ns.snapshot(options) -> Picture\npic.save(path)",
    "A picture held as a value: plot, rec.plot and s.snapshot called without a path draw one in memory (PNG and SVG). A notebook (swimlab kernel) shows it inline when it is a cell's value; at the prompt it is described; pic.save(path) writes it as PNG or SVG by the extension.",
    "let pic = plot(#{ x: [1, 2, 3], y: [1, 4, 9] }); pic.save(\"out/help/pic.png\"); print(pic);"
)];
