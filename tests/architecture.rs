//! src/README.md's table is the map a newcomer reads first: every engine module has a row, and
//! its "may import" column lists every other engine module the file (with its child modules)
//! uses. `error` is open to all. Arrows that drift from the code fail here, and so does an import
//! circle between engine modules or between script modules (each module must be readable with
//! only those below it); the REPL reaches the engine through the script layer only.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// Top-level engine modules: `engine/x.rs` and `engine/x/` (a folder with mod.rs).
fn engine_modules() -> BTreeSet<String> {
    layer_modules("engine")
}

/// Top-level modules of the layer in `src/<layer>`: `x.rs` and `x/` (a folder with mod.rs).
fn layer_modules(layer: &str) -> BTreeSet<String> {
    std::fs::read_dir(Path::new(ROOT).join("src").join(layer))
        .unwrap()
        .flatten()
        .filter_map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            if e.path().is_dir() {
                e.path().join("mod.rs").exists().then_some(name)
            } else {
                name.strip_suffix(".rs")
                    .filter(|n| *n != "mod")
                    .map(str::to_string)
            }
        })
        .collect()
}

/// The modules of `layer` named in `path` (outside comments) through `crate::<layer>::x` or a
/// `super::` chain that climbs to the layer.
fn imports(path: &Path, depth: usize, modules: &BTreeSet<String>, layer: &str) -> BTreeSet<String> {
    let text = std::fs::read_to_string(path).unwrap();
    let prefix = format!("crate::{layer}::");
    let mut out = BTreeSet::new();
    for line in text.lines().filter(|l| !l.trim_start().starts_with("//")) {
        let mut rest = line;
        while let Some(k) = rest.find("super::").or_else(|| rest.find(&prefix)) {
            let tail = &rest[k..];
            let (ups, after) = if let Some(a) = tail.strip_prefix(prefix.as_str()) {
                (depth, a)
            } else {
                let mut t = tail;
                let mut n = 0;
                while let Some(a) = t.strip_prefix("super::") {
                    n += 1;
                    t = a;
                }
                (n, t)
            };
            let name: String = after
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            if ups == depth && modules.contains(&name) {
                out.insert(name);
            }
            rest = &tail[1..];
        }
    }
    out
}

fn rs_files(dir: &Path, out: &mut Vec<(std::path::PathBuf, usize)>, depth: usize) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            rs_files(&p, out, depth + 1);
        } else if p.extension().is_some_and(|x| x == "rs") {
            // engine/x.rs sits one module below the engine, engine/x/y.rs two, ...
            let d = if p.file_name().is_some_and(|n| n == "mod.rs") {
                depth
            } else {
                depth + 1
            };
            out.push((p, d));
        }
    }
}

/// What each top-level engine module (with its children) imports of the others, `error` aside.
fn import_graph() -> BTreeMap<String, BTreeSet<String>> {
    let mut graph = layer_graph("engine");
    for used in graph.values_mut() {
        used.remove("error");
    }
    graph
}

/// What each top-level module of `layer` (with its children) imports of the others.
fn layer_graph(layer: &str) -> BTreeMap<String, BTreeSet<String>> {
    let modules = layer_modules(layer);
    let dir = Path::new(ROOT).join("src").join(layer);
    let mut files = Vec::new();
    rs_files(&dir, &mut files, 0);
    let mut graph = BTreeMap::new();
    for m in &modules {
        let mut used = BTreeSet::new();
        for (p, depth) in &files {
            let rel = p.strip_prefix(&dir).unwrap();
            let first = rel.iter().next().unwrap().to_string_lossy();
            if first.trim_end_matches(".rs") == m {
                used.extend(imports(p, *depth, &modules, layer));
            }
        }
        used.remove(m);
        graph.insert(m.clone(), used);
    }
    graph
}

#[test]
fn the_may_import_column_of_src_readme_is_the_truth() {
    let modules = engine_modules();
    let graph = import_graph();
    let readme = std::fs::read_to_string(Path::new(ROOT).join("src/README.md")).unwrap();
    let mut allowed: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for line in readme.lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        if cells.len() < 5 {
            continue;
        }
        let path = cells[1].trim_matches('`');
        let Some(rest) = path.strip_prefix("engine/") else {
            continue;
        };
        let name = rest.trim_end_matches('/').trim_end_matches(".rs");
        if !modules.contains(name) {
            continue;
        }
        let list = cells[3]
            .split(',')
            .map(|w| w.trim().to_string())
            .filter(|w| !w.is_empty())
            .collect();
        allowed.insert(name.to_string(), list);
    }
    let mut wrong = Vec::new();
    for m in &modules {
        let Some(ok) = allowed.get(m) else {
            wrong.push(format!("engine/{m}: no row in src/README.md"));
            continue;
        };
        let used = &graph[m];
        let extra: Vec<&String> = used.iter().filter(|u| !ok.contains(*u)).collect();
        let stale: Vec<&String> = ok.iter().filter(|a| !used.contains(*a)).collect();
        if !extra.is_empty() || !stale.is_empty() {
            wrong.push(format!(
                "engine/{m}: imports {used:?}; the row says {ok:?} (missing {extra:?}, not used {stale:?})"
            ));
        }
    }
    assert!(
        wrong.is_empty(),
        "src/README.md drifted:\n{}",
        wrong.join("\n")
    );
}

/// The first import circle of `graph`, as the path that closes it.
fn first_circle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<String> {
    // Depth-first search; a module met again while it is still on the path closes a circle.
    fn visit<'a>(
        m: &'a str,
        graph: &'a BTreeMap<String, BTreeSet<String>>,
        path: &mut Vec<&'a str>,
        done: &mut BTreeSet<&'a str>,
    ) -> Option<Vec<String>> {
        if let Some(k) = path.iter().position(|p| *p == m) {
            let mut circle: Vec<String> = path[k..].iter().map(|s| s.to_string()).collect();
            circle.push(m.to_string());
            return Some(circle);
        }
        if !done.insert(m) {
            return None;
        }
        path.push(m);
        for next in &graph[m] {
            if let Some(c) = visit(next, graph, path, done) {
                return Some(c);
            }
        }
        path.pop();
        None
    }
    let mut done = BTreeSet::new();
    graph
        .keys()
        .find_map(|m| visit(m, graph, &mut Vec::new(), &mut done))
        .map(|c| c.join(" → "))
}

#[test]
fn the_engine_has_no_import_circle() {
    if let Some(c) = first_circle(&import_graph()) {
        panic!("engine import circle: {c}");
    }
}

#[test]
fn the_script_layer_has_no_import_circle() {
    if let Some(c) = first_circle(&layer_graph("script")) {
        panic!("script import circle: {c}");
    }
}

/// The REPL and the kernel speak to the script layer; the engine's names reach them through it.
#[test]
fn the_repl_reaches_the_engine_through_the_script_layer() {
    let mut files = Vec::new();
    rs_files(&Path::new(ROOT).join("src/repl"), &mut files, 0);
    let reaching: Vec<String> = files
        .iter()
        .filter(|(p, _)| {
            std::fs::read_to_string(p)
                .unwrap()
                .lines()
                .filter(|l| !l.trim_start().starts_with("//"))
                .any(|l| l.contains("crate::engine"))
        })
        .map(|(p, _)| p.display().to_string())
        .collect();
    assert!(
        reaching.is_empty(),
        "the REPL imports the engine directly in {reaching:?}"
    );
}
