//! The one place a Rhai engine is built and scripts are run.

use super::source::{read_text, strip_bom, MAX_SOURCE_BYTES};
use super::{
    checkpoint_api, collective_api, continuum_api, csv_api, dumbbell_api, field_api, float_cmp,
    integrator_api, interrupt, limits, observable_api, panic_guard::guard, params, picture_api,
    plot_api, render_error, run_api, scene_api, scene_settings_api, signatures, stdlib, sweep_api,
    types, util_api, view_api, wall_api, wrong_calls,
};
use rhai::{Dynamic, Engine, EvalAltResult, Scope};

/// A Rhai engine with the whole swimlab vocabulary registered.
pub fn engine() -> Engine {
    engine_and_stdlib().0
}

/// The engine of [`engine()`] and the stdlib modules it compiled, for a caller that resolves
/// imports itself (the REPL keeps imports across inputs) without compiling them again.
pub fn engine_and_stdlib() -> (Engine, rhai::module_resolvers::StaticModuleResolver) {
    let (mut engine, embedded) = vocabulary_engine();
    signatures::install(&engine);
    wrong_calls::register(&mut engine);
    (engine, embedded)
}

/// The engine of [`engine()`] without the forms that answer calls no registered form takes
/// (`wrong_calls`): its metadata is the vocabulary those forms, `:help` and the error messages
/// are built from.
pub(super) fn vocabulary_engine() -> (Engine, rhai::module_resolvers::StaticModuleResolver) {
    let mut engine = Engine::new();
    engine.set_max_expr_depths(256, 256);
    limits::apply(&mut engine);
    types::register(&mut engine);
    super::convert::install_describe(super::show::describe);
    dumbbell_api::register(&mut engine);
    integrator_api::register(&mut engine);
    scene_api::register(&mut engine);
    run_api::register(&mut engine);
    scene_settings_api::register(&mut engine);
    wall_api::register(&mut engine);
    observable_api::register(&mut engine);
    checkpoint_api::register(&mut engine);
    collective_api::register(&mut engine);
    float_cmp::register(&mut engine);
    csv_api::register(&mut engine);
    util_api::register(&mut engine);
    sweep_api::register(&mut engine);
    plot_api::register(&mut engine);
    picture_api::register(&mut engine);
    field_api::register(&mut engine);
    continuum_api::register(&mut engine);
    view_api::register(&mut engine);
    params::register_defaults(&mut engine);
    let embedded = stdlib::install(&mut engine);
    // `print` as every other text a script writes: a closed standard output ends the process
    // quietly (Rhai's own `println!` would panic).
    engine.on_print(|s| super::console::to_stdout(&format!("{s}\n")));
    // Ctrl-C also stops plain script loops between statements.
    let stop = interrupt::current();
    engine.on_progress(move |_| stop.requested().then(|| "interrupted".into()));
    (engine, embedded)
}

/// Run script text; on error return the rendered message (file, line, column, caret).
pub fn run_source(name: &str, source: &str, scope: &mut Scope) -> Result<(), String> {
    let source = strip_bom(source);
    guard(name, || {
        interrupt::clear();
        let engine = engine();
        let ast = engine
            .compile_with_scope(scope, source)
            .map_err(|e| render_error(name, source, &e.into()))?;
        engine
            .run_ast_with_scope(scope, &ast)
            .map_err(|e| render_error(name, source, &e))
    })
}

/// Run script text with [`params::RunOptions`]: `quick()` answers `options.quick`; each `--set`
/// value is a constant of the script and the value of `param(name, default)`; a name the script
/// never reads, or hides with its own `let`, is an error before anything runs.
pub fn run_source_with(
    name: &str,
    source: &str,
    options: &params::RunOptions,
) -> Result<(), String> {
    let source = strip_bom(source);
    let sets = &options.sets;
    let quick = options.quick;
    guard(name, || {
        interrupt::clear();
        let mut engine = engine();
        params::register(&mut engine, sets);
        engine.register_fn("quick", move || quick || util_api::quick());
        let mut scope = Scope::new();
        for (n, v) in sets {
            scope.push_constant_dynamic(n.clone(), v.clone());
        }
        // Compiled without the constants, so that the optimiser does not fold them into the
        // tree: the check must see every place the script reads them.
        let ast = engine
            .compile(source)
            .map_err(|e| render_error(name, source, &e.into()))?;
        params::check(&ast, sets).map_err(|(pos, msg)| {
            render_error(
                name,
                source,
                &EvalAltResult::ErrorRuntime(Dynamic::from(msg), pos),
            )
        })?;
        engine
            .run_ast_with_scope(&mut scope, &ast)
            .map_err(|e| render_error(name, source, &e))
    })
}

/// Run a script file.
pub fn run_file(path: &std::path::Path, scope: &mut Scope) -> Result<(), String> {
    let source =
        read_text(path, MAX_SOURCE_BYTES, "script").map_err(|e| format!("error: {e}\n"))?;
    run_source(&path.display().to_string(), &source, scope)
}

/// Run a script file with [`params::RunOptions`] (see [`run_source_with`]).
pub fn run_file_with(path: &std::path::Path, options: &params::RunOptions) -> Result<(), String> {
    let source =
        read_text(path, MAX_SOURCE_BYTES, "script").map_err(|e| format!("error: {e}\n"))?;
    run_source_with(&path.display().to_string(), &source, options)
}

/// Evaluate one expression (`swimlab -e`) and return its value shown as the shell shows it.
pub fn eval_expression(expr: &str) -> Result<Option<String>, String> {
    guard("-e", || {
        interrupt::clear();
        let engine = engine();
        let mut scope = Scope::new();
        let v = engine
            .eval_with_scope::<Dynamic>(&mut scope, expr)
            .map_err(|e| render_error("-e", expr, &e))?;
        Ok((!v.is_unit()).then(|| super::show(&v)))
    })
}

#[cfg(test)]
mod tests {
    /// The answering forms are added beside the registered ones, never in place of one: a
    /// registered form of the same parameter types (all `any`) would share its hash, and the
    /// later registration would replace it.
    #[test]
    fn the_answering_forms_replace_no_registered_form() {
        let (vocabulary, _) = super::vocabulary_engine();
        let full = super::engine();
        let added: usize = super::wrong_calls::arities().values().map(Vec::len).sum();
        assert!(added > 0);
        assert_eq!(
            full.gen_fn_signatures(false).len(),
            vocabulary.gen_fn_signatures(false).len() + added
        );
    }
}
