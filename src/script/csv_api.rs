//! `write_csv(path, rows)` / `write_csv(path, columns, rows[, #{ notes }])`: tables from scripts.

use super::convert::{describe, script_error, ScriptResult};
use super::doc::{doc_entry, Doc};
use crate::engine::files::{check_csv_name, write_atomically};
use rhai::{Array, Dynamic, Engine, Map};
use std::path::Path;

fn cell(v: &Dynamic) -> String {
    if let Some(f) = v.clone().try_cast::<f64>() {
        // Shortest representation that reads back to the same f64.
        format!("{f:?}")
    } else {
        v.to_string()
    }
}

/// Write `rows` (maps) under the header `columns` to `path`, after `notes` as comment lines
/// ("# " and the note), creating parent folders (through a temporary file renamed over `path`: a
/// crash keeps the old file whole).
pub fn write_table(
    path: &str,
    columns: &[String],
    rows: &[Map],
    notes: &[String],
) -> ScriptResult<()> {
    let mut records = Vec::with_capacity(rows.len());
    for (k, row) in rows.iter().enumerate() {
        let record: Vec<String> = columns
            .iter()
            .map(|c| {
                row.get(c.as_str()).map(cell).ok_or_else(|| {
                    script_error(format!(
                        "write_csv: row {k} has no column \"{c}\"; give every row the same keys"
                    ))
                })
            })
            .collect::<ScriptResult<_>>()?;
        records.push(record);
    }
    super::convert::lift(check_csv_name(Path::new(path), "write_csv"))?;
    super::convert::lift(write_atomically(Path::new(path), |w| {
        for note in notes {
            for line in note.lines() {
                writeln!(w, "# {line}")?;
            }
        }
        let mut csv = csv::Writer::from_writer(w);
        csv.write_record(columns)?;
        for r in &records {
            csv.write_record(r)?;
        }
        csv.flush()
    }))
}

fn maps(rows: Array) -> ScriptResult<Vec<Map>> {
    rows.into_iter()
        .enumerate()
        .map(|(k, r)| {
            let got = describe(&r);
            r.try_cast::<Map>().ok_or_else(|| {
                script_error(format!(
                    "write_csv: row {k} must be an object map such as #{{ D: 10.0, drift: 1e-6 }}, got {got}"
                ))
            })
        })
        .collect()
}

/// The notes of `write_csv`'s options: #{ notes: [text, ...] } (or one text).
fn notes(options: Map) -> ScriptResult<Vec<String>> {
    let mut out = Vec::new();
    for (key, value) in options {
        if key != "notes" {
            return Err(script_error(format!(
                "write_csv: unknown option \"{key}\"; the options are #{{ notes: [\"made by ...\"] }}"
            )));
        }
        let items = if value.is_array() {
            value.cast::<Array>()
        } else {
            vec![value]
        };
        for item in items {
            let got = describe(&item);
            let text = item.into_immutable_string().map_err(|_| {
                script_error(format!(
                    "write_csv: each note is a text, such as run_info().command; got {got}"
                ))
            })?;
            out.push(text.to_string());
        }
    }
    Ok(out)
}

/// Register `write_csv`.
pub fn register(engine: &mut Engine) {
    engine
        .register_fn(
            "write_csv",
            |path: &str, columns: Array, rows: Array| -> ScriptResult<()> {
                let cols: Vec<String> = columns.iter().map(|c| c.to_string()).collect();
                write_table(path, &cols, &maps(rows)?, &[])
            },
        )
        .register_fn(
            "write_csv",
            |path: &str, columns: Array, rows: Array, options: Map| -> ScriptResult<()> {
                let cols: Vec<String> = columns.iter().map(|c| c.to_string()).collect();
                write_table(path, &cols, &maps(rows)?, &notes(options)?)
            },
        )
        .register_fn("write_csv", |path: &str, rows: Array| -> ScriptResult<()> {
            let rows = maps(rows)?;
            let cols: Vec<String> = rows
                .first()
                .map(|r| r.keys().map(|k| k.to_string()).collect())
                .unwrap_or_default();
            write_table(path, &cols, &rows, &[])
        });
}

/// The help text of this file's script names (`:help NAME`), gathered by [`super::docs`].
pub(super) const DOCS: &[Doc] = &[doc_entry!(
    "write_csv",
    "files",
    "write_csv(path, rows)\nwrite_csv(path, columns, rows)\nwrite_csv(path, columns, rows, #{ notes })",
    "Write an array of maps as CSV (columns in the given order, or sorted). notes: texts written first as comment lines (\"# \" and the text; pandas reads them with comment=\"#\"), such as what made the file: let i = run_info(); #{ notes: [i.command, i.build, i.machine] }. A name ending in another format's extension (.png, .svg, .gif, .vti, .vtp, .pvd, .xyz, .json, ...) is refused: CSV text under it would open in no program for that format.",
    "write_csv(\"out/help/t.csv\", [\"D\", \"v\"], [#{ D: 10.0, v: 1e-6 }]);"
)];
