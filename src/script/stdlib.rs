//! The Rhai modules of `stdlib/`, embedded in the binary and importable by name
//! (`import "paper" as paper;`). Files are found after them, relative to the working folder.

use rhai::module_resolvers::{FileModuleResolver, ModuleResolversCollection, StaticModuleResolver};
use rhai::{Engine, Module, Scope};

/// (name, source) of every embedded module.
pub const MODULES: &[(&str, &str)] = &[
    ("paper", include_str!("../../stdlib/paper.rhai")),
    ("phases", include_str!("../../stdlib/phases.rhai")),
    ("measure", include_str!("../../stdlib/measure.rhai")),
    ("lattice", include_str!("../../stdlib/lattice.rhai")),
    ("figures", include_str!("../../stdlib/figures.rhai")),
    ("study", include_str!("../../stdlib/study.rhai")),
];

/// Compile the embedded modules with `engine`, install the resolver (embedded modules first, then
/// files), and return the compiled modules for whoever else resolves imports (the REPL session).
pub fn install(engine: &mut Engine) -> StaticModuleResolver {
    let embedded = compile(engine);
    engine.set_module_resolver(resolver(embedded.clone()));
    embedded
}

/// Embedded modules first, then files relative to the working folder.
pub fn resolver(embedded: StaticModuleResolver) -> ModuleResolversCollection {
    let mut all = ModuleResolversCollection::new();
    all.push(embedded);
    all.push(FileModuleResolver::new());
    all
}

/// The embedded modules, compiled with `engine` (cheap to clone: modules are shared).
fn compile(engine: &Engine) -> StaticModuleResolver {
    let mut embedded = StaticModuleResolver::new();
    for (name, source) in MODULES {
        // The modules are ours and compiled in tests; a broken one is reported, never a panic.
        match engine
            .compile(source)
            .map_err(|e| e.to_string())
            .and_then(|ast| {
                Module::eval_ast_as_new(Scope::new(), &ast, engine).map_err(|e| e.to_string())
            }) {
            Ok(module) => embedded.insert(*name, module),
            Err(e) => super::console::to_stderr(&format!(
                "warning: stdlib module \"{name}\" failed to load: {e}\n"
            )),
        }
    }
    embedded
}
