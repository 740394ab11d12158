//! The crate as modules: every file of src/ with its module path, what each `use` brings into
//! scope, and the module each written path leads to (through `use` names and re-exports, such
//! as a `pub use` in a mod.rs, to the file that holds the item). From that, the imports between
//! the modules of any folder, and their circles.

use super::rust_source::{self, Source};
use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::path::{Path, PathBuf};

/// A module's path from the crate root: `["engine", "averaged", "listed"]`. The binary's
/// `main.rs` is `["main"]` and reaches the library as `swimlab::`.
pub type ModPath = Vec<String>;

/// Where a path leads.
#[derive(Debug, Clone, PartialEq)]
enum Target {
    /// A module of this crate (the deepest one the path names).
    Module(ModPath),
    /// A dependency (or `std`): its name.
    Crate(String),
}

/// One file of src/.
pub struct File {
    /// Relative to src/: `engine/averaged/listed.rs`.
    pub path: PathBuf,
    pub module: ModPath,
    source: Source,
    /// The modules its uses and paths lead to, each with the first line that names it.
    pub imports: BTreeMap<ModPath, usize>,
    /// The dependencies it names, each with the first line that names it.
    pub crates: BTreeMap<String, usize>,
}

/// Node → the nodes it imports, each with the file and line that first does.
pub type Graph = BTreeMap<String, BTreeMap<String, (PathBuf, usize)>>;

pub struct CrateMap {
    pub files: Vec<File>,
    /// Every module, inline ones (`tests`) included.
    modules: BTreeSet<ModPath>,
    /// Module → name → what the name stands for there (from its `use`s).
    names: BTreeMap<ModPath, BTreeMap<String, Target>>,
    /// Module → the modules its glob `use`s open.
    globs: BTreeMap<ModPath, Vec<ModPath>>,
    /// The dependencies of Cargo.toml, with `std`, `core` and `alloc`.
    deps: BTreeSet<String>,
}

fn rs_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            rs_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The module path of a file relative to src/.
pub fn module_of(rel: &Path) -> ModPath {
    let mut m: ModPath = rel
        .iter()
        .map(|s| s.to_string_lossy().trim_end_matches(".rs").to_string())
        .collect();
    if m.last()
        .is_some_and(|l| l == "mod" || (m.len() == 1 && l == "lib"))
    {
        m.pop();
    }
    m
}

impl CrateMap {
    /// Reads every file under `root`/src and the dependencies in `root`/Cargo.toml.
    pub fn read(root: &Path) -> CrateMap {
        let src = root.join("src");
        let mut paths = Vec::new();
        rs_files(&src, &mut paths);
        paths.sort();
        let cargo = std::fs::read_to_string(root.join("Cargo.toml")).unwrap();
        let mut deps: BTreeSet<String> = ["std", "core", "alloc"].map(String::from).into();
        let mut in_deps = false;
        for line in cargo.lines().map(str::trim) {
            if line.starts_with('[') {
                in_deps = line.trim_end_matches(']').ends_with("dependencies");
            } else if let Some((name, _)) = line.split_once('=').filter(|_| in_deps) {
                deps.insert(name.trim().split('.').next().unwrap().replace('-', "_"));
            }
        }
        let mut map = CrateMap {
            files: Vec::new(),
            modules: BTreeSet::new(),
            names: BTreeMap::new(),
            globs: BTreeMap::new(),
            deps,
        };
        for p in paths {
            let rel = p.strip_prefix(&src).unwrap().to_path_buf();
            let module = module_of(&rel);
            let source = rust_source::read(&std::fs::read_to_string(&p).unwrap());
            map.modules.insert(module.clone());
            for inline in &source.inline_modules {
                map.modules
                    .insert([module.clone(), inline.clone()].concat());
            }
            map.files.push(File {
                path: rel,
                module,
                source,
                imports: BTreeMap::new(),
                crates: BTreeMap::new(),
            });
        }
        // What each `use` names, in the order written (a use may build on an earlier one).
        for f in 0..map.files.len() {
            for u in map.files[f].source.uses.clone() {
                let here = [map.files[f].module.clone(), u.inline.clone()].concat();
                let target = map.absolute(&u.path, &here, &map.files[f].module);
                match (u.alias, target) {
                    (Some(alias), Some(t)) => {
                        map.names.entry(here).or_default().insert(alias, t);
                    }
                    (None, Some(Target::Module(m))) => map.globs.entry(here).or_default().push(m),
                    _ => {}
                }
            }
        }
        for f in 0..map.files.len() {
            let file = &map.files[f];
            let written = file
                .source
                .uses
                .iter()
                .map(|u| (&u.inline, &u.path, u.line));
            let written = written.chain(
                file.source
                    .paths
                    .iter()
                    .map(|p| (&p.inline, &p.path, p.line)),
            );
            let mut imports = BTreeMap::new();
            let mut crates = BTreeMap::new();
            for (inline, path, line) in written {
                let here = [file.module.clone(), inline.clone()].concat();
                match map
                    .absolute(path, &here, &file.module)
                    .map(|t| map.resolve(t, &file.module, 0))
                {
                    Some(Target::Module(m)) => imports.entry(m).or_insert(line),
                    Some(Target::Crate(c)) => crates.entry(c).or_insert(line),
                    None => continue,
                };
            }
            map.files[f].imports = imports;
            map.files[f].crates = crates;
        }
        map
    }

