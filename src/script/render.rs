//! One error renderer for `swimlab run`, `-e` and the REPL: `file:line:col: message`, the source
//! line, and a caret under the position (tabs and wide characters kept, so the caret lines up).
//! Errors inside a stdlib module are reported at the user's call, with the module's line beneath.
//! Rhai's own messages for unknown names and mismatched calls are rewritten into ones that name
//! the fix: the closest known name, or the accepted forms of the call.

use super::convert::suggest;
use super::signatures::{core_functions, shown_type, vocabulary};
use rhai::{EvalAltResult, Position};

/// Render a script error against its source text.
pub fn render_error(name: &str, source: &str, err: &EvalAltResult) -> String {
    let mut d = describe(err);
    d.msg = super::types::in_words(&d.msg);
    let mut out = String::new();
    match d.pos.line() {
        Some(line) => {
            let col = d.pos.position().unwrap_or(1);
            out.push_str(&format!("error: {name}:{line}:{col}: {}\n", d.msg));
            out.push_str(&excerpt(source, line, col));
        }
        None => out.push_str(&format!("error: {name}: {}\n", d.msg)),
    }
    if let Some((module, pos)) = d.module {
        if let Some(line) = pos.line() {
            let col = pos.position().unwrap_or(1);
            out.push_str(&format!("  inside module \"{module}\" at {line}:{col}:\n"));
            if let Some(text) = module_source(&module) {
                out.push_str(&excerpt(&text, line, col));
            }
        }
    }
    out
}

/// The message of `err` as [`render_error`] words it, without its position (for an error quoted
/// inside another's message).
pub fn message_of(err: &EvalAltResult) -> String {
    super::types::in_words(&describe(err).msg)
}

/// The source line and a caret under column `col` (1-based, counted in characters as Rhai does).
fn excerpt(source: &str, line: usize, col: usize) -> String {
    let Some(text) = source.lines().nth(line - 1) else {
        return String::new();
    };
    let text = if line == 1 {
        text.strip_prefix('\u{feff}').unwrap_or(text)
    } else {
        text
    };
    let gutter = format!("{line:>4} | ");
    let pad: String = text
        .chars()
        .take(col.saturating_sub(1))
        .map(|c| match c {
            '\t' => "\t".to_string(),
            c => " ".repeat(unicode_width::UnicodeWidthChar::width(c).unwrap_or(0)),
        })
        .collect();
    format!("{gutter}{text}\n{}{pad}^\n", " ".repeat(gutter.len()))
}

/// The text of a module by the name Rhai gives as its source: embedded stdlib, else a file.
fn module_source(module: &str) -> Option<String> {
    super::stdlib::MODULES
        .iter()
        .find(|(n, _)| *n == module)
        .map(|(_, s)| s.to_string())
        .or_else(|| std::fs::read_to_string(module).ok())
}

/// Where an error is shown and what it says.
struct Described {
    /// Position in the user's source.
    pos: Position,
    msg: String,
    /// The innermost position inside a module, if the error happened there.
    module: Option<(String, Position)>,
}

/// The innermost position inside the script and a message without Rhai's "(line x, position y)".
fn describe(err: &EvalAltResult) -> Described {
    match err {
        EvalAltResult::ErrorInFunctionCall(f, src, inner, pos) => {
            let d = describe(inner);
            // A closure's function has a generated name ("anon$5f3c..."), which says nothing.
            let f = if f.starts_with("anon$") {
                "the closure"
            } else {
                f.as_str()
            };
            if !src.is_empty() && src != "<input>" {
                // The inner position is in the module `src`; the user's position is the call.
                let module = d.module.or_else(|| Some((src.clone(), d.pos)));
                Described {
                    pos: *pos,
                    msg: format!("in {f}: {}", d.msg),
                    module,
                }
            } else if d.pos.is_none() {
                Described {
                    pos: *pos,
                    msg: format!("in call to {f}: {}", d.msg),
                    module: d.module,
                }
            } else {
                Described {
                    pos: d.pos,
                    msg: format!("in {f}: {}", d.msg),
                    module: d.module,
                }
            }
        }
        EvalAltResult::ErrorInModule(m, inner, pos) => {
            let d = describe(inner);
            let module = d.module.or_else(|| Some((m.clone(), d.pos)));
            Described {
                pos: *pos,
                msg: format!("in module \"{m}\": {}", d.msg),
                module,
            }
        }
        EvalAltResult::ErrorRuntime(v, pos) => plain(*pos, v.to_string()),
        EvalAltResult::ErrorFunctionNotFound(sig, pos) => plain(*pos, function_not_found(sig)),
        EvalAltResult::ErrorModuleNotFound(m, pos) => plain(*pos, module_not_found(m)),
        EvalAltResult::ErrorDotExpr(msg, pos) => plain(*pos, property_not_found(msg)),
        EvalAltResult::ErrorDataRace(name, pos) => plain(*pos, data_race(name)),
        EvalAltResult::ErrorDataTooLarge(what, pos) => {
            plain(*pos, super::limits::data_too_large(what))
        }
        EvalAltResult::ErrorStackOverflow(pos) => plain(*pos, super::limits::call_depth_exceeded()),
        // The engine's statement check (Ctrl-C, a kernel's interrupt) ends the script here.
        EvalAltResult::ErrorTerminated(token, pos) if token.to_string() == "interrupted" => plain(
            *pos,
            "script interrupted at this statement (Ctrl-C); what it ran before is kept".into(),
        ),
        other => {
            let pos = other.position();
            let msg = other.to_string();
            let suffix = format!(" ({pos})");
            let msg = msg.strip_suffix(&suffix).map(str::to_string).unwrap_or(msg);
            plain(pos, msg)
        }
    }
}

