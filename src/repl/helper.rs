//! rustyline glue: a validator that asks Rhai's parser whether the input is complete, completion
//! of functions, methods, properties, variables and commands, and signature hints.

use super::session::Session;
use crate::script::docs;
use rustyline::completion::{Completer, Pair};
use rustyline::highlight::Highlighter;
use rustyline::hint::Hinter;
use rustyline::validate::{ValidationContext, ValidationResult, Validator};
use rustyline::{Context, Helper};
use std::cell::RefCell;
use std::rc::Rc;

const KEYWORDS: &[&str] = &[
    "let", "const", "fn", "if", "else", "for", "in", "while", "loop", "break", "continue",
    "return", "true", "false", "print", "throw", "try", "catch", "import", "export",
];
const COMMANDS: &[&str] = &[":help", ":load", ":vars", ":clear", ":quit"];

/// The REPL's rustyline helper; it reads the session it serves.
pub struct ReplHelper {
    session: Rc<RefCell<Session>>,
    /// Registered names: functions, methods and properties (from the engine and the help).
    names: Vec<String>,
}

impl ReplHelper {
    /// A helper for `session`.
    pub fn new(session: Rc<RefCell<Session>>) -> Self {
        let mut names: Vec<String> = docs::DOCS.iter().map(|d| d.name.to_string()).collect();
        for sig in session.borrow().engine().gen_fn_signatures(false) {
            let name = sig.split('(').next().unwrap_or("");
            let name = name.trim_start_matches("get$").trim_start_matches("set$");
            if name
                .chars()
                .next()
                .is_some_and(|c| c.is_alphabetic() || c == '_')
            {
                names.push(name.to_string());
            }
        }
        names.sort();
        names.dedup();
        ReplHelper { session, names }
    }

    /// Candidates for the word `prefix`; after a `.` only methods and properties make sense,
    /// which are among the registered names.
    pub fn candidates(&self, prefix: &str, after_dot: bool, command: bool) -> Vec<String> {
        let mut out: Vec<String> = if command {
            COMMANDS.iter().map(|c| c.to_string()).collect()
        } else if after_dot {
            self.names.clone()
        } else {
            let s = self.session.borrow();
            self.names
                .iter()
                .cloned()
                .chain(s.variables())
                .chain(s.user_functions())
                .chain(KEYWORDS.iter().map(|k| k.to_string()))
                .collect()
        };
        out.retain(|n| n.starts_with(prefix));
        out.sort();
        out.dedup();
        out
    }
}

impl Completer for ReplHelper {
    type Candidate = Pair;

    fn complete(
        &self,
        line: &str,
        pos: usize,
        _ctx: &Context<'_>,
    ) -> rustyline::Result<(usize, Vec<Pair>)> {
        let head = &line[..pos];
        let start = head
            .char_indices()
            .rev()
            .find(|(_, c)| !(c.is_alphanumeric() || *c == '_' || *c == ':'))
            .map_or(0, |(i, c)| i + c.len_utf8());
        let prefix = &head[start..];
        let after_dot = head[..start].ends_with('.');
        let command = start == 0 && prefix.starts_with(':');
        let pairs = self
            .candidates(prefix, after_dot, command)
            .into_iter()
            .map(|c| Pair {
                display: c.clone(),
                replacement: c,
            })
            .collect();
        Ok((start, pairs))
    }
}

impl Hinter for ReplHelper {
    type Hint = String;

    /// After `name(`, the rest of the call form from the help, e.g. `s.run(` → `seconds)`.
    fn hint(&self, line: &str, pos: usize, _ctx: &Context<'_>) -> Option<String> {
        if pos < line.len() || !line.ends_with('(') {
            return None;
        }
        let head = &line[..line.len() - 1];
        let name_start = head
            .rfind(|c: char| !(c.is_alphanumeric() || c == '_'))
            .map_or(0, |i| i + 1);
        let name = &head[name_start..];
        let doc = docs::lookup(name)?;
        let first = doc
            .signature
            .lines()
            .find(|l| l.contains(&format!("{name}(")))?;
        let rest = &first[first.find(&format!("{name}("))? + name.len() + 1..];
        Some(rest.to_string())
    }
}

impl Highlighter for ReplHelper {}

impl Validator for ReplHelper {
    fn validate(&self, ctx: &mut ValidationContext) -> rustyline::Result<ValidationResult> {
        Ok(if self.session.borrow().is_complete(ctx.input()) {
            ValidationResult::Valid(None)
        } else {
            ValidationResult::Incomplete
        })
    }
}

impl Helper for ReplHelper {}