    /// A path as written in module `here` of the file whose module is `file`, from the root;
    /// `None` for a name local to the module (a type's `Self::new`, `Vec::new`).
    fn absolute(&self, path: &[String], here: &ModPath, file: &ModPath) -> Option<Target> {
        let first = path.first()?;
        let rest = path[1..].to_vec();
        let internal =
            |base: ModPath, rest: Vec<String>| Some(Target::Module([base, rest].concat()));
        match first.as_str() {
            "crate" if file.first().is_some_and(|m| m == "main") => {
                internal(vec!["main".into()], rest)
            }
            "crate" | "swimlab" => internal(vec![], rest),
            "self" => internal(here.clone(), rest),
            "super" => {
                let ups = path.iter().take_while(|s| *s == "super").count();
                let base = here[..here.len().checked_sub(ups)?].to_vec();
                internal(base, path[ups..].to_vec())
            }
            _ => {
                // A child module or a name a `use` brought in comes before a dependency of the
                // same name; a glob may bring in any name that is not a dependency.
                let child = [here.clone(), vec![first.clone()]].concat();
                let named = self.names.get(here).is_some_and(|n| n.contains_key(first));
                let glob = self.globs.get(here).is_some_and(|g| !g.is_empty());
                if self.modules.contains(&child) || named {
                    internal(here.clone(), path.to_vec())
                } else if self.deps.contains(first) {
                    Some(Target::Crate(first.clone()))
                } else if glob {
                    internal(here.clone(), path.to_vec())
                } else {
                    None
                }
            }
        }
    }

    /// The module (or dependency) an absolute path written in the file of module `file` leads
    /// to: down the module tree, through the names `use`s bring into that file, and through the
    /// names a module re-exports from below itself (a mod.rs's `pub use child::Item`), and the
    /// modules globs open. A name a module re-exports from elsewhere (`pub use
    /// crate::engine::files::write_atomically` in script/mod.rs) is that module's offering:
    /// the path leads to it.
    fn resolve(&self, target: Target, file: &ModPath, depth: usize) -> Target {
        let Target::Module(path) = target else {
            return target;
        };
        let mut here: ModPath = Vec::new();
        for (k, seg) in path.iter().enumerate() {
            let child = [here.clone(), vec![seg.clone()]].concat();
            if self.modules.contains(&child) {
                here = child;
                continue;
            }
            if depth < 8 {
                let own = here.starts_with(file);
                if let Some(t) = self.names.get(&here).and_then(|n| n.get(seg)) {
                    return match t.clone() {
                        Target::Module(m) if own || m.starts_with(&here) => {
                            let rest = path[k + 1..].to_vec();
                            self.resolve(Target::Module([m, rest].concat()), file, depth + 1)
                        }
                        Target::Module(_) => Target::Module(here),
                        t => t,
                    };
                }
                for g in self.globs.get(&here).into_iter().flatten() {
                    let t = [g.clone(), path[k..].to_vec()].concat();
                    let t = self.resolve(Target::Module(t), file, depth + 1);
                    if t != Target::Module(g.clone()) {
                        return t;
                    }
                }
            }
            break;
        }
        Target::Module(here)
    }

