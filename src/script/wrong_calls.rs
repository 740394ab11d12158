//! A swimlab function called with arguments none of its forms takes raises the message the error
//! renderer gives ("add_at cannot be called as add_at(Scene, Dumbbell, string); its forms: ..."),
//! as a script error whose value is that text. Left to Rhai, such a call raises Rhai's own
//! "function not found", which an uncaught error shows rewritten, but which `try { } catch (e)`
//! receives as Rhai's error map, quoting the Rust spellings of the argument types
//! (`#{"error": "ErrorFunctionNotFound", "function": "add_at (Scene, Dumbbell, &str |
//! ImmutableString | String)", ...}`).
//!
//! Each swimlab function name, and each of Rhai's own (`split`, `trim`, ...), gets for every
//! arity up to two more than its longest form a form whose parameters are all `Dynamic`. Rhai
//! tries such forms only after every form of the exact argument types (in every module, Rhai's
//! standard library included), so they answer only calls that would otherwise not be found.
//! Arities where a form already takes anything are left alone, and so are the functions Rhai
//! itself calls and treats a missing form of specially (printing, `type_of`, function pointers),
//! operators, property accessors and indexers (their errors are Rhai's, rendered by the error
//! renderer where uncaught). A name both define keeps its swimlab forms' message.

use rhai::{Dynamic, Engine, EvalAltResult, NativeCallContext, Position};
use std::any::TypeId;
use std::collections::{BTreeMap, BTreeSet};
use std::sync::OnceLock;

/// Functions that Rhai calls itself, or whose missing form it treats as an answer (printing a
/// value without `to_string`, `type_of`, function pointers and their calls, `eval`).
const RHAI_OWN: &[&str] = &[
    "to_string",
    "print",
    "debug",
    "type_of",
    "Fn",
    "call",
    "curry",
    "eval",
    "is_def_fn",
    "is_def_var",
    "is_shared",
];

/// Per function name, the arities that get the all-`Dynamic` form.
pub(super) fn arities() -> &'static BTreeMap<String, Vec<usize>> {
    static A: OnceLock<BTreeMap<String, Vec<usize>>> = OnceLock::new();
    A.get_or_init(|| {
        let core = super::signatures::core_functions();
        let swimlab = &super::signatures::vocabulary().functions;
        // A name both define: every form either has, so that none of the answering forms
        // stands where one of Rhai's takes anything.
        let mut all: BTreeMap<&String, Vec<&String>> = BTreeMap::new();
        for (name, forms) in swimlab.iter().chain(core) {
            all.entry(name).or_default().extend(forms);
        }
        let mut out = BTreeMap::new();
        for (name, forms) in all {
            let is_ident = name
                .chars()
                .next()
                .is_some_and(|c| c.is_alphabetic() || c == '_')
                && name.chars().all(|c| c.is_alphanumeric() || c == '_');
            if !is_ident || RHAI_OWN.contains(&name.as_str()) {
                continue;
            }
            let params = |form: &str| -> Vec<String> {
                let inner = form
                    .split_once('(')
                    .map_or("", |(_, rest)| rest.trim_end_matches(')'));
                if inner.trim().is_empty() {
                    Vec::new()
                } else {
                    inner.split(", ").map(str::to_string).collect()
                }
            };
            let longest = forms.iter().map(|f| params(f).len()).max().unwrap_or(0);
            // A form that takes anything at an arity already answers every call of it.
            let taken: BTreeSet<usize> = forms
                .iter()
                .map(|f| params(f))
                .filter(|p| p.iter().all(|t| t == "any"))
                .map(|p| p.len())
                .collect();
            let free: Vec<usize> = (0..=longest + 2).filter(|n| !taken.contains(n)).collect();
            out.insert(name.clone(), free);
        }
        out
    })
}

/// Register the all-`Dynamic` forms on `engine` (the last registration: it reads what the others
/// registered, through [`super::signatures::vocabulary`]).
pub fn register(engine: &mut Engine) {
    for (name, counts) in arities() {
        for &n in counts {
            let called = name.clone();
            engine.register_raw_fn(
                name.as_str(),
                vec![TypeId::of::<Dynamic>(); n],
                move |ctx: NativeCallContext,
                      args: &mut [&mut Dynamic]|
                      -> Result<(), Box<EvalAltResult>> {
                    Err(EvalAltResult::ErrorRuntime(
                        message(ctx.engine(), &called, args).into(),
                        Position::NONE,
                    )
                    .into())
                },
            );
        }
    }
}

/// The renderer's message for a call of `name` with `args` that no form takes.
fn message(engine: &Engine, name: &str, args: &[&mut Dynamic]) -> String {
    let types: Vec<&str> = args
        .iter()
        .map(|a| {
            if a.is_string() {
                "string"
            } else {
                engine.map_type_name(a.type_name())
            }
        })
        .collect();
    super::types::in_words(&super::render::function_not_found(&format!(
        "{name} ({})",
        types.join(", ")
    )))
}
