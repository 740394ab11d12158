//! The REPL's state and logic below the terminal: inputs in, text out. Variables and functions
//! defined on earlier inputs stay; the value of an expression is shown; `:commands` are handled
//! here. The terminal front ends (`super::terminal`) only read lines and print replies.

use super::view_command;
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
    pub(super) engine: Engine,
    /// The same module resolution the engine does, for keeping imports (see `keep_imports`).
    resolver: rhai::module_resolvers::ModuleResolversCollection,
    pub(super) scope: Scope<'static>,
    functions: AST,
    inputs: usize,
    /// The inputs handled so far (`:history`).
    history: Vec<String>,
    /// Completion's registered names, made on first use.
    pub(super) names: std::sync::OnceLock<Vec<String>>,
    /// The registered methods and properties of each script type, made on first use.
    pub(super) methods: std::sync::OnceLock<std::collections::HashMap<String, Vec<String>>>,
}

/// A wall time in words: µs, ms or s to a thousandth, minutes and seconds from a minute on.
fn duration_in_words(seconds: f64) -> String {
    if seconds < 1e-3 {
        format!("{:.3} µs", seconds * 1e6)
    } else if seconds < 1.0 {
        format!("{:.3} ms", seconds * 1e3)
    } else if seconds < 60.0 {
        format!("{seconds:.3} s")
    } else {
        let m = (seconds / 60.0).floor();
        format!("{m:.0} min {:.1} s", seconds - 60.0 * m)
    }
}

impl Default for Session {
    fn default() -> Self {
        Self::new()
    }
}

