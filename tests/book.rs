//! The book and README as a newcomer meets them: every ```rhai block runs (examples that are run
//! cannot rot), the reference chapter is what `:help` shows (generated from the same entries),
//! every chapter is in the summary, and every relative link and picture resolves, anchors
//! included.

use rhai::Scope;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use swimlab::script::run_source;

const BOOK: &str = "docs/src";
const REFERENCE: &str = "docs/src/reference.md";

/// README.md and every chapter of the book.
fn pages() -> Vec<PathBuf> {
    let mut pages: Vec<PathBuf> = std::fs::read_dir(BOOK)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    pages.sort();
    pages.insert(0, PathBuf::from("README.md"));
    pages
}

/// The fenced blocks of `text` whose info string starts with `lang`.
fn blocks(text: &str, lang: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut current: Option<String> = None;
    let mut fenced = false;
    for line in text.lines() {
        let l = line.trim_start();
        match &mut current {
            None if l.starts_with("```") && !fenced => {
                if l[3..].trim().starts_with(lang) {
                    current = Some(String::new());
                } else {
                    fenced = true;
                }
            }
            None if l.starts_with("```") => fenced = false,
            Some(b) if l.starts_with("```") => {
                out.push(std::mem::take(b));
                current = None;
            }
            Some(b) => {
                b.push_str(line);
                b.push('\n');
            }
            None => {}
        }
    }
    out
}

/// The lines of `text` outside fenced blocks.
fn prose(text: &str) -> Vec<&str> {
    let mut fenced = false;
    text.lines()
        .filter(|l| {
            if l.trim_start().starts_with("```") {
                fenced = !fenced;
                return false;
            }
            !fenced
        })
        .collect()
}

/// The id mdBook gives a heading: its text in lower case, spaces as '-', other punctuation
/// dropped (inline code marks included).
fn heading_id(heading: &str) -> String {
    heading
        .chars()
        .filter_map(|c| {
            if c.is_alphanumeric() || c == '_' || c == '-' {
                Some(c.to_ascii_lowercase())
            } else if c.is_whitespace() {
                Some('-')
            } else {
                None
            }
        })
        .collect()
}

/// The heading ids of a page.
fn anchors(text: &str) -> BTreeSet<String> {
    prose(text)
        .iter()
        .filter_map(|l| {
            let t = l.trim_start_matches('#');
            (l.starts_with('#') && t.starts_with(' ')).then(|| heading_id(t.trim()))
        })
        .collect()
}

/// The targets of the Markdown links and pictures on a line: `](target)`.
fn link_targets(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = line;
    while let Some(i) = rest.find("](") {
        let after = &rest[i + 2..];
        let Some(end) = after.find(')') else { break };
        out.push(after[..end].to_string());
        rest = &after[end..];
    }
    out
}

#[test]
fn every_rhai_block_runs() {
    let mut ran = 0;
    for page in pages() {
        // The reference's examples are `:help`'s, which tests/help_docs.rs runs.
        if page == Path::new(REFERENCE) {
            continue;
        }
        let text = std::fs::read_to_string(&page).unwrap();
        for (k, b) in blocks(&text, "rhai").iter().enumerate() {
            run_source(
                &format!("{} block {k}", page.display()),
                b,
                &mut Scope::new(),
            )
            .unwrap_or_else(|e| panic!("{e}"));
            ran += 1;
        }
    }
    assert!(
        ran >= 15,
        "only {ran} rhai blocks found in README and the book"
    );
}

#[test]
fn the_reference_chapter_is_what_help_shows() {
    let committed = std::fs::read_to_string(REFERENCE).unwrap();
    let generated = swimlab::repl::reference::markdown();
    assert!(
        committed == generated,
        "{REFERENCE} differs from the entries :help shows; regenerate it: \
         cargo run --release -- reference > {REFERENCE}"
    );
    for d in swimlab::script::docs::DOCS.iter() {
        assert!(
            committed.contains(&format!("### `{}`", d.name)),
            "{} is missing from the reference",
            d.name
        );
    }
}

#[test]
fn every_chapter_is_in_the_summary_and_every_entry_exists() {
    let summary = std::fs::read_to_string(Path::new(BOOK).join("SUMMARY.md")).unwrap();
    let listed: BTreeSet<String> = prose(&summary)
        .iter()
        .flat_map(|l| link_targets(l))
        .collect();
    for page in pages().iter().skip(1) {
        let name = page.file_name().unwrap().to_str().unwrap();
        if name != "SUMMARY.md" {
            assert!(listed.contains(name), "{name} is not in SUMMARY.md");
        }
    }
    for target in &listed {
        assert!(
            Path::new(BOOK).join(target).is_file(),
            "SUMMARY.md lists {target}, which does not exist"
        );
    }
}

