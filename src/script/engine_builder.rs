//! The one place a Rhai engine is built and scripts are run.

use super::{
    csv_api, dumbbell_api, float_cmp, integrator_api, interrupt, observable_api, plot_api,
    render_error, scene_api, stdlib, sweep_api, util_api,
};
use rhai::{Engine, Scope};

/// A Rhai engine with the whole swimlab vocabulary registered.
pub fn engine() -> Engine {
    engine_and_stdlib().0
}

/// The engine of [`engine()`] and the stdlib modules it compiled, for a caller that resolves
/// imports itself (the REPL keeps imports across inputs) without compiling them again.
pub fn engine_and_stdlib() -> (Engine, rhai::module_resolvers::StaticModuleResolver) {
    let mut engine = Engine::new();
    engine.set_max_expr_depths(256, 256);
    dumbbell_api::register(&mut engine);
    integrator_api::register(&mut engine);
    scene_api::register(&mut engine);
    observable_api::register(&mut engine);
    float_cmp::register(&mut engine);
    csv_api::register(&mut engine);
    util_api::register(&mut engine);
    sweep_api::register(&mut engine);
    plot_api::register(&mut engine);
    let embedded = stdlib::install(&mut engine);
    // Ctrl-C also stops plain script loops between statements.
    engine.on_progress(|_| interrupt::requested().then(|| "interrupted".into()));
    (engine, embedded)
}

/// Run script text; on error return the rendered message (file, line, column, caret).
pub fn run_source(name: &str, source: &str, scope: &mut Scope) -> Result<(), String> {
    interrupt::clear();
    let engine = engine();
    let ast = engine
        .compile_with_scope(scope, source)
        .map_err(|e| render_error(name, source, &e.into()))?;
    engine
        .run_ast_with_scope(scope, &ast)
        .map_err(|e| render_error(name, source, &e))
}

/// Run a script file.
pub fn run_file(path: &std::path::Path, scope: &mut Scope) -> Result<(), String> {
    let source = std::fs::read_to_string(path)
        .map_err(|e| format!("error: cannot read {}: {e}\n", path.display()))?;
    run_source(&path.display().to_string(), &source, scope)
}
