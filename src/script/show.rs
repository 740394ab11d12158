//! How the REPL shows a value: the same text `print` gives for swimlab's types, Rhai's debug form
//! for the rest.

use rhai::{Array, Dynamic, Map};

/// Text for a value printed by the REPL.
pub fn show(v: &Dynamic) -> String {
    if let Some(text) = super::types::swimlab_text(v) {
        return text;
    }
    if let Some(f) = v.read_lock::<rhai::FnPtr>() {
        return super::types::fn_text(&f);
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
