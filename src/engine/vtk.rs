//! VTK XML files (ParaView, VTK's readers, OVITO) from vtkio's model, with the units as the
//! dataset's field data.
//!
//! vtkio writes point and cell arrays but drops field data in XML files, so the units are spliced
//! in as VTK string arrays (`length_unit` = `um`, ...) where VTK's own writer puts them: the
//! first child of the dataset element, before its first `<Piece`. Array names stay plain words
//! (viewers rename or quote names with spaces and slashes); what their values are measured in is
//! read from the field data, or from the docs.

use super::error::{invalid, Result};

/// The bytes of `vtk` as a VTK XML file with `units` (name, value) as string field data; `what`
/// names the file in errors ("a VTK frame").
pub(crate) fn xml_with_units(
    vtk: vtkio::Vtk,
    units: &[(&str, &str)],
    what: &str,
) -> Result<Vec<u8>> {
    let file =
        vtkio::xml::VTKFile::try_from(vtk).map_err(|e| invalid!("cannot make {what}: {e}"))?;
    let mut bytes = Vec::new();
    file.write(&mut bytes)
        .map_err(|e| invalid!("cannot write {what}: {e}"))?;
    let at = find(&bytes, b"<Piece")
        .ok_or_else(|| invalid!("cannot write {what}: the dataset has no piece"))?;
    let mut out = Vec::with_capacity(bytes.len() + 128 * units.len());
    out.extend_from_slice(&bytes[..at]);
    out.extend_from_slice(field_data(units).as_bytes());
    out.extend_from_slice(&bytes[at..]);
    Ok(out)
}

/// `<FieldData>` with one VTK string array per (name, value): in ASCII, a string is its bytes as
/// numbers, ended by a 0.
fn field_data(units: &[(&str, &str)]) -> String {
    let mut s = String::from("<FieldData>");
    for (name, value) in units {
        let codes: Vec<String> = value
            .bytes()
            .map(|b| b.to_string())
            .chain(["0".to_string()])
            .collect();
        s.push_str(&format!(
            "<DataArray type=\"String\" Name=\"{name}\" NumberOfTuples=\"1\" format=\"ascii\">{}</DataArray>",
            codes.join(" ")
        ));
    }
    s.push_str("</FieldData>");
    s
}

fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).position(|w| w == needle)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_unit_is_its_bytes_ended_by_zero() {
        assert_eq!(
            field_data(&[("length_unit", "um")]),
            "<FieldData><DataArray type=\"String\" Name=\"length_unit\" NumberOfTuples=\"1\" format=\"ascii\">117 109 0</DataArray></FieldData>"
        );
    }
}
