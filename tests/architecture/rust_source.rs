//! What one Rust source file names: its `use` trees (grouped, nested, over several lines, `pub`
//! or not, `self`, `super::super::`, renamed with `as`, globs), the paths its code writes
//! (`crate::engine::x::f(..)`, `super::y::Z`), and the modules it declares inline (`mod tests {`).
//! Comments, strings, characters and lifetimes are left out, so a path in a message or a doc
//! comment is not an import.

/// A token of source: an identifier, `::`, or one punctuation character; with its line.
#[derive(Debug, Clone)]
struct Token {
    text: String,
    line: usize,
}

fn is_ident(s: &str) -> bool {
    s.starts_with(|c: char| c.is_alphabetic() || c == '_')
}

/// The tokens of `text` that can name paths (numbers, comments and literals dropped).
fn tokens(text: &str) -> Vec<Token> {
    let c: Vec<char> = text.chars().collect();
    let at = |k: usize| c.get(k).copied().unwrap_or('\0');
    let (mut i, mut line) = (0, 1);
    let mut out = Vec::new();
    // Skips to just past the closing quote (and `hashes` #s) of a string body starting at k.
    let string_end = |mut k: usize, raw: bool, hashes: usize, line: &mut usize| {
        while k < c.len() {
            match c[k] {
                '\n' => *line += 1,
                '\\' if !raw => k += 1,
                '"' if (1..=hashes).all(|h| at(k + h) == '#') => return k + 1 + hashes,
                _ => {}
            }
            k += 1;
        }
        k
    };
    while i < c.len() {
        let ch = c[i];
        if ch == '\n' {
            line += 1;
            i += 1;
        } else if ch.is_whitespace() {
            i += 1;
        } else if ch == '/' && at(i + 1) == '/' {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if ch == '/' && at(i + 1) == '*' {
            let mut depth = 0;
            while i < c.len() {
                if c[i] == '/' && at(i + 1) == '*' {
                    depth += 1;
                    i += 1;
                } else if c[i] == '*' && at(i + 1) == '/' {
                    depth -= 1;
                    i += 1;
                } else if c[i] == '\n' {
                    line += 1;
                }
                i += 1;
                if depth == 0 {
                    break;
                }
            }
        } else if ch == '"' {
            i = string_end(i + 1, false, 0, &mut line);
        } else if ch == '\'' {
            if at(i + 1) == '\\' {
                // An escaped character: '\n', '\'', '\u{..}'.
                i += 3;
                while i < c.len() && c[i] != '\'' {
                    i += 1;
                }
                i += 1;
            } else if at(i + 2) == '\'' {
                i += 3;
            } else {
                // A lifetime or a label: its name is no path.
                i += 1;
                while at(i).is_alphanumeric() || at(i) == '_' {
                    i += 1;
                }
            }
        } else if ch.is_alphabetic() || ch == '_' {
            let start = i;
            while at(i).is_alphanumeric() || at(i) == '_' {
                i += 1;
            }
            let word: String = c[start..i].iter().collect();
            let hashes = (i..).take_while(|k| at(*k) == '#').count();
            if matches!(word.as_str(), "r" | "br" | "cr") && at(i + hashes) == '"' {
                i = string_end(i + hashes + 1, true, hashes, &mut line);
            } else if matches!(word.as_str(), "b" | "c") && at(i) == '"' {
                i = string_end(i + 1, false, 0, &mut line);
            } else if word == "b" && at(i) == '\'' {
                i += if at(i + 1) == '\\' { 4 } else { 3 };
            } else if word == "r" && hashes == 1 && (at(i + 1).is_alphabetic() || at(i + 1) == '_')
            {
                i += 1; // a raw identifier, r#type: the word follows
            } else {
                out.push(Token { text: word, line });
            }
        } else if ch.is_ascii_digit() {
            while at(i).is_alphanumeric() || at(i) == '_' {
                i += 1;
            }
        } else if ch == ':' && at(i + 1) == ':' {
            out.push(Token {
                text: "::".into(),
                line,
            });
            i += 2;
        } else {
            out.push(Token {
                text: ch.to_string(),
                line,
            });
            i += 1;
        }
    }
    out
}

/// A name a file brings into scope with `use` (the last segment, or the `as` name), or a glob.
#[derive(Debug, Clone, PartialEq)]
pub struct Use {
    /// The inline modules it sits in (`["tests"]`), outermost first; empty at the file's top.
    pub inline: Vec<String>,
    /// The path as written: `["super", "render", "render_error"]`.
    pub path: Vec<String>,
    /// The name it is known by; `None` for a glob (`use super::*`).
    pub alias: Option<String>,
    /// `pub use`, `pub(crate) use`, ...
    pub public: bool,
    pub line: usize,
}

/// A path the code writes with at least one `::`, as written.
#[derive(Debug, Clone, PartialEq)]
pub struct PathRef {
    pub inline: Vec<String>,
    pub path: Vec<String>,
    pub line: usize,
}

/// What a file names.
#[derive(Debug, Default)]
pub struct Source {
    pub uses: Vec<Use>,
    pub paths: Vec<PathRef>,
    /// Inline modules (`mod tests { .. }`), each as its chain of names.
    pub inline_modules: Vec<Vec<String>>,
}

/// Reads one use tree at `i` below `prefix`; returns the index after it.
fn use_tree(
    t: &[Token],
    mut i: usize,
    prefix: &[String],
    out: &mut Vec<(Vec<String>, Option<String>)>,
) -> usize {
    let text = |k: usize| t.get(k).map_or("", |x| x.text.as_str());
    let mut path = prefix.to_vec();
    if text(i) == "::" {
        i += 1;
    }
    loop {
        match text(i) {
            "{" => {
                i += 1;
                while i < t.len() && text(i) != "}" {
                    let next = use_tree(t, i, &path, out);
                    i = if text(next) == "," {
                        next + 1
                    } else {
                        next.max(i + 1)
                    };
                }
                return i + 1;
            }
            "*" => {
                out.push((path, None));
                return i + 1;
            }
            s if is_ident(s) => {
                path.push(s.to_string());
                i += 1;
                if text(i) == "::" {
                    i += 1;
                    continue;
                }
                if path.last().is_some_and(|l| l == "self") {
                    path.pop();
                }
                let mut alias = path.last().cloned();
                if text(i) == "as" {
                    alias = Some(text(i + 1).to_string());
                    i += 2;
                }
                out.push((path, alias));
                return i;
            }
            _ => return i,
        }
    }
}

/// Reads the `use` trees, written paths and inline modules of a file's text.
pub fn read(text: &str) -> Source {
    let t = tokens(text);
    let text = |k: usize| t.get(k).map_or("", |x| x.text.as_str());
    let mut src = Source::default();
    // Inline modules open, each with the brace depth outside it.
    let mut open: Vec<(String, usize)> = Vec::new();
    let mut depth = 0;
    let mut i = 0;
    while i < t.len() {
        let inline: Vec<String> = open.iter().map(|(n, _)| n.clone()).collect();
        match text(i) {
            "{" => depth += 1,
            "}" => {
                depth -= 1;
                if open.last().is_some_and(|(_, d)| *d == depth) {
                    open.pop();
                }
            }
            "mod" if is_ident(text(i + 1)) && text(i + 2) == "{" => {
                open.push((text(i + 1).to_string(), depth));
                src.inline_modules
                    .push(open.iter().map(|(n, _)| n.clone()).collect());
                depth += 1;
                i += 3;
                continue;
            }
            "use" if text(i + 1) != "<" => {
                let before = |k: usize| k.checked_sub(1).map_or("", text);
                let public = before(i) == "pub"
                    || (before(i) == ")"
                        && (0..i)
                            .rev()
                            .find(|k| text(*k) == "(")
                            .is_some_and(|k| before(k) == "pub"));
                let mut trees = Vec::new();
                let end = use_tree(&t, i + 1, &[], &mut trees);
                for (path, alias) in trees {
                    src.uses.push(Use {
                        inline: inline.clone(),
                        path,
                        alias,
                        public,
                        line: t[i].line,
                    });
                }
                i = end;
                continue;
            }
            s if is_ident(s) && text(i + 1) == "::" && (i == 0 || text(i - 1) != "::") => {
                let mut path = vec![s.to_string()];
                let mut k = i;
                while text(k + 1) == "::" && is_ident(text(k + 2)) {
                    path.push(text(k + 2).to_string());
                    k += 2;
                }
                src.paths.push(PathRef {
                    inline,
                    path,
                    line: t[i].line,
                });
                i = k + 1;
                continue;
            }
            _ => {}
        }
        i += 1;
    }
    src
}

#[test]
fn use_trees_and_paths_are_read_whole() {
    let src = read(
        r##"
//! use crate::not::this;
pub(crate) use super::{a, b::{c, d as e}, self as f};
use crate::engine::{
    x,
    y::z, // use crate::nor::this
};
pub use self::g::*;
fn h() -> &'static str {
    let _ = 'c';
    let _ = '\'';
    super::super::k::m(crate::engine::n::p(), r#"crate::q::r"#, "super::s");
    "crate::t"
}
#[cfg(test)]
mod tests {
    use super::*;
    /* crate::u::v /* nested */ */
    fn w() { self::y::z(); }
}
"##,
    );
    let uses: Vec<(String, Option<String>, bool, Vec<String>)> = src
        .uses
        .iter()
        .map(|u| {
            (
                u.path.join("::"),
                u.alias.clone(),
                u.public,
                u.inline.clone(),
            )
        })
        .collect();
    let s = |x: &str| x.to_string();
    assert_eq!(
        uses,
        [
            (s("super::a"), Some(s("a")), true, vec![]),
            (s("super::b::c"), Some(s("c")), true, vec![]),
            (s("super::b::d"), Some(s("e")), true, vec![]),
            (s("super"), Some(s("f")), true, vec![]),
            (s("crate::engine::x"), Some(s("x")), false, vec![]),
            (s("crate::engine::y::z"), Some(s("z")), false, vec![]),
            (s("self::g"), None, true, vec![]),
            (s("super"), None, false, vec![s("tests")]),
        ]
    );
    let paths: Vec<(String, usize)> = src
        .paths
        .iter()
        .map(|p| (p.path.join("::"), p.inline.len()))
        .collect();
    assert_eq!(
        paths,
        [
            (s("super::super::k::m"), 0),
            (s("crate::engine::n::p"), 0),
            (s("self::y::z"), 1)
        ]
    );
    assert_eq!(src.inline_modules, [vec![s("tests")]]);
}
