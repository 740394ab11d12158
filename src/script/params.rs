//! `--set NAME=VALUE` constants of `swimlab run`, and `param(name, default)`, the way a script
//! tells a value given on the command line from its own default.
//!
//! Before a script runs, its syntax tree is checked against the `--set` names: a name the script
//! never reads is an error (a typo on a cluster job line would otherwise run the default
//! silently), and so is a `let NAME = ...` or `const NAME = ...` that would shadow the value
//! without reading it (write `let NAME = param("NAME", default);` instead).

use super::doc::{doc_entry, Doc};
use rhai::{Dynamic, Engine, Position, AST};

/// The `--set` values of one run, in command-line order.
pub type Sets = [(String, Dynamic)];

/// How `swimlab run` (and `make-figures`) runs a script: its quick variant or not, and the
/// `--set` constants.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// What `quick()` returns (also true when SWIMLAB_QUICK=1 is set).
    pub quick: bool,
    /// The `--set NAME=VALUE` constants.
    pub sets: Vec<(String, Dynamic)>,
}

/// Parse `NAME=VALUE` into a Rhai constant.
pub fn parse_set(item: &str) -> Result<(String, Dynamic), String> {
    let (name, value) = item
        .split_once('=')
        .ok_or_else(|| format!("error: --set {item}: expected NAME=VALUE, such as --set D=10"))?;
    if !valid_name(name) {
        return Err(format!(
            "error: --set {item}: \"{name}\" is not a valid variable name (letters, digits, _)"
        ));
    }
    let v = if let Ok(i) = value.parse::<i64>() {
        Dynamic::from_int(i)
    } else if let Ok(f) = value.parse::<f64>() {
        Dynamic::from_float(f)
    } else if let Ok(b) = value.parse::<bool>() {
        Dynamic::from_bool(b)
    } else {
        Dynamic::from(value.to_string())
    };
    Ok((name.to_string(), v))
}

/// Whether `name` can be a `--set` name: a variable name (a letter or _, then letters, digits, _).
fn valid_name(name: &str) -> bool {
    name.chars()
        .next()
        .is_some_and(|c| c.is_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_alphanumeric() || c == '_')
}

/// Register `param(name, default)`: the `--set` value of `name` if one was given, else `default`.
/// A name that no `--set` can give (empty, or not a variable name) is refused: the script would
/// always run its default.
pub fn register(engine: &mut Engine, sets: &Sets) {
    let sets: Vec<(String, Dynamic)> = sets.to_vec();
    engine.register_fn(
        "param",
        move |name: &str, default: Dynamic| -> super::ScriptResult<Dynamic> {
            if !valid_name(name) {
                return Err(super::script_error(format!(
                    "param(\"{name}\", ...): the name must be a variable name (a letter or _, then letters, digits, _), as --set NAME=VALUE gives it, such as param(\"D\", 10.0)"
                )));
            }
            Ok(sets
                .iter()
                .find(|(n, _)| n == name)
                .map_or(default, |(_, v)| v.clone()))
        },
    );
}

/// Register `param(name, default)` without any `--set` values (the shell, `-e`, tests).
pub fn register_defaults(engine: &mut Engine) {
    register(engine, &[]);
}

/// How a name appears in the script.
#[derive(Default)]
struct Uses {
    /// Read as a variable or through `param("name", ...)`.
    read: bool,
    /// The first top-level declaration that hides the name without reading it.
    shadow: Option<Position>,
}

