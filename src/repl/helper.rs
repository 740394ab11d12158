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

/// The line editor's helper over the session.
pub struct ReplHelper {
    session: Rc<RefCell<Session>>,
}

impl ReplHelper {
    /// A helper completing against `session`.
    pub fn new(session: Rc<RefCell<Session>>) -> Self {
        ReplHelper { session }
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
        let (start, names) = self.session.borrow().complete(line, pos);
        let pairs = names
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
