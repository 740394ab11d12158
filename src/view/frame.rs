//! One frame of a scene as JSON, the format the page and users read (SI units):
//!
//! ```text
//! {"t": s, "periods": p or null, "steps": k, "box": [x, y, z] or null, "wall": z or null,
//!  "spheres": [[x, y, z, radius, kind], ...], "n": [[nx, ny, nz], ...],
//!  "rows": [{"t": s, "columns": {"name": value, ...}}, ...]}
//! ```
//!
//! Spheres go swimmer by swimmer, the a1 sphere (kind 1) before the a2 sphere (kind 2), at the
//! places snapshots show them (in a box each swimmer moved whole into it by its centre); `n` has
//! one orientation per swimmer; `rows` the latest row of each recorder of observables (its first
//! [`MAX_COLUMNS`] columns). Numbers are written in their shortest form that reads back exactly.

use crate::engine::{Recorder, Scene};
use std::fmt::Write;
use std::sync::Arc;

/// The most columns of one recorder a frame carries (a recorder of every swimmer's position
/// would make every frame as big as the scene again).
pub const MAX_COLUMNS: usize = 32;

/// Which of a frame's parts are sent: the spheres, the orientations, the recorders' rows (the
/// time, periods, steps, box and wall always are).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Parts {
    /// `spheres`.
    pub spheres: bool,
    /// `n`.
    pub n: bool,
    /// `rows`.
    pub rows: bool,
}

impl Default for Parts {
    fn default() -> Self {
        Parts {
            spheres: true,
            n: true,
            rows: true,
        }
    }
}

impl Parts {
    /// The names a user may give, in frame order.
    pub const NAMES: [&'static str; 3] = ["spheres", "n", "rows"];

    /// The parts named in `names` (each one of [`Parts::NAMES`]); `Err` names an unknown one.
    pub fn from_names<'a>(names: impl IntoIterator<Item = &'a str>) -> Result<Parts, String> {
        let mut p = Parts {
            spheres: false,
            n: false,
            rows: false,
        };
        for name in names {
            match name {
                "spheres" => p.spheres = true,
                "n" => p.n = true,
                "rows" => p.rows = true,
                other => return Err(other.to_string()),
            }
        }
        Ok(p)
    }
}

/// A recorder's latest row: its time, column names and values (at most [`MAX_COLUMNS`]).
#[derive(Debug, Clone)]
pub struct RowSnapshot {
    /// The row's time (s).
    pub t: f64,
    /// Column names, without the time's.
    pub names: Arc<[String]>,
    /// Values, one per name.
    pub values: Vec<f64>,
}

/// The latest rows of the recorders that have observables and rows.
pub fn latest_rows(recorders: &[Recorder]) -> Vec<RowSnapshot> {
    recorders
        .iter()
        .filter(|r| !r.observables.is_empty())
        .filter_map(|r| {
            let row = r.rows.last()?;
            let names: Vec<String> = r.columns().into_iter().skip(1).take(MAX_COLUMNS).collect();
            let values = row.iter().skip(1).take(names.len()).copied().collect();
            Some(RowSnapshot {
                t: row[0],
                names: names.into(),
                values,
            })
        })
        .collect()
}

/// A number as JSON: the shortest form that reads back exactly; `null` if not finite.
fn number(out: &mut String, x: f64) {
    if x.is_finite() {
        let _ = write!(out, "{x:e}");
    } else {
        out.push_str("null");
    }
}

fn numbers(out: &mut String, xs: &[f64]) {
    out.push('[');
    for (k, x) in xs.iter().enumerate() {
        if k > 0 {
            out.push(',');
        }
        number(out, *x);
    }
    out.push(']');
}

/// The frame of `s` with `rows`, its `parts` only.
pub fn encode(s: &Scene, rows: &[RowSnapshot], parts: Parts) -> String {
    let n = s.count();
    let mut out = String::with_capacity(256 + n * (if parts.spheres { 200 } else { 0 } + 70));
    out.push_str("{\"t\":");
    number(&mut out, s.time());
    out.push_str(",\"periods\":");
    match s.period() {
        Ok(p) => number(&mut out, s.time() / p),
        Err(_) => out.push_str("null"),
    }
    let _ = write!(out, ",\"steps\":{}", s.stats().steps);
    out.push_str(",\"box\":");
    match s.periodic() {
        Some(b) => numbers(&mut out, &b.sides()),
        None => out.push_str("null"),
    }
    out.push_str(",\"wall\":");
    match s.wall() {
        Some(w) => number(&mut out, w.z),
        None => out.push_str("null"),
    }
    if parts.spheres {
        out.push_str(",\"spheres\":[");
        for (i, d) in s.swimmers().iter().enumerate() {
            let (x1, x2) = s.shown_spheres(i);
            for (k, (x, a)) in [(x1, d.a1), (x2, d.a2)].into_iter().enumerate() {
                if i > 0 || k > 0 {
                    out.push(',');
                }
                numbers(&mut out, &[x.x, x.y, x.z, a]);
                out.pop();
                let _ = write!(out, ",{}]", k + 1);
            }
        }
        out.push(']');
    }
    if parts.n {
        out.push_str(",\"n\":[");
        for i in 0..n {
            if i > 0 {
                out.push(',');
            }
            let d = s.dir(i).map(|d| [d.x, d.y, d.z]).unwrap_or([f64::NAN; 3]);
            numbers(&mut out, &d);
        }
        out.push(']');
    }
    if parts.rows {
        out.push_str(",\"rows\":[");
        for (k, r) in rows.iter().enumerate() {
            if k > 0 {
                out.push(',');
            }
            out.push_str("{\"t\":");
            number(&mut out, r.t);
            out.push_str(",\"columns\":{");
            for (j, (name, v)) in r.names.iter().zip(&r.values).enumerate() {
                if j > 0 {
                    out.push(',');
                }
                out.push_str(&serde_json::Value::from(name.as_str()).to_string());
                out.push(':');
                number(&mut out, *v);
            }
            out.push_str("}}");
        }
        out.push(']');
    }
    out.push('}');
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_read_back_exactly_as_json() {
        let xs = [
            0.0,
            -0.0,
            1.0,
            -1.5e-6,
            1e-300,
            6.02214076e23,
            0.1 + 0.2,
            f64::MIN_POSITIVE,
        ];
        let mut out = String::new();
        numbers(&mut out, &xs);
        let back: Vec<f64> = serde_json::from_str(&out).unwrap();
        for (x, y) in xs.iter().zip(&back) {
            assert_eq!(x.to_bits() & !(1 << 63), y.to_bits() & !(1 << 63), "{out}");
        }
        let mut out = String::new();
        numbers(&mut out, &[f64::NAN, f64::INFINITY]);
        assert_eq!(out, "[null,null]");
    }

    #[test]
    fn parts_are_named() {
        assert_eq!(
            Parts::from_names(["spheres", "n", "rows"]),
            Ok(Parts::default())
        );
        assert_eq!(Parts::from_names(["sphere"]), Err("sphere".to_string()));
    }
}
