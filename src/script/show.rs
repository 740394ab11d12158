//! How the REPL shows a value: the same text `print` gives for swimlab's types, Rhai's debug form
//! for the rest.

use super::dumbbell_api::DumbbellSpec;
use super::observable_api::RecorderHandle;
use super::picture_api::Picture;
use super::scene_api::SceneHandle;
use crate::engine::{IntegratorSpec, Observable, Trigger};
use rhai::{Array, Dynamic, Map};

/// The text of the first of `types` that `v` holds, through its `Display` (the one the type's
/// `to_string` uses).
macro_rules! displayed {
    ($v:expr; $($t:ty),+) => {
        $(if let Some(x) = $v.read_lock::<$t>() {
            return x.to_string();
        })+
    };
}

/// Text for a value printed by the REPL.
pub fn show(v: &Dynamic) -> String {
    displayed!(v; SceneHandle, DumbbellSpec, IntegratorSpec, Observable, Trigger, RecorderHandle, Picture);
    if let Some(a) = v.clone().try_cast::<Array>() {
        return format!("[{}]", a.iter().map(show).collect::<Vec<_>>().join(", "));
    }
    if let Some(m) = v.clone().try_cast::<Map>() {
        let items: Vec<String> = m.iter().map(|(k, x)| format!("{k}: {}", show(x))).collect();
        return format!("#{{{}}}", items.join(", "));
    }
    if let Ok(f) = v.as_float() {
        return format!("{f:?}");
    }
    if v.is_string() {
        return format!("{v:?}");
    }
    v.to_string()
}
