//! src/README.md's table is the map a newcomer reads first, and these tests hold it to the code.
//! Each file's `use` trees (grouped and nested lists, `self`, `super::super::`, `pub use`) and
//! the paths its code writes are resolved, through re-exports, to the files that hold what they
//! name ([`crate_map`]). From that:
//! - no folder has an import circle between its files or subfolders (each module readable with
//!   only those below it; the folder's own mod.rs is the folder, not one of them); a circle is
//!   shown as its chain, with the line of each arrow;
//! - the layers import along the arrows the README draws: each layer's row lists exactly the
//!   layers (and, in parentheses, their modules) and the dependencies it uses;
//! - every file of src/ has a row (`x/` is the folder's mod.rs; `{a,b}` patterns name several)
//!   and every row a file;
//! - every other row lists exactly what its files (with their child modules) import, each
//!   import named where its path leaves the row's module: an engine module's row names the
//!   engine modules it uses, a file's row in `engine/gpu/` its siblings and those engine
//!   modules; in the engine, `error` is open to all.

mod crate_map;
mod rust_source;

use crate_map::{circles, module_of, CrateMap, ModPath};
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// A row of src/README.md's table: the modules it names (`x/` is the folder's mod.rs; `{a,b}`
/// patterns name several), the `.wgsl` files it names, and its "may import" words, each with
/// the names in its parentheses (`script (params, interrupt)`).
struct Row {
    modules: Vec<ModPath>,
    shaders: Vec<String>,
    imports: BTreeMap<String, BTreeSet<String>>,
}

/// `engine/gpu/{a,b}.{rs,wgsl}` as the four paths it names.
fn expand(pattern: &str) -> Vec<String> {
    let Some(open) = pattern.find('{') else {
        return vec![pattern.to_string()];
    };
    let close = open + pattern[open..].find('}').expect("a closing brace");
    pattern[open + 1..close]
        .split(',')
        .flat_map(|alt| {
            expand(&format!(
                "{}{}{}",
                &pattern[..open],
                alt.trim(),
                &pattern[close + 1..]
            ))
        })
        .collect()
}

/// The words of a "may import" cell, split at commas outside parentheses.
fn import_words(cell: &str) -> BTreeMap<String, BTreeSet<String>> {
    let mut words = Vec::new();
    let (mut depth, mut word) = (0, String::new());
    for c in cell.chars() {
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            ',' if depth == 0 => {
                words.push(std::mem::take(&mut word));
                continue;
            }
            _ => {}
        }
        word.push(c);
    }
    words.push(word);
    words
        .iter()
        .filter(|w| !w.trim().is_empty())
        .map(|w| {
            let (name, detail) = w.split_once('(').unwrap_or((w, ""));
            let detail = detail.trim_end().trim_end_matches(')').split(',');
            let detail = detail
                .map(|d| d.trim().to_string())
                .filter(|d| !d.is_empty());
            (name.trim().to_string(), detail.collect())
        })
        .collect()
}

/// The rows of src/README.md's table.
fn readme_rows() -> Vec<Row> {
    let readme = std::fs::read_to_string(Path::new(ROOT).join("src/README.md")).unwrap();
    let mut rows = Vec::new();
    for line in readme.lines().filter(|l| l.starts_with("| `")) {
        let line = line.replace("\\|", "/");
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        let (shaders, paths): (Vec<String>, Vec<String>) = expand(cells[1].trim_matches('`'))
            .into_iter()
            .partition(|p| p.ends_with(".wgsl"));
        rows.push(Row {
            modules: paths
                .iter()
                .map(|p| module_of(Path::new(p.trim_end_matches('/'))))
                .collect(),
            shaders,
            imports: import_words(cells.get(3).copied().unwrap_or("")),
        });
    }
    rows
}

/// Each module's row.
fn row_of(rows: &[Row]) -> BTreeMap<&ModPath, &Row> {
    let mut out = BTreeMap::new();
    for row in rows {
        for m in &row.modules {
            assert!(
                out.insert(m, row).is_none(),
                "src/README.md has two rows for {}",
                shown(m)
            );
        }
    }
    out
}

fn shown(m: &[String]) -> String {
    if m.is_empty() {
        "src".into()
    } else {
        m.join("/")
    }
}

