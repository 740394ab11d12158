//! Script and scene files as text: read with a bound on their size and errors that name the
//! file and the fix; a leading byte-order mark dropped.

/// The largest script or scene file swimlab reads (bytes): far above any real one, and a bound
/// on what a wrong path (a device, a huge data file) can cost.
pub const MAX_SOURCE_BYTES: u64 = 16 << 20;

/// Script text without a leading UTF-8 byte-order mark (editors on Windows write one).
pub fn strip_bom(source: &str) -> &str {
    source.strip_prefix('\u{feff}').unwrap_or(source)
}

/// Read a text file of at most `max` bytes, with errors that name the file and the fix.
pub fn read_text(path: &std::path::Path, max: u64, what: &str) -> Result<String, String> {
    use std::io::Read;
    let shown = path.display();
    let too_big = || {
        format!(
            "cannot read {what} {shown}: it is larger than {max} bytes, more than any {what} swimlab writes; check the path"
        )
    };
    let file = std::fs::File::open(path).map_err(|e| {
        format!("cannot read {what} {shown}: {e}; check the path (relative paths start in the working folder)")
    })?;
    if let Ok(m) = file.metadata() {
        if m.is_dir() {
            return Err(format!(
                "cannot read {what} {shown}: it is a folder; give a file"
            ));
        }
        // A regular file is measured before reading; a device or pipe by reading at most max + 1.
        if m.is_file() && m.len() > max {
            return Err(too_big());
        }
    }
    let mut bytes = Vec::new();
    file.take(max + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read {what} {shown}: {e}"))?;
    if bytes.len() as u64 > max {
        return Err(too_big());
    }
    String::from_utf8(bytes).map_err(|e| {
        format!("cannot read {what} {shown}: it is not UTF-8 text ({e}); save it as UTF-8")
    })
}
