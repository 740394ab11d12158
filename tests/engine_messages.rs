//! The engine speaks engine terms, the script layer script terms: an engine error names its fix
//! as a typed [`Setting`] ("the micro model" to a Rust embedder), and the script layer shows the
//! same fix as the line that makes it (`s.model = "micro"`). No string in `src/engine` holds
//! script syntax.

use swimlab::engine::error::Setting;
use swimlab::engine::{Dumbbell, EngineError, Model, Scene, Simulation};
use swimlab::script::engine_message;

fn fixes(e: &EngineError) -> Vec<Setting> {
    match e {
        EngineError::Unsupported { fixes, .. } | EngineError::StepFailed { fixes, .. } => {
            fixes.clone()
        }
        _ => Vec::new(),
    }
}

#[test]
fn engine_errors_name_typed_fixes_that_scripts_show_as_script_lines() {
    let mut s = Scene::new();
    let e = s.period().unwrap_err();
    assert_eq!(fixes(&e), vec![Setting::AddSwimmer]);
    assert!(engine_message(&e).contains("s.add(dumbbell(#{}))"));

    s.add(
        Dumbbell::default(),
        nalgebra::Vector3::zeros(),
        nalgebra::Vector3::x(),
    )
    .unwrap();
    s.set_model(Model::Averaged);
    let e = s.tension(0).unwrap_err();
    let no_tension = e.clone();
    assert_eq!(
        fixes(&e),
        vec![Setting::Model("micro"), Setting::Model("rigid")]
    );
    assert!(
        e.to_string()
            .contains("use the micro model or the rigid model"),
        "{e}"
    );
    assert!(
        engine_message(&e).contains("use s.model = \"micro\" or s.model = \"rigid\""),
        "{}",
        engine_message(&e)
    );

    s.set_model(Model::Rigid);
    s.set_temperature(300.0).unwrap();
    let e = Simulation::new(s.clone()).run_periods(0.01).unwrap_err();
    assert!(fixes(&e).contains(&Setting::NoNoise));
    assert!(engine_message(&e).contains("s.temperature = 0"));
    for e in [e, no_tension] {
        assert!(!e.to_string().contains("s."), "engine words only: {e}");
    }
}

/// Every string literal in the engine's sources, by file and line.
fn engine_strings() -> Vec<(String, usize, String)> {
    let mut out = Vec::new();
    let mut stack = vec![std::path::PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/src/engine"
    ))];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap().flatten() {
            let p = entry.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == "rs") {
                let text = std::fs::read_to_string(&p).unwrap();
                for (k, line) in text.lines().enumerate() {
                    let code = line.trim_start();
                    if code.starts_with("//") {
                        continue;
                    }
                    for (i, piece) in line.split('"').enumerate() {
                        if i % 2 == 1 {
                            out.push((p.display().to_string(), k + 1, piece.to_string()));
                        }
                    }
                }
            }
        }
    }
    out
}

#[test]
fn no_engine_string_holds_script_syntax() {
    let script_like = |s: &str| {
        let b = s.as_bytes();
        // `s.name =`, `s.name(` or `#{`: a scene property, method or map literal of the scripts.
        s.contains("#{")
            || s.match_indices("s.").any(|(i, _)| {
                (i == 0 || !b[i - 1].is_ascii_alphanumeric())
                    && s[i + 2..].starts_with(|c: char| c.is_ascii_lowercase())
                    && {
                        let rest = &s[i + 2..];
                        let end = rest
                            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                            .unwrap_or(rest.len());
                        let after = rest[end..].trim_start();
                        after.starts_with("= ") || after.starts_with('(')
                    }
            })
    };
    assert!(script_like("use s.backend = \"cpu\""));
    assert!(script_like("add one with s.add(d)"));
    assert!(!script_like("the swimmers.len() and s.t"));
    let bad: Vec<String> = engine_strings()
        .into_iter()
        .filter(|(_, _, s)| script_like(s))
        .map(|(f, l, s)| format!("{f}:{l}: {s}"))
        .collect();
    assert!(
        bad.is_empty(),
        "script syntax in engine strings:\n{}",
        bad.join("\n")
    );
}