#[test]
fn no_folder_has_an_import_circle() {
    let map = CrateMap::read(Path::new(ROOT));
    let found: Vec<String> = map
        .folders()
        .iter()
        .flat_map(|f| {
            circles(&map.graph(f))
                .into_iter()
                .map(move |c| format!("{}: {c}", shown(f)))
        })
        .collect();
    assert!(found.is_empty(), "import circles:\n{}", found.join("\n"));
}

#[test]
fn every_file_has_a_row_and_every_row_a_file() {
    let map = CrateMap::read(Path::new(ROOT));
    let rows = readme_rows();
    let row_of = row_of(&rows);
    let mut wrong: Vec<String> = map
        .files
        .iter()
        .filter(|f| !f.module.is_empty() && !row_of.contains_key(&f.module))
        .map(|f| format!("src/{} has no row", f.path.display()))
        .collect();
    let modules: BTreeSet<&ModPath> = map.files.iter().map(|f| &f.module).collect();
    for m in row_of.keys().filter(|m| !modules.contains(*m)) {
        wrong.push(format!("a row names {}, which is no file", shown(m)));
    }
    for s in rows.iter().flat_map(|r| &r.shaders) {
        if !Path::new(ROOT).join("src").join(s).exists() {
            wrong.push(format!("a row names {s}, which is no file"));
        }
    }
    assert!(
        wrong.is_empty(),
        "src/README.md and src/ differ:\n{}",
        wrong.join("\n")
    );
}

/// What the files of a row (with their child modules) import, each import named where its path
/// leaves the row's own: a layer (`plot`), a module of the layer (`scene`), ..., a module of the
/// same folder; each name with the names below it (`script` → `params`, `interrupt`) and the
/// first file and line that imports it. In the engine, `error` is open to all.
fn imports_of(map: &CrateMap, row: &Row) -> BTreeMap<String, (BTreeSet<String>, String)> {
    let mut out: BTreeMap<String, (BTreeSet<String>, String)> = BTreeMap::new();
    for m in &row.modules {
        for f in map.files.iter().filter(|f| f.module.starts_with(m)) {
            for (q, line) in &f.imports {
                let Some(i) = (0..q.len()).find(|i| m.get(*i) != Some(&q[*i])) else {
                    continue; // the module itself, or one above it
                };
                let own = row
                    .modules
                    .iter()
                    .any(|o| o.len() == i + 1 && o[..] == q[..=i]);
                if i >= m.len() || own || (i == 1 && q[0] == "engine" && q[1] == "error") {
                    continue;
                }
                let entry = out.entry(q[i].clone()).or_insert_with(|| {
                    (BTreeSet::new(), format!("src/{}:{line}", f.path.display()))
                });
                entry.0.extend(q.get(i + 1).cloned());
            }
        }
    }
    out
}

/// How a row's "may import" column differs from what its files import, if it does: the names
/// (and the names in parentheses where it gives them), and for a layer the dependencies too.
fn drift(map: &CrateMap, row: &Row) -> Option<String> {
    let used = imports_of(map, row);
    let layer = row.modules.iter().all(|m| m.len() == 1);
    let crates = if layer {
        map.crates_of(&row.modules[0])
    } else {
        BTreeSet::new()
    };
    let said: BTreeSet<&String> = row
        .imports
        .keys()
        .filter(|w| !crates.contains(*w))
        .collect();
    let mut wrong = Vec::new();
    for (name, (_, at)) in used.iter().filter(|(n, _)| !said.contains(n)) {
        wrong.push(format!("imports {name} ({at}), not in its row"));
    }
    for name in said.iter().filter(|n| !used.contains_key(**n)) {
        let what = if layer {
            "a layer or dependency it does not use"
        } else {
            "not imported"
        };
        wrong.push(format!("its row lists {name}, {what}"));
    }
    for (name, detail) in row.imports.iter().filter(|(_, d)| !d.is_empty()) {
        let below = used.get(name).map(|u| u.0.clone()).unwrap_or_default();
        if &below != detail {
            wrong.push(format!(
                "imports {name} {below:?}; its row says {name} {detail:?}"
            ));
        }
    }
    let said: BTreeSet<String> = row.imports.keys().cloned().collect();
    let listed = crates.iter().filter(|c| !said.contains(*c));
    wrong.extend(listed.map(|c| format!("names the dependency {c}, not in its row")));
    let mut names: Vec<&String> = used.keys().chain(&crates).collect();
    names.sort();
    (!wrong.is_empty()).then(|| {
        let names: Vec<&str> = names.iter().map(|n| n.as_str()).collect();
        format!(
            "{}: {}; the names: {}",
            shown(&row.modules[0]),
            wrong.join("; "),
            names.join(", ")
        )
    })
}