#[test]
fn every_relative_link_and_picture_resolves() {
    let mut checked = 0;
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        let dir = page.parent().unwrap();
        for line in prose(&text) {
            for target in link_targets(line) {
                if target.contains("://") || target.starts_with("mailto:") {
                    continue;
                }
                let (file, anchor) = match target.split_once('#') {
                    Some((f, a)) => (f, Some(a)),
                    None => (target.as_str(), None),
                };
                let path = if file.is_empty() {
                    page.clone()
                } else {
                    dir.join(file)
                };
                assert!(
                    path.exists(),
                    "{}: the link {target} points at {}, which does not exist",
                    page.display(),
                    path.display()
                );
                if let Some(a) = anchor {
                    let ids = anchors(&std::fs::read_to_string(&path).unwrap());
                    assert!(
                        ids.contains(a),
                        "{}: the link {target}: {} has no heading #{a}",
                        page.display(),
                        path.display()
                    );
                }
                checked += 1;
            }
        }
    }
    assert!(checked > 30, "only {checked} links checked");
}

#[test]
fn readme_stays_a_front_door() {
    let lines = std::fs::read_to_string("README.md")
        .unwrap()
        .lines()
        .count();
    assert!(
        lines <= 250,
        "README.md has {lines} lines; the detail belongs in the book"
    );
}

/// The design notes' places hold: every source path they name (in backticks) exists, a bare
/// file name relative to the last path before it in its paragraph (or a folder above it); every
/// constant (`UPPER_CASE`) is defined in a file its paragraph names; and a name written
/// "`Name` in `path`" is defined in that file.
#[test]
fn the_design_notes_name_places_that_exist() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("docs/src/design-notes.md")).unwrap();
    let mut problems = Vec::new();
    for paragraph in text.split("\n\n") {
        let ticks: Vec<&str> = paragraph.split('`').skip(1).step_by(2).collect();
        let is_path = |t: &str| {
            [".rs", ".md", ".wgsl", ".toml", ".rhai"]
                .iter()
                .any(|e| t.ends_with(e))
                && !t.contains(' ')
        };
        let mut last: Option<PathBuf> = None;
        let mut files: Vec<PathBuf> = Vec::new();
        for t in &ticks {
            // A folder: bare names after it are looked up in it.
            if t.ends_with('/') && !t.contains(' ') && root.join(t).is_dir() {
                last = Some(root.join(t).join("-"));
                continue;
            }
            if !is_path(t) || t.contains('*') {
                continue;
            }
            let found = if t.contains('/') && root.join(t).exists() {
                Some(root.join(t))
            } else {
                last.as_ref().and_then(|l| {
                    l.ancestors()
                        .skip(1)
                        .take_while(|a| a.starts_with(root) && *a != root)
                        .map(|a| a.join(t))
                        .find(|p| p.exists())
                })
            };
            match found {
                Some(p) => {
                    if p.extension().is_some_and(|e| e == "rs") {
                        files.push(p.clone());
                    }
                    last = Some(p);
                }
                None => problems.push(format!("`{t}` does not exist")),
            }
        }
        let defines = |file: &Path, name: &str| {
            let src = std::fs::read_to_string(file).unwrap_or_default();
            [
                "const ", "static ", "struct ", "enum ", "trait ", "fn ", "type ", "mod ",
            ]
            .iter()
            .any(|k| {
                src.match_indices(&format!("{k}{name}")).any(|(i, _)| {
                    let after = src[i + k.len() + name.len()..].chars().next();
                    !after.is_some_and(|c| c.is_alphanumeric() || c == '_')
                })
            })
        };
        for t in &ticks {
            let constant = t.len() > 2
                && t.contains('_')
                && t.chars()
                    .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_');
            if constant && !files.iter().any(|f| defines(f, t)) {
                problems.push(format!(
                    "`{t}` is defined in none of the files its paragraph names ({})",
                    files
                        .iter()
                        .map(|f| f.strip_prefix(root).unwrap().display().to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
            }
        }
        for (i, piece) in paragraph.split('`').enumerate() {
            // "`Name` in `path`": the piece after a name is " in ", then the path.
            if i % 2 == 0 || i + 2 >= paragraph.split('`').count() {
                continue;
            }
            let pieces: Vec<&str> = paragraph.split('`').collect();
            let ident = piece.chars().all(|c| c.is_alphanumeric() || c == '_')
                && piece.chars().next().is_some_and(|c| c.is_ascii_uppercase());
            if ident && pieces[i + 1] == " in " && is_path(pieces[i + 2]) {
                let file = root.join(pieces[i + 2]);
                if file.exists() && !defines(&file, piece) {
                    problems.push(format!("`{piece}` is not defined in `{}`", pieces[i + 2]));
                }
            }
        }
    }
    assert!(problems.is_empty(), "the design notes: {problems:#?}");
}
