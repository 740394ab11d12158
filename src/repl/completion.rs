//! Completion in the shell and the kernel: the word before the cursor completed from the
//! registered and documented names, the session's variables and functions, the keywords, a
//! value's methods after a `.`, and the `:commands` at the start of a line.

use super::session::{Session, COMMANDS};
use crate::script::{self, docs};

/// Keywords offered by completion.
const KEYWORDS: &[&str] = &[
    "let", "const", "fn", "if", "else", "for", "in", "while", "loop", "break", "continue",
    "return", "true", "false", "print", "throw", "try", "catch", "import", "export",
];

impl Session {
    /// Completions of the word that ends at byte `pos` of `line`: where the word starts and the
    /// candidates (registered and documented names, variables, functions, keywords; after a `.`
    /// the registered names; at the start of a line the `:commands`).
    pub fn complete(&self, line: &str, pos: usize) -> (usize, Vec<String>) {
        let pos = pos.min(line.len());
        let pos = (0..=pos)
            .rev()
            .find(|&p| line.is_char_boundary(p))
            .unwrap_or(0);
        let head = &line[..pos];
        let start = head
            .char_indices()
            .rev()
            .find(|(_, c)| !(c.is_alphanumeric() || *c == '_' || *c == ':'))
            .map_or(0, |(i, c)| i + c.len_utf8());
        let prefix = &head[start..];
        let after_dot = head[..start].ends_with('.');
        let command = start == 0 && prefix.starts_with(':');
        let mut out: Vec<String> = if command {
            COMMANDS
                .iter()
                .map(|(c, _)| c.split_whitespace().next().unwrap_or(c).to_string())
                .collect()
        } else if after_dot {
            // After `value.`, that value's methods and properties when its type is known.
            self.receiver_type(&head[..start - 1])
                .and_then(|ty| self.methods().get(&ty).cloned())
                .unwrap_or_else(|| self.names().to_vec())
        } else {
            self.names()
                .iter()
                .cloned()
                .chain(self.variables())
                .chain(self.user_functions())
                .chain(KEYWORDS.iter().map(|k| k.to_string()))
                .collect()
        };
        out.retain(|n| n.starts_with(prefix));
        out.sort();
        out.dedup();
        (start, out)
    }

    /// The script type of the variable that `before` (the text up to a `.`) ends with.
    fn receiver_type(&self, before: &str) -> Option<String> {
        let start = before
            .char_indices()
            .rev()
            .find(|(_, c)| !(c.is_alphanumeric() || *c == '_'))
            .map_or(0, |(i, c)| i + c.len_utf8());
        let name = &before[start..];
        let value = self.scope.get(name)?;
        Some(script::type_word(value))
    }

    /// Each script type's registered methods and properties (by the type of their first
    /// parameter), sorted (computed once).
    fn methods(&self) -> &std::collections::HashMap<String, Vec<String>> {
        self.methods.get_or_init(|| {
            let mut by_type: std::collections::HashMap<String, Vec<String>> = Default::default();
            for sig in self.engine.gen_fn_signatures(false) {
                let Some((name, rest)) = sig.split_once('(') else {
                    continue;
                };
                let name = name.trim_start_matches("get$").trim_start_matches("set$");
                let first = rest.split([',', ')']).next().unwrap_or("");
                let Some((_, ty)) = first.split_once(": ") else {
                    continue;
                };
                let ty = ty.trim().trim_start_matches("&mut ").trim();
                if name
                    .chars()
                    .next()
                    .is_some_and(|c| c.is_alphabetic() || c == '_')
                {
                    by_type
                        .entry(ty.to_string())
                        .or_default()
                        .push(name.to_string());
                }
            }
            for names in by_type.values_mut() {
                names.sort();
                names.dedup();
            }
            by_type
        })
    }

    /// The registered and documented names, sorted (computed once).
    fn names(&self) -> &[String] {
        self.names.get_or_init(|| {
            let mut names: Vec<String> = docs::DOCS.iter().map(|d| d.name.to_string()).collect();
            for sig in self.engine.gen_fn_signatures(false) {
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
            names
        })
    }
}