/// `main.rs` → `repl/` → `script/` → `plot/` → `engine/`, `sweep.rs` and `bench/` beside: each
/// layer's row lists the layers it imports (with their modules where it names them in
/// parentheses) and the dependencies it names, no more and no fewer.
#[test]
fn the_layers_import_along_the_arrows() {
    let map = CrateMap::read(Path::new(ROOT));
    let rows = readme_rows();
    let layers = rows
        .iter()
        .filter(|r| r.modules.iter().all(|m| m.len() == 1));
    let wrong: Vec<String> = layers.filter_map(|r| drift(&map, r)).collect();
    assert!(
        wrong.is_empty(),
        "src/README.md's layer rows drifted:\n{}",
        wrong.join("\n")
    );
}

/// Below the layers, a row's "may import" column lists exactly what its files import, each
/// named where its path leaves the row's own: `engine/gpu/support.rs` imports `contacts` (an
/// engine module) and `rk_stages` (a module of `engine/gpu/`), `script/plot_api.rs` imports
/// `plot` (a layer) and `scene_api`.
#[test]
fn each_row_lists_what_its_files_import() {
    let map = CrateMap::read(Path::new(ROOT));
    let rows = readme_rows();
    let inner = rows
        .iter()
        .filter(|r| r.modules.iter().all(|m| m.len() > 1));
    let wrong: Vec<String> = inner.filter_map(|r| drift(&map, r)).collect();
    assert!(
        wrong.is_empty(),
        "src/README.md's may-import column drifted:\n{}",
        wrong.join("\n")
    );
}

/// The REPL and the kernel speak to the script layer; the engine's names reach them through it.
#[test]
fn the_repl_reaches_the_engine_through_the_script_layer() {
    let map = CrateMap::read(Path::new(ROOT));
    let reaching: Vec<String> = map
        .files
        .iter()
        .filter(|f| f.module.first().is_some_and(|l| l == "repl"))
        .filter_map(|f| {
            let line = f
                .imports
                .iter()
                .find(|(m, _)| m.first().is_some_and(|l| l == "engine"))?
                .1;
            Some(format!("src/{}:{line}", f.path.display()))
        })
        .collect();
    assert!(
        reaching.is_empty(),
        "the REPL imports the engine directly in {reaching:?}"
    );
}

/// A boundary's kind-specific rules live in `engine/boundary/`: no code elsewhere tells the kinds
/// apart by matching `Boundary`'s variants (a `match` arm, `if let`, `matches!`), so that a new
/// kind is one file and one arm there. Building a boundary value (`Boundary::Open`) is not a match.
#[test]
fn boundary_kinds_are_matched_only_in_the_boundary_folder() {
    let variant = |s: &str, at: usize| {
        ["Boundary::Open", "Boundary::Periodic", "Boundary::Wall"]
            .iter()
            .any(|v| s[at..].starts_with(v))
    };
    let mut found = Vec::new();
    let mut stack = vec![Path::new(ROOT).join("src")];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap().flatten() {
            let p = entry.path();
            if p.is_dir() {
                if !p.ends_with("engine/boundary") {
                    stack.push(p);
                }
                continue;
            }
            if p.extension().is_none_or(|e| e != "rs") {
                continue;
            }
            let text = std::fs::read_to_string(&p).unwrap();
            for (k, line) in text.lines().enumerate() {
                let code = line.split("//").next().unwrap_or("");
                for (at, _) in code.match_indices("Boundary::") {
                    if !variant(code, at) {
                        continue;
                    }
                    let before = code[..at].trim_end();
                    let rest = &code[at..];
                    let arm = rest.contains("=>") && !rest.contains("=> Boundary::");
                    if arm
                        || before.ends_with("if let")
                        || before.ends_with("while let")
                        || before.ends_with('|')
                        || before.contains("matches!(")
                    {
                        found.push(format!("{}:{}: {}", p.display(), k + 1, line.trim()));
                    }
                }
            }
        }
    }
    assert!(
        found.is_empty(),
        "Boundary matched outside engine/boundary/:\n{}",
        found.join("\n")
    );
}
