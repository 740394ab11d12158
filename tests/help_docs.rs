//! Docs that are run cannot rot: every `:help` example runs, and every function a script can call
//! has a help entry.

use rhai::Scope;
use swimlab::script::{docs::DOCS, engine, run_source};

#[test]
fn every_help_example_runs() {
    for d in DOCS.iter() {
        run_source(&format!(":help {}", d.name), d.example, &mut Scope::new())
            .unwrap_or_else(|e| panic!("example of {} fails:\n{e}", d.name));
    }
}

#[test]
fn every_registered_name_has_help() {
    // Conversion and display hooks Rhai calls itself are not user vocabulary.
    let internal = ["to_string", "to_debug"];
    // Rhai's own functions (`split`, `trim`) get forms that answer a wrong call with their call
    // forms; those forms (untyped parameters, `_`) are Rhai's vocabulary, not swimlab's.
    let rhai_names: Vec<String> = rhai::Engine::new()
        .gen_fn_signatures(true)
        .iter()
        .map(|sig| sig.split('(').next().unwrap().trim().to_string())
        .collect();
    let mut missing = Vec::new();
    for sig in engine().gen_fn_signatures(false) {
        let name = sig.split('(').next().unwrap();
        let params = sig
            .split_once('(')
            .map_or("", |(_, rest)| rest.split(')').next().unwrap_or(""));
        let answering = params.split(", ").all(|p| p.is_empty() || p == "_");
        if answering && rhai_names.iter().any(|n| n == name) {
            continue;
        }
        let name = name.trim_start_matches("get$").trim_start_matches("set$");
        let is_ident = name
            .chars()
            .next()
            .is_some_and(|c| c.is_alphabetic() || c == '_');
        if is_ident && !internal.contains(&name) && !DOCS.iter().any(|d| d.name == name) {
            missing.push(name.to_string());
        }
    }
    missing.sort();
    missing.dedup();
    assert!(missing.is_empty(), "no :help entry for {missing:?}");
}

/// Each choice is defined once (engine::choice): its `:help` entry lists exactly those names.
#[test]
fn help_lists_every_choice_as_the_engine_defines_it() {
    use swimlab::engine::choice::{names, Named};
    use swimlab::engine::{Backend, Coefficients, Mobility, Model, Overlaps};
    fn check<T: Named>(property: &str) {
        let d = DOCS.iter().find(|d| d.name == property).unwrap();
        let shown = names::<T>()
            .iter()
            .map(|n| format!("\"{n}\""))
            .collect::<Vec<_>>()
            .join(" | ");
        assert!(
            d.signature.contains(&format!("s.{property} = {shown}")),
            ":help {property} should list {shown}: {}",
            d.signature
        );
    }
    check::<Model>("model");
    check::<Mobility>("mobility");
    check::<Backend>("backend");
    check::<Coefficients>("coefficients");
    check::<Overlaps>("overlaps");
    check::<swimlab::engine::thermal::NoiseRoot>("noise_root");
    check::<swimlab::engine::ewald::EwaldMethod>("ewald_method");
}
