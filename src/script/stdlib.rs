//! The Rhai modules of `stdlib/`, embedded in the binary and importable by name
//! (`import "paper" as paper;`). Files are found after them, relative to the working folder.

use rhai::module_resolvers::{FileModuleResolver, ModuleResolversCollection, StaticModuleResolver};
use rhai::{Engine, Module, Scope};

/// (name, source) of every embedded module.
pub const MODULES: &[(&str, &str)] = &[
    ("paper", include_str!("../../stdlib/paper.rhai")),
    ("phases", include_str!("../../stdlib/phases.rhai")),
    ("measure", include_str!("../../stdlib/measure.rhai")),
];

/// Install the resolver: the embedded modules first, then files.
pub fn install(engine: &mut Engine) {
    let resolver = resolver(engine);
    engine.set_module_resolver(resolver);
}

/// The resolver `install` sets: embedded modules (compiled with `engine`) first, then files.
pub fn resolver(engine: &Engine) -> ModuleResolversCollection {
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
            Err(e) => eprintln!("warning: stdlib module \"{name}\" failed to load: {e}"),
        }
    }
    let mut all = ModuleResolversCollection::new();
    all.push(embedded);
    all.push(FileModuleResolver::new());
    all
}