    /// The file modules directly inside `folder` (its files and subfolders), by name.
    pub fn children(&self, folder: &[String]) -> BTreeSet<String> {
        self.files
            .iter()
            .filter(|f| f.module.len() > folder.len() && f.module.starts_with(folder))
            .map(|f| f.module[folder.len()].clone())
            .collect()
    }

    /// Every module that holds other files (src's root included).
    pub fn folders(&self) -> BTreeSet<ModPath> {
        self.files
            .iter()
            .flat_map(|f| (0..f.module.len()).map(|k| f.module[..k].to_vec()))
            .collect()
    }

    /// The imports between the children of `folder`, each child standing for its whole subtree;
    /// the folder's own file (its mod.rs) is the folder, not one of them.
    pub fn graph(&self, folder: &[String]) -> Graph {
        let nodes = self.children(folder);
        let mut graph: Graph = nodes.iter().map(|n| (n.clone(), BTreeMap::new())).collect();
        let node = |m: &ModPath| {
            (m.len() > folder.len() && m.starts_with(folder)).then(|| m[folder.len()].clone())
        };
        for f in &self.files {
            let Some(from) = node(&f.module) else {
                continue;
            };
            for (m, line) in &f.imports {
                if let Some(to) = node(m).filter(|to| *to != from && nodes.contains(to)) {
                    graph
                        .get_mut(&from)
                        .unwrap()
                        .entry(to)
                        .or_insert((f.path.clone(), *line));
                }
            }
        }
        graph
    }

    /// The dependencies that the files of module `m` (with its children) name.
    pub fn crates_of(&self, m: &[String]) -> BTreeSet<String> {
        self.files
            .iter()
            .filter(|f| f.module.starts_with(m))
            .flat_map(|f| f.crates.keys().cloned())
            .filter(|c| !matches!(c.as_str(), "std" | "core" | "alloc"))
            .collect()
    }
}

/// The nodes reachable from `start` along the graph's arrows (`forward`) or against them.
fn reach<'a>(graph: &'a Graph, start: &'a String, forward: bool) -> BTreeSet<&'a String> {
    let mut seen = BTreeSet::from([start]);
    let mut queue = vec![start];
    while let Some(n) = queue.pop() {
        for (m, arrows) in graph {
            let next: Vec<&String> = if forward && m == n {
                arrows.keys().collect()
            } else if !forward && arrows.contains_key(n) {
                vec![m]
            } else {
                vec![]
            };
            queue.extend(next.into_iter().filter(|x| seen.insert(*x)));
        }
    }
    seen
}

/// Each group of nodes that import each other (a strongly connected component), as one of its
/// shortest circles with the file and line of each arrow, then the whole group:
/// `a -> b (a.rs:3) -> a (b.rs:7); the group: a, b`.
pub fn circles(graph: &Graph) -> Vec<String> {
    let mut seen = BTreeSet::new();
    let mut out = Vec::new();
    for start in graph.keys() {
        if seen.contains(start) {
            continue;
        }
        // Breadth first from `start`; the first arrow back to it closes a shortest circle.
        let mut came_from: BTreeMap<&String, &String> = BTreeMap::new();
        let mut queue = VecDeque::from([start]);
        let mut last = None;
        while let Some(n) = queue.pop_front() {
            if graph[n].contains_key(start) {
                last = Some(n);
                break;
            }
            for next in graph[n].keys() {
                if next != start && !came_from.contains_key(next) {
                    came_from.insert(next, n);
                    queue.push_back(next);
                }
            }
        }
        let Some(mut n) = last else {
            continue;
        };
        let mut chain = vec![start];
        while n != start {
            chain.push(n);
            n = came_from[n];
        }
        chain[1..].reverse();
        chain.push(start);
        let forward = reach(graph, start, true);
        let group: Vec<&String> = reach(graph, start, false)
            .into_iter()
            .filter(|m| forward.contains(m))
            .collect();
        seen.extend(group.iter().map(|s| s.to_string()));
        let mut text = start.clone();
        for w in chain.windows(2) {
            let (file, line) = &graph[w[0]][w[1]];
            text += &format!(" -> {} ({}:{line})", w[1], file.display());
        }
        let group: Vec<&str> = group.iter().map(|s| s.as_str()).collect();
        out.push(format!("{text}; the group: {}", group.join(", ")));
    }
    out
}
