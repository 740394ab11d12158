//! The REPL's state and logic below the terminal: inputs in, text out. Variables and functions
//! defined on earlier inputs stay; the value of an expression is shown; `:commands` are handled
//! here. The terminal front ends (`super::terminal`) only read lines and print replies.

use crate::script::{self, docs, interrupt, render_error, show};
use rhai::{Dynamic, Engine, ParseErrorType, Scope, AST};

/// What the front end should do after an input.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Reply {
    /// Print this (may be empty) and prompt again.
    Output(String),
    /// Print this (an error, already rendered) and prompt again.
    Error(String),
    /// End the session.
    Quit,
}

/// An interactive session: engine, variables, and the functions defined so far.
pub struct Session {
    engine: Engine,
    /// The same module resolution the engine does, for keeping imports (see `keep_imports`).
    resolver: rhai::module_resolvers::ModuleResolversCollection,
    scope: Scope<'static>,
    functions: AST,
    inputs: usize,
}

impl Default for Session {
    fn default() -> Self {
        Self::new()
    }
}

const COMMANDS: &[(&str, &str)] = &[
    (
        ":help",
        "list everything; :help NAME shows one name with an example",
    ),
    (
        ":load FILE",
        "run a script file in this session (its variables and functions stay)",
    ),
    (":vars", "list the variables in scope"),
    (":clear", "forget all variables and functions"),
    (":quit", "leave (Ctrl-D does too)"),
];

impl Session {
    /// A fresh session.
    pub fn new() -> Self {
        let (engine, embedded) = script::engine_and_stdlib();
        Session {
            resolver: script::stdlib::resolver(embedded),
            engine,
            scope: Scope::new(),
            functions: AST::empty(),
            inputs: 0,
        }
    }

    /// Whether `input` is a complete statement sequence (a `:command`, or code that parses), as
    /// opposed to one the user is still typing (an unclosed block, bracket or trailing operator).
    /// Code with a real syntax error counts as complete, so the error is shown.
    pub fn is_complete(&self, input: &str) -> bool {
        let t = input.trim();
        if t.is_empty() || t.starts_with(':') {
            return true;
        }
        match self.engine.compile_with_scope(&self.scope, input) {
            Ok(_) => true,
            Err(err) => !incomplete(input, &err.0, err.1),
        }
    }

    /// Handle one complete input.
    pub fn handle(&mut self, input: &str) -> Reply {
        let t = input.trim();
        if t.is_empty() {
            return Reply::Output(String::new());
        }
        if let Some(cmd) = t.strip_prefix(':') {
            return self.command(cmd);
        }
        self.inputs += 1;
        let name = format!("<input {}>", self.inputs);
        self.eval(&name, input)
    }

    fn eval(&mut self, name: &str, source: &str) -> Reply {
        let source = script::strip_bom(source);
        // A panic (a bug) becomes an error reply; the session, its scope and scenes stay.
        let guarded = script::guard(name, || Ok(self.eval_unguarded(name, source)));
        guarded.unwrap_or_else(Reply::Error)
    }

    fn eval_unguarded(&mut self, name: &str, source: &str) -> Reply {
        interrupt::clear();
        let ast = match self.engine.compile_with_scope(&self.scope, source) {
            Ok(a) => a,
            Err(e) => return Reply::Error(render_error(name, source, &e.into())),
        };
        let merged = self.functions.merge(&ast);
        let result = self
            .engine
            .eval_ast_with_scope::<Dynamic>(&mut self.scope, &merged);
        // Keep the functions even when the statements failed: they were defined.
        self.functions = merged;
        self.functions.clear_statements();
        if result.is_ok() {
            self.keep_imports(source);
        }
        // As in IPython and Julia, a trailing `;` means "don't show the value".
        let quiet = source.trim_end().ends_with(';');
        match result {
            Ok(v) if v.is_unit() || quiet => Reply::Output(String::new()),
            Ok(v) => Reply::Output(format!("=> {}", show(&v))),
            Err(e) => Reply::Error(render_error(name, source, &e)),
        }
    }