/// Check the script against the `--set` names: each given once, every one read, none shadowed.
pub fn check(ast: &AST, sets: &Sets) -> Result<(), (Position, String)> {
    use rhai::{ASTNode, Expr, Stmt};
    for (k, (name, value)) in sets.iter().enumerate() {
        if let Some((_, first)) = sets[..k].iter().find(|(n, _)| n == name) {
            return Err((
                Position::NONE,
                format!(
                    "--set {name} is given twice ({name}={first} and {name}={value}); give each name once"
                ),
            ));
        }
    }
    let names: Vec<&str> = sets.iter().map(|(n, _)| n.as_str()).collect();
    let param_name = |f: &rhai::FnCallExpr| -> Option<String> {
        if f.name != "param" || !f.namespace.is_empty() {
            return None;
        }
        match f.args.first() {
            Some(Expr::StringConstant(s, ..)) => Some(s.to_string()),
            _ => None,
        }
    };
    let reads = |node: &ASTNode| -> Option<String> {
        match node {
            ASTNode::Expr(Expr::Variable(x, ..)) if x.2.is_empty() => Some(x.1.to_string()),
            ASTNode::Expr(Expr::FnCall(f, ..)) => param_name(f),
            // A call that ends a block (an if branch, a function body) is a statement.
            ASTNode::Stmt(Stmt::FnCall(f, ..)) => param_name(f),
            _ => None,
        }
    };
    let mut uses: Vec<Uses> = names.iter().map(|_| Uses::default()).collect();
    let mut all_reads: Vec<String> = Vec::new();
    // Reads anywhere, closures and functions included.
    ast.walk(&mut |path: &[ASTNode]| {
        if let Some(name) = path.last().and_then(reads) {
            if let Some(k) = names.iter().position(|n| *n == name) {
                uses[k].read = true;
            }
            all_reads.push(name);
        }
        true
    });
    // Declarations in the script's own statements (a `let` inside a function is local to it).
    let mut declared: Vec<(usize, Position, bool)> = Vec::new();
    for stmt in ast.statements() {
        let mut path = Vec::new();
        stmt.walk(&mut path, &mut |path: &[ASTNode]| {
            match path.last() {
                Some(ASTNode::Stmt(Stmt::Var(x, _, pos))) => {
                    if let Some(k) = names.iter().position(|n| *n == x.0.name.as_str()) {
                        declared.push((k, *pos, false));
                    }
                }
                Some(node) => {
                    if let Some(name) = reads(node) {
                        // A read inside the declaration of the same name takes the --set value.
                        let inside_own = path[..path.len() - 1].iter().any(
                            |a| matches!(a, ASTNode::Stmt(Stmt::Var(x, ..)) if x.0.name == name),
                        );
                        if inside_own {
                            if let Some(d) =
                                declared.iter_mut().rev().find(|(k, ..)| names[*k] == name)
                            {
                                d.2 = true;
                            }
                        }
                    }
                }
                None => {}
            }
            true
        });
    }
    for (k, pos, reads_itself) in declared {
        if !reads_itself {
            uses[k].shadow.get_or_insert(pos);
        }
    }
    for (k, u) in uses.iter().enumerate() {
        let (name, value) = (&sets[k].0, &sets[k].1);
        if let Some(pos) = u.shadow {
            return Err((
                pos,
                format!(
                    "this declaration of {name} hides the value given by --set {name}={value}; to let --set choose and keep a default, write let {name} = param(\"{name}\", <default>);"
                ),
            ));
        }
        if !u.read {
            let mut known: Vec<&str> = all_reads.iter().map(String::as_str).collect();
            known.sort_unstable();
            known.dedup();
            let hint = super::convert::suggest(name, &known)
                .map(|s| format!(" (did you mean --set {s}=...?)"))
                .unwrap_or_default();
            return Err((
                Position::NONE,
                format!(
                    "--set {name}={value}: the script never reads {name}{hint}; give only names the script uses, as a variable or through param(\"{name}\", default)"
                ),
            ));
        }
    }
    Ok(())
}

/// The help text of this file's script names (`:help NAME`), gathered by [`super::docs`].
pub(super) const DOCS: &[Doc] = &[
    doc_entry!("param", "running", "param(name, default) -> value", "The value given by swimlab run --set name=VALUE, or default without one: let D = param(\"D\", 10.0); lets a cluster job choose D. A --set name the script never reads, or hides with its own let, is an error, and so is a name no --set can give (empty, or not a variable name).", "let D = param(\"D\", 10.0); print(D);"),
];
