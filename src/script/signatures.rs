//! What the engine has registered, read once from Rhai's metadata: the call forms of every
//! function and the properties of every type, for "did you mean" and for errors that list the
//! accepted forms of a call.

use std::collections::BTreeMap;
use std::sync::OnceLock;

/// Registered functions and properties, by name.
#[derive(Debug, Default)]
pub struct Vocabulary {
    /// Function name → its call forms, e.g. "run_periods(Scene, number)".
    pub functions: BTreeMap<String, Vec<String>>,
    /// Type name → its readable properties.
    pub getters: BTreeMap<String, Vec<String>>,
    /// Type name → its writable properties.
    pub setters: BTreeMap<String, Vec<String>>,
    /// Stdlib module name → its function names.
    pub modules: BTreeMap<String, Vec<String>>,
}

/// A Rust type name as a script user knows it.
fn script_type(t: &str) -> String {
    let t = t.trim().trim_start_matches("&mut ").trim_start_matches('&');
    if let Some(name) = super::types::script_name(t) {
        return name.to_string();
    }
    let last = t.rsplit("::").next().unwrap_or(t);
    match last {
        "i64" | "INT" => "int".into(),
        "f64" | "FLOAT" => "float".into(),
        "bool" => "bool".into(),
        "Dynamic" => "any".into(),
        "str" | "String" | "ImmutableString" => "string".into(),
        "Array" | "Vec<Dynamic>" => "array".into(),
        "Map" => "map".into(),
        "FnPtr" => "Fn".into(),
        "SceneHandle" => "Scene".into(),
        "RecorderHandle" => "Recorder".into(),
        "DumbbellSpec" => "Dumbbell".into(),
        "IntegratorSpec" => "Integrator".into(),
        other => other.to_string(),
    }
}

/// The vocabulary, read once per process by [`install`].
static VOCABULARY: OnceLock<Vocabulary> = OnceLock::new();

/// The vocabulary of [`super::engine()`] (what it registers besides the forms of
/// `wrong_calls`, which are built from this), installed by the engine builder before any
/// script runs. Before any engine is built it is empty: messages then lack suggestions, and
/// nothing panics.
pub fn vocabulary() -> &'static Vocabulary {
    static EMPTY: OnceLock<Vocabulary> = OnceLock::new();
    VOCABULARY
        .get()
        .unwrap_or_else(|| EMPTY.get_or_init(Vocabulary::default))
}

/// Reads the vocabulary from `engine`'s metadata, once per process: the engine builder hands in
/// each engine it builds, with every registration but the forms of `wrong_calls`.
pub fn install(engine: &rhai::Engine) {
    VOCABULARY.get_or_init(|| {
        let mut v = Vocabulary::default();
        let json = engine.gen_fn_metadata_to_json(false).unwrap_or_default();
        let parsed: serde_json::Value = serde_json::from_str(&json).unwrap_or_default();
        let functions = parsed["functions"].as_array().cloned().unwrap_or_default();
        for f in functions {
            let Some(name) = f["name"].as_str() else {
                continue;
            };
            let params = params_of(&f);
            if let Some(prop) = name.strip_prefix("get$") {
                let ty = params.first().cloned().unwrap_or_default();
                v.getters.entry(ty).or_default().push(prop.to_string());
            } else if let Some(prop) = name.strip_prefix("set$") {
                let ty = params.first().cloned().unwrap_or_default();
                v.setters.entry(ty).or_default().push(prop.to_string());
            } else if !name.starts_with("index$") && name != "to_debug" {
                let form = format!("{name}({})", params.join(", "));
                let forms = v.functions.entry(name.to_string()).or_default();
                if !forms.contains(&form) {
                    forms.push(form);
                }
            }
        }
        for list in v.getters.values_mut().chain(v.setters.values_mut()) {
            list.sort();
            list.dedup();
        }
        for (name, source) in super::stdlib::MODULES {
            if let Ok(ast) = engine.compile(source) {
                let mut fns: Vec<String> =
                    ast.iter_functions().map(|f| f.name.to_string()).collect();
                fns.sort();
                fns.dedup();
                v.modules.insert(name.to_string(), fns);
            }
        }
        v
    });
}

/// The parameter types of a function of Rhai's metadata, as a script user knows them.
fn params_of(f: &serde_json::Value) -> Vec<String> {
    f["params"]
        .as_array()
        .map(|ps| {
            ps.iter()
                // A parameter of no stated type takes anything.
                .map(|p| p["type"].as_str().unwrap_or("Dynamic"))
                .filter(|t| !t.contains("NativeCallContext"))
                .map(script_type)
                .collect()
        })
        .unwrap_or_default()
}

/// Rhai's own functions (its standard packages: `split`, `trim`, `push`, ...), name → call
/// forms such as "split(string, string)", read once from a plain engine's metadata: a wrong call
/// of one is answered with its forms, as a wrong call of a swimlab function is.
pub fn core_functions() -> &'static BTreeMap<String, Vec<String>> {
    static CORE: OnceLock<BTreeMap<String, Vec<String>>> = OnceLock::new();
    CORE.get_or_init(|| {
        let json = rhai::Engine::new()
            .gen_fn_metadata_to_json(true)
            .unwrap_or_default();
        let parsed: serde_json::Value = serde_json::from_str(&json).unwrap_or_default();
        let mut out: BTreeMap<String, Vec<String>> = BTreeMap::new();
        for f in parsed["functions"].as_array().into_iter().flatten() {
            let Some(name) = f["name"].as_str() else {
                continue;
            };
            if name.contains('$') || name == "to_debug" {
                continue;
            }
            let form = format!("{name}({})", params_of(f).join(", "));
            let forms = out.entry(name.to_string()).or_default();
            if !forms.contains(&form) {
                forms.push(form);
            }
        }
        // The metadata's order is a hash map's: shortest forms first, then by name.
        for forms in out.values_mut() {
            forms.sort_by_key(|f| {
                (
                    f.matches(", ").count() + usize::from(!f.ends_with("()")),
                    f.clone(),
                )
            });
        }
        out
    })
}

/// A Rhai type name in a "Function not found" signature as a script user knows it.
pub fn shown_type(t: &str) -> String {
    if t.contains("ImmutableString") || t.contains("&str") {
        return "string".into();
    }
    script_type(t)
}
