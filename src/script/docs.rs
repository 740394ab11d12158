//! The help text of every script-visible name: what `:help NAME` shows. Each binding file keeps the
//! entries of its own names beside them (`DOCS`, entries of [`super::doc`]); this file gathers
//! them. Each entry has a runnable example (tests run them all, and check that every registered
//! function has an entry).

use std::sync::LazyLock;

pub use super::doc::Doc;

/// The order in which `:help` lists the groups.
const GROUPS: &[&str] = &[
    "building",
    "phases",
    "numerics",
    "thermal",
    "scene",
    "pictures",
    "running",
    "reading",
    "continuum",
    "observables",
    "collective",
    "recording",
    "files",
    "formatting",
    "swimmer properties",
];

/// Every documented name: each binding file's table, grouped as `:help` lists them.
pub static DOCS: LazyLock<Vec<Doc>> = LazyLock::new(|| {
    let mut all: Vec<Doc> = [
        super::scene_api::DOCS,
        super::run_api::DOCS,
        super::dumbbell_api::DOCS,
        super::scene_settings_api::DOCS,
        super::wall_api::DOCS,
        super::sweep_api::DOCS,
        super::plot_api::DOCS,
        super::picture_api::DOCS,
        super::field_api::DOCS,
        super::continuum_api::DOCS,
        super::integrator_api::DOCS,
        super::observable_api::DOCS,
        super::checkpoint_api::DOCS,
        super::collective_api::DOCS,
        super::params::DOCS,
        super::csv_api::DOCS,
        super::util_api::DOCS,
        super::view_api::DOCS,
    ]
    .concat();
    all.sort_by_key(|d| GROUPS.iter().position(|g| *g == d.group));
    all
});

/// The entry for `name`.
pub fn lookup(name: &str) -> Option<&'static Doc> {
    DOCS.iter().find(|d| d.name == name)
}
