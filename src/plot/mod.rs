//! Pictures of what swimlab measures: line and point plots of series to SVG or PNG files, quick
//! plots as text for the terminal, and snapshots of a scene (its spheres projected on a plane).
//!
//! This layer sits between the engine and the script bindings: it reads engine types (a
//! [`crate::engine::Scene`] for snapshots) and knows nothing of Rhai. Files are drawn with
//! plotters, headless: text is set in an embedded subset of DejaVu Sans, so no system font is
//! needed.
//!
//! What a plot is in `figure` ([`Figure`], [`Series`], [`Style`], [`Legend`]); what a drawing
//! becomes in `image` ([`Image`] in memory, a file [`Format`]); the drawing itself (plotters) in
//! `render`; tick labels in `ticks`; text plots in `text`; scene snapshots and films in
//! `snapshot`; heat maps in `heatmap`.

mod figure;
mod heatmap;
mod image;
mod render;
mod snapshot;
mod text;
mod ticks;

pub use figure::{Figure, Legend, Series, Style, COLORS, MAX_LOG_DECADES};
pub use heatmap::HeatMap;
pub use image::{Format, Image};
pub use snapshot::{scene_image, snapshot, Plane, SceneFilm, SnapshotOptions};
pub use text::render_text;
pub use ticks::format_number;