fn plain(pos: Position, msg: String) -> Described {
    Described {
        pos,
        msg,
        module: None,
    }
}

/// A note when the call passed a float where every form wants an integer (an index or count).
fn integer_hint(call: &str, args: &[String], forms: &[String]) -> String {
    let wants_int = |k: usize| {
        forms.iter().all(|form| {
            form.split_once('(')
                .map(|(_, rest)| rest.trim_end_matches(')').split(", ").nth(k) == Some("int"))
                .unwrap_or(false)
        })
    };
    match args.iter().enumerate().find(|(k, a)| *a == "float" && wants_int(*k)) {
        Some((k, _)) => format!(
            "; argument {} of {call} must be an integer (an index or a count: write 10, not 10.0; to_int(x) converts)",
            k + 1
        ),
        None => String::new(),
    }
}

/// "run_period (Scene, i64)" → a message with the closest name, or the accepted forms.
pub(super) fn function_not_found(sig: &str) -> String {
    let (name, args) = match sig.split_once(" (") {
        Some((n, a)) => (n.trim(), a.trim_end_matches(')')),
        None => (sig.trim(), ""),
    };
    let args: Vec<String> = if args.trim().is_empty() {
        Vec::new()
    } else {
        args.split(", ").map(shown_type).collect()
    };
    let call = format!("{name}({})", args.join(", "));
    if name.starts_with("anon$") {
        // A closure (its function's generated name says nothing) called with a number of
        // arguments other than its parameters'.
        let n = args.len();
        let params = match n {
            1 => "p".to_string(),
            _ => (1..=n)
                .map(|k| format!("p{k}"))
                .collect::<Vec<_>>()
                .join(", "),
        };
        let s = if n == 1 { "" } else { "s" };
        return format!(
            "a closure was called with {n} argument{s} ({}), which its parameters do not take; write it with {n} parameter{s}, such as |{params}| ...",
            args.join(", ")
        );
    }
    if is_operator(name) {
        return operator_not_found(name, &args);
    }
    let voc = vocabulary();
    if let Some((alias, f)) = name.rsplit_once("::") {
        // A module function: look for it (or the closest name) in every stdlib module, since
        // the alias the script chose need not be the module's name.
        if let Some((m, _)) = voc
            .modules
            .iter()
            .find(|(_, fns)| fns.iter().any(|g| g == f))
        {
            return format!(
                "{call}: {alias}::{f} exists but takes other arguments; see its definition in stdlib/{m}.rhai (:help {m})"
            );
        }
        let best = voc
            .modules
            .iter()
            .filter_map(|(m, fns)| {
                let names: Vec<&str> = fns.iter().map(String::as_str).collect();
                suggest(f, &names).map(|s| (m, s.to_string()))
            })
            .next();
        return match best {
            Some((m, s)) => format!(
                "there is no function {alias}::{f}; did you mean {alias}::{s}? (module \"{m}\" has: {})",
                voc.modules[m].join(", ")
            ),
            None => format!("there is no function {call}; check the module alias and the function name"),
        };
    }
    if let Some(forms) = voc
        .functions
        .get(name)
        .or_else(|| core_functions().get(name))
    {
        return format!(
            "{name} cannot be called as {call}; its forms: {}{}",
            forms.join(", "),
            integer_hint(&call, &args, forms)
        );
    }
    // A property called as a method: `s.count()` for `s.count`.
    if let [ty] = args.as_slice() {
        if voc
            .getters
            .get(ty)
            .is_some_and(|g| g.iter().any(|p| p == name))
        {
            return format!(
                "{ty}.{name} is a property, not a function: write it without parentheses (x.{name}, not x.{name}())"
            );
        }
    }
    let names: Vec<&str> = voc.functions.keys().map(String::as_str).collect();
    match suggest(name, &names) {
        Some(s) => format!(
            "there is no function {name}; did you mean {s}? Its forms: {}",
            voc.functions[s].join(", ")
        ),
        None => format!("there is no function {call}; :help lists every name"),
    }
}

/// Whether `name` is an operator (`/`, `+=`, `<`, ...) rather than a function name.
fn is_operator(name: &str) -> bool {
    !name.is_empty() && !name.chars().any(|c| c.is_alphanumeric() || c == '_')
}

