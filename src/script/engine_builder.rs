//! The one place a Rhai engine is built and scripts are run.

use super::{
    continuum_api, csv_api, dumbbell_api, field_api, float_cmp, integrator_api, interrupt, limits,
    observable_api, panic_guard::guard, params, picture_api, plot_api, render_error, scene_api,
    scene_settings_api, stdlib, sweep_api, types, util_api, wall_api, wrong_calls,
};
use rhai::{Dynamic, Engine, EvalAltResult, Scope};

/// The largest script or scene file swimlab reads (bytes): far above any real one, and a bound
/// on what a wrong path (a device, a huge data file) can cost.
pub const MAX_SOURCE_BYTES: u64 = 16 << 20;

/// A Rhai engine with the whole swimlab vocabulary registered.
pub fn engine() -> Engine {
    engine_and_stdlib().0
}

/// The engine of [`engine()`] and the stdlib modules it compiled, for a caller that resolves
/// imports itself (the REPL keeps imports across inputs) without compiling them again.
pub fn engine_and_stdlib() -> (Engine, rhai::module_resolvers::StaticModuleResolver) {
    let (mut engine, embedded) = vocabulary_engine();
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
    scene_settings_api::register(&mut engine);
    wall_api::register(&mut engine);
    observable_api::register(&mut engine);
    float_cmp::register(&mut engine);
    csv_api::register(&mut engine);
    util_api::register(&mut engine);
    sweep_api::register(&mut engine);
    plot_api::register(&mut engine);
    picture_api::register(&mut engine);
    field_api::register(&mut engine);
    continuum_api::register(&mut engine);
    params::register_defaults(&mut engine);
    let embedded = stdlib::install(&mut engine);
    // `print` as every other text a script writes: a closed standard output ends the process
    // quietly (Rhai's own `println!` would panic).
    engine.on_print(|s| super::console::to_stdout(&format!("{s}\n")));
    // Ctrl-C also stops plain script loops between statements.
    engine.on_progress(|_| interrupt::requested().then(|| "interrupted".into()));
    (engine, embedded)
}

/// Script text without a leading UTF-8 byte-order mark (editors on Windows write one).
pub fn strip_bom(source: &str) -> &str {
    source.strip_prefix('\u{feff}').unwrap_or(source)
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

/// Read a text file of at most `max` bytes, with errors that name the file and the fix.
pub fn read_text(path: &std::path::Path, max: u64, what: &str) -> Result<String, String> {
    use std::io::Read;
    let shown = path.display();
    let too_big = || {
        format!(
            "cannot read {what} {shown}: it is larger than {max} bytes, more than any {what} swimlab writes; check the path"
        )
    };
    let file = std::fs::File::open(path).map_err(|e| {
        format!("cannot read {what} {shown}: {e}; check the path (relative paths start in the working folder)")
    })?;
    if let Ok(m) = file.metadata() {
        if m.is_dir() {
            return Err(format!(
                "cannot read {what} {shown}: it is a folder; give a file"
            ));
        }
        // A regular file is measured before reading; a device or pipe by reading at most max + 1.
        if m.is_file() && m.len() > max {
            return Err(too_big());
        }
    }
    let mut bytes = Vec::new();
    file.take(max + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read {what} {shown}: {e}"))?;
    if bytes.len() as u64 > max {
        return Err(too_big());
    }
    String::from_utf8(bytes).map_err(|e| {
        format!("cannot read {what} {shown}: it is not UTF-8 text ({e}); save it as UTF-8")
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