/// The shell's `:commands` and what each does (`:help` lists them; so does the book's reference).
pub(super) const COMMANDS: &[(&str, &str)] = &[
    (
        ":help",
        "list everything; :help NAME shows one name with an example",
    ),
    (
        ":load FILE",
        "run a script file in this session (its variables and functions stay)",
    ),
    (":vars", "list the variables in scope"),
    (
        ":time CODE",
        "run CODE and say how long it took (and the steps and right-hand sides of each scene that ran)",
    ),
    (
        ":history [N]",
        "list this session's inputs (the last N)",
    ),
    (
        ":view",
        "open the latest live view (s.view()) in the default browser, or print its address where none opens",
    ),
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
            history: Vec::new(),
            names: std::sync::OnceLock::new(),
            methods: std::sync::OnceLock::new(),
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
        if !t.starts_with(":history") {
            self.history.push(t.to_string());
        }
        if let Some(cmd) = t.strip_prefix(':') {
            return self.command(cmd);
        }
        let name = self.next_name();
        self.eval(&name, input)
    }

    /// Run one input of code (not a `:command`): its value, `None` when there is none to show
    /// (unit, or a trailing `;`), or the rendered error.
    pub fn execute(&mut self, input: &str) -> Result<Option<Dynamic>, String> {
        let name = self.next_name();
        self.value_of(&name, input)
    }

    fn next_name(&mut self) -> String {
        self.inputs += 1;
        format!("<input {}>", self.inputs)
    }

    fn eval(&mut self, name: &str, source: &str) -> Reply {
        match self.value_of(name, source) {
            Ok(Some(v)) => Reply::Output(format!("=> {}", show(&v))),
            Ok(None) => Reply::Output(String::new()),
            Err(e) => Reply::Error(e),
        }
    }

    fn value_of(&mut self, name: &str, source: &str) -> Result<Option<Dynamic>, String> {
        let source = script::strip_bom(source);
        // A panic (a bug) becomes an error reply; the session, its scope and scenes stay.
        let guarded = script::guard(name, || Ok(self.eval_unguarded(name, source)));
        guarded.unwrap_or_else(Err)
    }

    fn eval_unguarded(&mut self, name: &str, source: &str) -> Result<Option<Dynamic>, String> {
        interrupt::clear();
        let ast = match self.engine.compile_with_scope(&self.scope, source) {
            Ok(a) => a,
            Err(e) => return Err(render_error(name, source, &e.into())),
        };
        let merged = self.functions.merge(&ast);
        let replaced = self.set_aside_replaced(&ast);
        let result = self
            .engine
            .eval_ast_with_scope::<Dynamic>(&mut self.scope, &merged);
        self.settle_replaced(replaced);
        // Keep the functions even when the statements failed: they were defined.
        self.functions = merged;
        self.functions.clear_statements();
        self.drop_shadowed();
        if result.is_ok() {
            self.keep_imports(source);
        }
        // As in Julia, `ans` is the last value an input gave, shown or not.
        if let Ok(v) = &result {
            if !v.is_unit() {
                self.set_ans(v.clone());
            }
        }
        // As in IPython and Julia, a trailing `;` means "don't show the value".
        let quiet = source.trim_end().ends_with(';');
        match result {
            Ok(v) if v.is_unit() || quiet => Ok(None),
            Ok(v) => Ok(Some(v)),
            Err(e) => Err(render_error(name, source, &e)),
        }
    }

    /// `ans` set to `v`, unless the user made `ans` a constant.
    fn set_ans(&mut self, v: Dynamic) {
        if self.scope.is_constant("ans") == Some(true) {
            return;
        }
        let _ = self.scope.remove::<Dynamic>("ans");
        self.scope.push_dynamic("ans", v);
    }

    /// Each scene in scope by name, with its steps and right-hand sides so far.
    fn scene_stats(&self) -> Vec<(String, (u64, u64))> {
        self.scope
            .iter_raw()
            .filter_map(|(name, _, value)| {
                let h = value.read_lock::<script::SceneHandle>()?;
                let stats = h.borrow().scene().stats();
                Some((name.to_string(), (stats.steps, stats.rhs_evals)))
            })
            .collect()
    }

    /// `:time CODE`: the reply to CODE, then its wall time and what each scene that ran took.
    fn timed(&mut self, code: &str) -> Reply {
        let before = self.scene_stats();
        let start = std::time::Instant::now();
        let name = self.next_name();
        let reply = self.eval(&name, code);
        let elapsed = start.elapsed().as_secs_f64();
        let mut lines = vec![format!("time: {}", duration_in_words(elapsed))];
        for (scene, after) in self.scene_stats() {
            let Some((_, b)) = before.iter().find(|(n, _)| *n == scene) else {
                continue;
            };
            let (steps, rhs) = (after.0.saturating_sub(b.0), after.1.saturating_sub(b.1));
            if steps > 0 || rhs > 0 {
                lines.push(format!("{scene}: {steps} steps, {rhs} right-hand sides"));
            }
        }
        let timing = lines.join("\n");
        match reply {
            Reply::Output(o) if o.is_empty() => Reply::Output(timing),
            Reply::Output(o) => Reply::Output(format!("{o}\n{timing}")),
            Reply::Error(e) => Reply::Error(format!("{e}\n{timing}")),
            Reply::Quit => Reply::Quit,
        }
    }

    /// `:history [N]`: this session's inputs, numbered, the last `n` of them (all when `None`).
    fn history_listing(&self, n: Option<usize>) -> String {
        if self.history.is_empty() {
            return "(no inputs yet)".into();
        }
        let from = n.map_or(0, |n| self.history.len().saturating_sub(n));
        self.history[from..]
            .iter()
            .enumerate()
            .map(|(k, input)| {
                let mut lines = input.lines();
                let first = format!("{:>4}  {}", from + k + 1, lines.next().unwrap_or(""));
                std::iter::once(first)
                    .chain(lines.map(|l| format!("      {l}")))
                    .collect::<Vec<_>>()
                    .join("\n")
            })
            .collect::<Vec<_>>()
            .join("\n")
    }

    /// The variables `ast` declares anew at its top level before anything in it mentions them (a
    /// notebook cell run again: `let s = scene(); s.trajectory("t.xyz", 1);`), taken out of the
    /// scope for the run: nothing in it could read them. A scene among them is marked as being
    /// replaced, so that a new writer may take over the files its recorders write. Each comes
    /// back with its constness.
    fn set_aside_replaced(&mut self, ast: &AST) -> Vec<(String, bool, Dynamic)> {
        let mut out = Vec::new();
        for name in declared_before_use(ast) {
            let Some(constant) = self
                .scope
                .iter_raw()
                .filter(|(n, ..)| *n == name)
                .map(|(_, c, _)| c)
                // The newest of that name: the one the input hides.
                .next()
            else {
                continue;
            };
            let Some(value) = self.scope.remove::<Dynamic>(&name) else {
                continue;
            };
            if let Some(h) = value.read_lock::<script::SceneHandle>() {
                h.borrow().set_retiring(true);
            }
            out.push((name, constant, value));
        }
        out
    }

    /// After the run: a variable set aside and declared anew is dropped; one the run did not get
    /// to declare (it failed first) comes back as it was.
    fn settle_replaced(&mut self, replaced: Vec<(String, bool, Dynamic)>) {
        for (name, constant, value) in replaced {
            if self.scope.contains(&name) {
                continue;
            }
            if let Some(h) = value.read_lock::<script::SceneHandle>() {
                h.borrow().set_retiring(false);
            }
            if constant {
                self.scope.push_constant_dynamic(name, value);
            } else {
                self.scope.push_dynamic(name, value);
            }
        }
    }

    /// Drop the variables a later `let` of the same name hid: nothing reaches them by name any
    /// more, and a scene among them would keep its memory, and its recorders the files they
    /// write.
    fn drop_shadowed(&mut self) {
        // Oldest first (the scope iterates from the newest).
        let mut entries: Vec<(String, bool, Dynamic)> = self
            .scope
            .iter_raw()
            .map(|(n, c, v)| (n.to_string(), c, v.clone()))
            .collect();
        entries.reverse();
        let last = |k: usize| !entries[k + 1..].iter().any(|(n, ..)| *n == entries[k].0);
        if (0..entries.len()).all(last) {
            return;
        }
        let kept: Vec<usize> = (0..entries.len()).filter(|&k| last(k)).collect();
        self.scope.clear();
        for k in kept {
            let (name, constant, value) = entries[k].clone();
            if constant {
                self.scope.push_constant_dynamic(name, value);
            } else {
                self.scope.push_dynamic(name, value);
            }
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
            "help" | "h" => match Session::help(arg) {
                Some(text) => Reply::Output(text),
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
            "time" if arg.is_empty() => {
                Reply::Error(":time needs code to run: :time s.run_periods(100)".into())
            }
            "time" => self.timed(arg),
            "history" => match arg {
                "" => Reply::Output(self.history_listing(None)),
                n => match n.parse::<usize>() {
                    Ok(n) => Reply::Output(self.history_listing(Some(n))),
                    Err(_) => Reply::Error(format!(
                        ":history takes a count of inputs, got \"{n}\": :history 10"
                    )),
                },
            },
            "view" => match view_command::open_latest() {
                Ok(text) => Reply::Output(text),
                Err(e) => Reply::Error(e),
            },
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

    /// The engine (for the front end's validator).
    pub fn engine(&self) -> &Engine {
        &self.engine
    }

    /// Send what `print` prints to `sink` instead of standard output (a notebook's stream).
    pub fn on_print(&mut self, sink: impl Fn(&str) + Send + Sync + 'static) {
        self.engine.on_print(sink);
    }

    /// The help of `name` (what `:help NAME` shows), if it is documented.
    pub fn help(name: &str) -> Option<String> {
        docs::lookup(name).map(|d| {
            format!(
                "{}\n\n  {}\n\nexample:\n  {}",
                d.signature, d.about, d.example
            )
        })
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

/// The names `ast` declares with a top-level `let` or `const` before any statement mentions them
/// (a read anywhere in an earlier statement, closures included, or in the declaration's own
/// value).
fn declared_before_use(ast: &AST) -> Vec<String> {
    use rhai::{ASTNode, Expr, Stmt};
    let mut mentioned: Vec<String> = Vec::new();
    let mut out = Vec::new();
    for stmt in ast.statements() {
        let mut reads = Vec::new();
        let mut path = Vec::new();
        stmt.walk(&mut path, &mut |p: &[ASTNode]| {
            match p.last() {
                Some(ASTNode::Expr(Expr::Variable(x, ..))) => reads.push(x.1.to_string()),
                // Variables a closure captures.
                Some(ASTNode::Stmt(Stmt::Share(x))) => {
                    reads.extend(x.iter().map(|(v, _)| v.name.to_string()))
                }
                _ => {}
            }
            true
        });
        if let Stmt::Var(x, ..) = stmt {
            let name = x.0.name.to_string();
            if !mentioned.contains(&name) && !reads.contains(&name) && !out.contains(&name) {
                out.push(name.clone());
            }
            mentioned.push(name);
        }
        mentioned.extend(reads);
    }
    out
}
