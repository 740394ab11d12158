//! One error renderer for `swimlab run` and (later) the REPL: `file:line:col: message`, the source
//! line, and a caret under the position.

use rhai::{EvalAltResult, Position};

/// Render a script error against its source text.
pub fn render_error(name: &str, source: &str, err: &EvalAltResult) -> String {
    let (pos, msg) = describe(err);
    let mut out = String::new();
    match (pos.line(), pos.position()) {
        (Some(line), col) => {
            let col = col.unwrap_or(1);
            out.push_str(&format!("error: {name}:{line}:{col}: {msg}\n"));
            if let Some(text) = source.lines().nth(line - 1) {
                let gutter = format!("{line:>4} | ");
                out.push_str(&format!("{gutter}{text}\n"));
                out.push_str(&format!(
                    "{}{}^\n",
                    " ".repeat(gutter.len()),
                    " ".repeat(col.saturating_sub(1))
                ));
            }
        }
        _ => out.push_str(&format!("error: {name}: {msg}\n")),
    }
    out
}

/// The innermost position inside the script and a message without Rhai's "(line x, position y)".
fn describe(err: &EvalAltResult) -> (Position, String) {
    match err {
        EvalAltResult::ErrorInFunctionCall(f, _, inner, pos) => {
            let (ipos, imsg) = describe(inner);
            if ipos.is_none() {
                (*pos, format!("in call to {f}: {imsg}"))
            } else {
                (ipos, format!("in {f}: {imsg}"))
            }
        }
        EvalAltResult::ErrorRuntime(v, pos) => (*pos, v.to_string()),
        other => {
            let pos = other.position();
            let msg = other.to_string();
            let suffix = format!(" ({pos})");
            let msg = msg.strip_suffix(&suffix).map(str::to_string).unwrap_or(msg);
            (pos, msg)
        }
    }
}
