//! What a drawing becomes: a picture in memory, or a file in a format named by its extension.

/// A picture drawn in memory (for notebooks): PNG bytes and SVG text of the same drawing.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    /// The PNG file's bytes.
    pub png: Vec<u8>,
    /// The SVG document.
    pub svg: String,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

/// File formats by extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Scalable vector graphics.
    Svg,
    /// Portable network graphics.
    Png,
}

impl Format {
    /// The format a path's extension names.
    pub fn of(path: &std::path::Path) -> Result<Self, String> {
        match path.extension().and_then(|e| e.to_str()) {
            Some(e) if e.eq_ignore_ascii_case("svg") => Ok(Format::Svg),
            Some(e) if e.eq_ignore_ascii_case("png") => Ok(Format::Png),
            _ => Err(format!(
                "cannot tell the picture format of \"{}\"; end the file name in .svg or .png",
                path.display()
            )),
        }
    }
}