/// An operator that has no form for these operand types: "cannot apply / to float and string".
fn operator_not_found(op: &str, args: &[String]) -> String {
    let operands = match args {
        [a] => format!("a {a}"),
        [a, b] => format!("{a} and {b}"),
        _ => args.join(", "),
    };
    let numeric = ["+", "-", "*", "/", "%", "**", "<", "<=", ">", ">="]
        .iter()
        .any(|o| op.trim_end_matches('=') == *o || op == *o);
    let fix = if args.iter().any(|a| a == "string") && numeric {
        "; a number was given as a string: write 2, not \"2\" (parse_float(s) or parse_int(s) converts)"
    } else if numeric {
        "; both sides must be numbers (int or float)"
    } else {
        ""
    };
    format!("the operator {op} cannot be applied to {operands}{fix}")
}

/// Rhai's "module not found": an `import` of a name that is neither built in nor a file, or a
/// `name::` path to a module that was not imported (built-in modules too must be imported).
fn module_not_found(m: &str) -> String {
    let names: Vec<&str> = super::stdlib::MODULES.iter().map(|(n, _)| *n).collect();
    if names.contains(&m) {
        return format!(
            "the module \"{m}\" is built in but not imported under that name here: write import \"{m}\" as {m}; before using {m}::… (or use the name an import gave it)"
        );
    }
    let hint = suggest(m, &names)
        .map(|s| format!("did you mean \"{s}\"? "))
        .unwrap_or_default();
    format!(
        "there is no module \"{m}\"; {hint}the built-in modules are {}; a file module is named by its path without \".rhai\", relative to the working folder",
        names.join(", ")
    )
}

/// Rhai's "Data race detected": a variable a closure captured was held by one use (a method
/// call on it) while another needed it: calls of the closure that run at once (a sweep's), or
/// the closure called from inside a method of that same variable.
fn data_race(name: &str) -> String {
    let what = if name.is_empty() {
        "a variable that a closure captured".to_string()
    } else {
        format!("a variable that a closure captured ({name})")
    };
    format!(
        "{what} was in use by one call while another needed it: calls of the closure that run at once share what it captures (a sweep's calls), and a closure called while a method of that same variable runs finds it held; build the value inside the closure, or give each call a copy (let t = s.copy(); ...)"
    )
}

/// "a Scene", "an int": the type word with its article.
fn a(ty: &str) -> String {
    let article = if ty.starts_with(['a', 'e', 'i', 'o', 'u', 'A', 'E', 'I', 'O', 'U']) {
        "an"
    } else {
        "a"
    };
    format!("{article} {ty}")
}

/// Rhai's "Unknown property 'p' - a getter is not registered for type 'T'" and "No writable
/// property 'p' - a setter is not registered for type 'T' to handle 'U'" in swimlab's words: the
/// type's properties that can be read (or set), the closest name, and, for a value that has no
/// such property at all (a number where a scene was meant), the types that do have it.
fn property_not_found(msg: &str) -> String {
    let quoted: Vec<&str> = msg.split('\'').skip(1).step_by(2).collect();
    let (Some(prop), Some(rhai_ty)) = (quoted.first(), quoted.get(1)) else {
        return msg.to_string();
    };
    let ty = shown_type(rhai_ty);
    let voc = vocabulary();
    let setter = msg.starts_with("No writable property");
    let readable = voc.getters.get(&ty);
    let settable = voc.setters.get(&ty);
    let list = |props: &[String]| props.join(", ");
    if setter && readable.is_some_and(|g| g.iter().any(|p| p == prop)) {
        return match settable {
            Some(s) => format!(
                "{ty}.{prop} can be read but not set; the properties of {} that can be set: {}",
                a(&ty),
                list(s)
            ),
            None => format!(
                "{ty}.{prop} can be read but not set: no property of {} can be set",
                a(&ty)
            ),
        };
    }
    let (table, what) = if setter {
        (settable, "can be set")
    } else {
        (readable, "can be read")
    };
    if let Some(props) = table {
        let names: Vec<&str> = props.iter().map(String::as_str).collect();
        let hint = suggest(prop, &names)
            .map(|s| format!("did you mean .{s}? "))
            .unwrap_or_default();
        return format!(
            "{ty} has no property .{prop}; {hint}the properties that {what}: {}",
            names.join(", ")
        );
    }
    // A type with no property of this kind at all: a plain value, or a read-only type set.
    let owners: Vec<&str> = voc
        .getters
        .iter()
        .chain(voc.setters.iter())
        .filter(|(_, props)| props.iter().any(|p| p == prop))
        .map(|(t, _)| t.as_str())
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect();
    let none = match (setter, readable) {
        (true, Some(g)) => format!(
            "no property of {} can be set (those that can be read: {})",
            a(&ty),
            list(g)
        ),
        _ => format!("{} has no properties", a(&ty)),
    };
    if owners.is_empty() {
        format!("{ty} has no property .{prop}: {none}")
    } else {
        format!(
            "{ty} has no property .{prop}: {none}; .{prop} is a property of {}: is the value the one you meant? (it is {} here)",
            owners.join(", "),
            a(&ty)
        )
    }
}
