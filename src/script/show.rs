//! How the REPL shows a value: the same text `print` gives for swimlab's types, Rhai's debug form
//! for the rest.

use rhai::{Array, Dynamic, Map};

/// Longest value text a message quotes (a scene's summary runs to a few hundred characters).
const QUOTED_CHARS: usize = 80;

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

/// A value as a message quotes it: its text (as the shell shows it, shortened) and its type,
/// "euler(1e-6) (Integrator)", "\"x\" (string)"; `()` alone.
pub fn describe(v: &Dynamic) -> String {
    if v.is_unit() {
        return "()".into();
    }
    format!("{} ({})", quote(v), super::types::type_word(v))
}

/// A value as a message quotes it: its text as the shell shows it, shortened.
pub fn quote(v: &Dynamic) -> String {
    let text = show(v);
    if text.chars().count() > QUOTED_CHARS {
        let cut: String = text.chars().take(QUOTED_CHARS).collect();
        format!("{cut}…")
    } else {
        text
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::IntegratorSpec;

    #[test]
    fn values_are_described_in_script_words() {
        let spec = Dynamic::from(IntegratorSpec::Euler { dt: 1e-6 });
        assert_eq!(super::super::types::type_word(&spec), "Integrator");
        let d = describe(&spec);
        assert!(
            d.starts_with("euler(") && d.ends_with("(Integrator)"),
            "{d}"
        );
        assert_eq!(super::super::types::type_word(&Dynamic::from_int(1)), "int");
        assert_eq!(
            super::super::types::type_word(&Dynamic::from_float(1.0)),
            "float"
        );
        assert_eq!(
            super::super::types::type_word(&Dynamic::from("x")),
            "string"
        );
        assert_eq!(describe(&Dynamic::UNIT), "()");
    }
}
