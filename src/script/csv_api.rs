//! `write_csv(path, rows)` / `write_csv(path, columns, rows)`: tables from scripts.

use super::convert::{script_error, ScriptResult};
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

/// Write `rows` (maps) under the header `columns` to `path`, creating parent folders.
pub fn write_table(path: &str, columns: &[String], rows: &[Map]) -> ScriptResult<()> {
    let p = Path::new(path);
    if let Some(dir) = p.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| script_error(format!("cannot create folder {}: {e}", dir.display())))?;
    }
    let mut w =
        csv::Writer::from_path(p).map_err(|e| script_error(format!("cannot write {path}: {e}")))?;
    let io = |e: csv::Error| script_error(format!("cannot write {path}: {e}"));
    w.write_record(columns).map_err(io)?;
    for (k, row) in rows.iter().enumerate() {
        let record: Vec<String> = columns
            .iter()
            .map(|c| {
                row.get(c.as_str()).map(cell).ok_or_else(|| {
                    script_error(format!("write_csv: row {k} has no column \"{c}\""))
                })
            })
            .collect::<ScriptResult<_>>()?;
        w.write_record(&record).map_err(io)?;
    }
    w.flush()
        .map_err(|e| script_error(format!("cannot write {path}: {e}")))
}

fn maps(rows: Array) -> ScriptResult<Vec<Map>> {
    rows.into_iter()
        .enumerate()
        .map(|(k, r)| {
            let t = r.type_name();
            r.try_cast::<Map>().ok_or_else(|| {
                script_error(format!(
                    "write_csv: row {k} must be an object map such as #{{ D: 10.0, drift: 1e-6 }}, got {t}"
                ))
            })
        })
        .collect()
}

/// Register `write_csv`.
pub fn register(engine: &mut Engine) {
    engine
        .register_fn(
            "write_csv",
            |path: &str, columns: Array, rows: Array| -> ScriptResult<()> {
                let cols: Vec<String> = columns.iter().map(|c| c.to_string()).collect();
                write_table(path, &cols, &maps(rows)?)
            },
        )
        .register_fn("write_csv", |path: &str, rows: Array| -> ScriptResult<()> {
            let rows = maps(rows)?;
            let cols: Vec<String> = rows
                .first()
                .map(|r| r.keys().map(|k| k.to_string()).collect())
                .unwrap_or_default();
            write_table(path, &cols, &rows)
        });
}