    fn command(&mut self, cmd: &str) -> Reply {
        let (word, arg) = match cmd.split_once(char::is_whitespace) {
            Some((w, a)) => (w, a.trim()),
            None => (cmd, ""),
        };
        match word {
            "quit" | "q" | "exit" => Reply::Quit,
            "help" | "h" if arg.is_empty() => Reply::Output(help_overview()),
            "help" | "h" => match docs::lookup(arg) {
                Some(d) => Reply::Output(format!(
                    "{}\n\n  {}\n\nexample:\n  {}",
                    d.signature, d.about, d.example
                )),
                None => Reply::Error(format!(
                    "no help for \"{arg}\"{}; :help lists every name",
                    script::suggest_name(arg)
                        .map(|s| format!(" (did you mean \"{s}\"?)"))
                        .unwrap_or_default()
                )),
            },
            "vars" => {
                let mut out = Vec::new();
                for (name, constant, value) in self.scope.iter_raw() {
                    let kind = if constant { "const" } else { "let" };
                    let ty = self.engine.map_type_name(value.type_name());
                    out.push(format!("{kind} {name}: {ty} = {}", show(value)));
                }
                if out.is_empty() {
                    out.push("(no variables)".into());
                }
                Reply::Output(out.join("\n"))
            }
            "clear" => {
                self.scope.clear();
                self.functions = AST::empty();
                Reply::Output("cleared all variables and functions".into())
            }
            "load" if arg.is_empty() => {
                Reply::Error(":load needs a file: :load scripts/pair.rhai".into())
            }
            "load" => match script::read_text(
                std::path::Path::new(arg),
                script::MAX_SOURCE_BYTES,
                "script",
            ) {
                Ok(src) => self.eval(arg, &src),
                Err(e) => Reply::Error(format!("error: {e}")),
            },
            other => Reply::Error(format!(
                "unknown command :{other}; commands: {}",
                COMMANDS
                    .iter()
                    .map(|(c, _)| *c)
                    .collect::<Vec<_>>()
                    .join(", ")
            )),
        }
    }

    /// Rhai forgets `import "x" as y;` after the evaluation it appears in; a session keeps it by
    /// registering the resolved module under its alias on the session's engine.
    fn keep_imports(&mut self, source: &str) {
        for stmt in source.split(';') {
            let words: Vec<&str> = stmt.split_whitespace().collect();
            if let ["import", path, "as", alias] = words.as_slice() {
                let path = path.trim_matches('"');
                let resolved = rhai::ModuleResolver::resolve(
                    &self.resolver,
                    &self.engine,
                    None,
                    path,
                    rhai::Position::NONE,
                );
                if let Ok(module) = resolved {
                    self.engine.register_static_module(*alias, module);
                }
            }
        }
    }

    /// Names of the variables in scope (for completion).
    pub fn variables(&self) -> Vec<String> {
        self.scope
            .iter_raw()
            .map(|(n, _, _)| n.to_string())
            .collect()
    }

    /// Names of functions the user defined (for completion).
    pub fn user_functions(&self) -> Vec<String> {
        self.functions
            .iter_functions()
            .map(|f| f.name.to_string())
            .collect()
    }

    /// The engine (for the front end's validator and completer).
    pub fn engine(&self) -> &Engine {
        &self.engine
    }
}

/// A parse error that only says "the input stopped too early".
fn incomplete(input: &str, err: &ParseErrorType, pos: rhai::Position) -> bool {
    match err {
        ParseErrorType::UnexpectedEOF => true,
        ParseErrorType::MissingToken(..) | ParseErrorType::MissingSymbol(..) => {
            let lines: Vec<&str> = input.lines().collect();
            let last = lines.len().max(1);
            match (pos.line(), pos.position()) {
                (Some(l), Some(c)) => {
                    l > last || (l == last && c > lines.last().map_or(0, |s| s.trim_end().len()))
                }
                _ => true,
            }
        }
        _ => false,
    }
}

fn help_overview() -> String {
    let mut out = String::from("swimlab: scenes of dumbbell swimmers. :help NAME for one name.\n");
    let mut groups: Vec<&str> = Vec::new();
    for d in docs::DOCS.iter() {
        if !groups.contains(&d.group) {
            groups.push(d.group);
        }
    }
    for g in groups {
        let names: Vec<&str> = docs::DOCS
            .iter()
            .filter(|d| d.group == g)
            .map(|d| d.name)
            .collect();
        out.push_str(&format!("\n{g:>12}: {}", names.join(", ")));
    }
    out.push_str("\n\ncommands:");
    for (c, what) in COMMANDS {
        out.push_str(&format!("\n  {c:<12} {what}"));
    }
    out.push_str("\n\nCtrl-C stops a running simulation (the scene is kept); Ctrl-D leaves.");
    out
}
