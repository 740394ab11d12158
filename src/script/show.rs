//! How the REPL shows a value: the same text `print` gives for swimlab's types, Rhai's debug form
//! for the rest.

use super::dumbbell_api::DumbbellSpec;
use super::observable_api::RecorderHandle;
use super::scene_api::{summary, SceneHandle};
use crate::engine::{IntegratorSpec, Observable, Trigger};
use rhai::{Array, Dynamic, Map};

/// Text for a value printed by the REPL.
pub fn show(v: &Dynamic) -> String {
    if let Some(s) = v.clone().try_cast::<SceneHandle>() {
        return summary(&s.borrow());
    }
    if let Some(d) = v.clone().try_cast::<DumbbellSpec>() {
        return d.to_string();
    }
    if let Some(i) = v.clone().try_cast::<IntegratorSpec>() {
        return i.to_string();
    }
    if let Some(o) = v.clone().try_cast::<Observable>() {
        return format!("{} [{}]", o.name(), o.unit());
    }
    if let Some(t) = v.clone().try_cast::<Trigger>() {
        return t.describe();
    }
    if let Some(r) = v.clone().try_cast::<RecorderHandle>() {
        return r.describe();
    }
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
