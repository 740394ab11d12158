//! swimlab's script types, each named once in the words scripts use: their registration (name,
//! `to_string` and `to_debug` through their `Display`), their text (what `print`, `display` and
//! the shell show), and the type word every message gives for a value (the "Integrator" of "got
//! euler(1e-6) (Integrator)"). Rhai's own messages name custom types by their Rust paths; [`in_words`]
//! rewrites those, so no Rust path reaches a user.

use super::continuum_api::ContinuumHandle;
use super::dumbbell_api::DumbbellSpec;
use super::observable_api::RecorderHandle;
use super::picture_api::Picture;
use super::scene_api::SceneHandle;
use crate::engine::fields::Field;
use crate::engine::{IntegratorSpec, Observable, Trigger};
use rhai::{Dynamic, Engine};

macro_rules! script_types {
    ($($t:ty => $name:literal),+ $(,)?) => {
        /// Register every script type with its name and its `Display` as `to_string`/`to_debug`,
        /// and a closure's text without its generated name.
        pub fn register(engine: &mut Engine) {
            engine
                .register_fn("to_string", |f: &mut rhai::FnPtr| fn_text(f))
                .register_fn("to_debug", |f: &mut rhai::FnPtr| fn_text(f));
            $(
                engine
                    .register_type_with_name::<$t>($name)
                    .register_fn("to_string", |x: &mut $t| x.to_string())
                    .register_fn("to_debug", |x: &mut $t| x.to_string());
            )+
        }

        /// The text and script name of a swimlab value, or `None` for Rhai's own types.
        fn swimlab_value(v: &Dynamic) -> Option<(String, &'static str)> {
            $(
                if let Some(x) = v.read_lock::<$t>() {
                    return Some((x.to_string(), $name));
                }
            )+
            None
        }

        /// (Rust type path, script name) of every script type.
        fn rust_names() -> &'static [(&'static str, &'static str)] {
            static NAMES: std::sync::OnceLock<Vec<(&'static str, &'static str)>> =
                std::sync::OnceLock::new();
            NAMES.get_or_init(|| vec![$((std::any::type_name::<$t>(), $name)),+])
        }
    };
}

script_types! {
    SceneHandle => "Scene",
    DumbbellSpec => "Dumbbell",
    IntegratorSpec => "Integrator",
    Observable => "Observable",
    Trigger => "Trigger",
    RecorderHandle => "Recorder",
    Field => "Field",
    Picture => "Picture",
    ContinuumHandle => "Continuum",
}

/// A function pointer's text: `Fn(name)`, or `Fn(a closure)` for a closure, whose function has a
/// generated name ("anon$5f3c...") that says nothing.
pub fn fn_text(f: &rhai::FnPtr) -> String {
    if f.fn_name().starts_with("anon$") {
        "Fn(a closure)".into()
    } else {
        format!("Fn({})", f.fn_name())
    }
}

/// Rhai's names of its own types (as `Dynamic::type_name` and its messages give them) in the
/// words `:help` uses.
const RHAI_NAMES: &[(&str, &str)] = &[
    ("i64", "int"),
    ("f64", "float"),
    ("bool", "bool"),
    ("char", "char"),
    ("()", "()"),
    ("&str | ImmutableString | String", "string"),
    ("ImmutableString", "string"),
    ("alloc::string::String", "string"),
    ("string", "string"),
    ("array", "array"),
    ("map", "map"),
    ("Fn", "Fn"),
    ("blob", "blob"),
    ("timestamp", "timestamp"),
];

/// The text `print`, `display` and the shell give for a swimlab value (its `Display`); `None`
/// for Rhai's own types.
pub fn swimlab_text(v: &Dynamic) -> Option<String> {
    swimlab_value(&v.flatten_clone()).map(|(text, _)| text)
}

/// The script name of a Rust type path or of one of Rhai's type names ("Integrator", "int"), if
/// it is one this module knows.
pub fn script_name(rust: &str) -> Option<&'static str> {
    let rust = rust.trim();
    rust_names()
        .iter()
        .chain(RHAI_NAMES)
        .find(|(r, _)| *r == rust)
        .map(|(_, n)| *n)
}

/// A value's type in script words: "Integrator", "int", "float", "string", "array", ...
pub fn type_word(v: &Dynamic) -> String {
    let v = v.flatten_clone();
    if let Some((_, name)) = swimlab_value(&v) {
        return name.to_string();
    }
    let rust = v.type_name();
    script_name(rust).map_or_else(|| in_words(rust), str::to_string)
}

/// `msg` with every Rust type path of a script type (and Rhai's string type spellings) in
/// script words; any other `swimlab::` path is cut to its last segment.
pub fn in_words(msg: &str) -> String {
    let mut out = msg.to_string();
    for (rust, name) in rust_names() {
        out = out.replace(rust, name);
    }
    for (rust, name) in [
        ("&str | ImmutableString | String", "string"),
        ("alloc::string::String", "string"),
    ] {
        out = out.replace(rust, name);
    }
    while let Some(start) = out.find("swimlab::") {
        let rest = &out[start..];
        let end = rest
            .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
            .unwrap_or(rest.len());
        let path = &rest[..end];
        let last = path.rsplit("::").next().unwrap_or(path).to_string();
        out.replace_range(start..start + end, &last);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_script_type_has_a_name_without_a_rust_path() {
        for (rust, name) in rust_names() {
            assert!(rust.starts_with("swimlab::"), "{rust}");
            assert!(!name.contains("::"), "{name}");
            assert_eq!(script_name(rust), Some(*name));
        }
    }

    #[test]
    fn rust_paths_in_messages_become_script_words() {
        let msg = format!(
            "Function not found: f ({}, &str | ImmutableString | String, swimlab::engine::foo::Bar)",
            std::any::type_name::<IntegratorSpec>()
        );
        assert_eq!(
            in_words(&msg),
            "Function not found: f (Integrator, string, Bar)"
        );
    }
}
