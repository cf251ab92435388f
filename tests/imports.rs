//! The layout's promise (docs/architecture.md): no import cycle between the modules of any crate,
//! at any level, so that each folder reads bottom-up.
//!
//! Every `use` and every path through `crate::`, `super::` or `self::` in a crate's non-test
//! sources is resolved to the module it names; a reference from module `a::b::c` to `a::d::e`
//! is an edge `b → d` between the siblings under `a`. A strongly connected component of more
//! than one sibling is a cycle. Paths that name items of the module itself, or of a parent, add
//! no edge; a bare path (`foo::bar` with `foo` a child module) is not followed: a child is
//! always below its parent.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// Module path of a source file relative to its crate's `src` (`lib.rs` and `main.rs` are the
/// root, `x/mod.rs` is `x`).
fn module_of(src: &Path, file: &Path) -> Vec<String> {
    let relative = file.strip_prefix(src).expect("file under src");
    let mut parts: Vec<String> = relative
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    let last = parts.pop().expect("a file name");
    let stem = last.trim_end_matches(".rs");
    if !matches!(stem, "lib" | "main" | "mod") {
        parts.push(stem.to_owned());
    }
    parts
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).expect("readable source directory") {
        let path = entry.expect("directory entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The source without line comments and without a trailing `#[cfg(test)] mod tests` block.
fn code_of(text: &str) -> String {
    let text = match text.find("#[cfg(test)]\nmod tests") {
        Some(at) => &text[..at],
        None => text,
    };
    text.lines()
        .map(|line| line.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n")
}

/// `a::{b, c::{d, e}}` as `a::b`, `a::c::d`, `a::c::e`.
fn expand_use(tree: &str) -> Vec<String> {
    let tree = tree.trim();
    let Some(open) = tree.find('{') else {
        return vec![tree.to_owned()];
    };
    let close = tree.rfind('}').expect("balanced use tree");
    let (head, body) = (&tree[..open], &tree[open + 1..close]);
    let mut parts = Vec::new();
    let (mut depth, mut start) = (0, 0);
    for (i, c) in body.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                parts.push(&body[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    parts.push(&body[start..]);
    parts
        .into_iter()
        .filter(|p| !p.trim().is_empty())
        .flat_map(|p| expand_use(p).into_iter().map(|e| format!("{head}{e}")))
        .collect()
}

/// Every path of `code` that starts at `crate`, `super` or `self`.
fn references(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    for statement in code.split(';') {
        let statement = statement.trim_start();
        let tree = ["use ", "pub use ", "pub(crate) use ", "pub(super) use "]
            .iter()
            .find_map(|prefix| statement.strip_prefix(prefix));
        // Only a path tree: a string that happens to hold "; use " is not a declaration.
        let is_tree = |t: &&str| {
            t.chars()
                .all(|c| c.is_ascii_alphanumeric() || c.is_whitespace() || "_:{},*".contains(c))
                && t.matches('{').count() == t.matches('}').count()
        };
        if let Some(tree) = tree.filter(is_tree) {
            let tree: String = tree.split_whitespace().collect::<Vec<_>>().join(" ");
            out.extend(expand_use(&tree));
        }
    }
    let bytes = code.as_bytes();
    for root in ["crate::", "super::", "self::"] {
        let mut from = 0;
        while let Some(at) = code[from..].find(root) {
            let start = from + at;
            from = start + root.len();
            let word_start = start == 0
                || !(bytes[start - 1].is_ascii_alphanumeric() || bytes[start - 1] == b'_');
            if !word_start {
                continue;
            }
            let end = code[start..]
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == ':'))
                .map_or(code.len(), |e| start + e);
            out.push(code[start..end].to_owned());
        }
    }
    out
}

/// The module path `reference` names from module `here` (its leading `crate`/`super`/`self`
/// resolved; the item names after the module are kept, the caller drops what is not a module).
fn resolve(here: &[String], reference: &str) -> Option<Vec<String>> {
    let mut segments = reference
        .split("::")
        .map(|s| s.split(" as ").next().unwrap_or("").trim())
        .filter(|s| !s.is_empty() && *s != "*")
        .peekable();
    let mut path: Vec<String> = match segments.peek() {
        Some(&"crate") => {
            segments.next();
            Vec::new()
        }
        Some(&"super") | Some(&"self") => here.to_vec(),
        _ => return None,
    };
    while let Some(&s) = segments.peek() {
        match s {
            "super" => {
                path.pop();
            }
            "self" => {}
            _ => break,
        }
        segments.next();
    }
    path.extend(segments.map(str::to_owned));
    Some(path)
}

/// Cycles among siblings, per parent module: Tarjan's strongly connected components.
fn cycles(edges: &BTreeMap<Vec<String>, BTreeSet<(String, String)>>) -> Vec<String> {
    let mut found = Vec::new();
    for (parent, pairs) in edges {
        let mut graph: BTreeMap<&str, Vec<&str>> = BTreeMap::new();
        for (a, b) in pairs {
            graph.entry(a).or_default().push(b);
            graph.entry(b).or_default();
        }
        let mut state = Tarjan::default();
        for &v in graph.keys() {
            if !state.index.contains_key(v) {
                state.visit(v, &graph);
            }
        }
        for component in state.components {
            found.push(format!(
                "in `{}`: {}",
                if parent.is_empty() {
                    "crate".to_owned()
                } else {
                    parent.join("::")
                },
                component.join(" ↔ ")
            ));
        }
    }
    found
}

#[derive(Default)]
struct Tarjan<'a> {
    index: BTreeMap<&'a str, usize>,
    low: BTreeMap<&'a str, usize>,
    stack: Vec<&'a str>,
    on_stack: BTreeSet<&'a str>,
    components: Vec<Vec<&'a str>>,
}

impl<'a> Tarjan<'a> {
    fn visit(&mut self, v: &'a str, graph: &BTreeMap<&'a str, Vec<&'a str>>) {
        let n = self.index.len();
        self.index.insert(v, n);
        self.low.insert(v, n);
        self.stack.push(v);
        self.on_stack.insert(v);
        for &w in &graph[v] {
            if !self.index.contains_key(w) {
                self.visit(w, graph);
                let low = self.low[v].min(self.low[w]);
                self.low.insert(v, low);
            } else if self.on_stack.contains(w) {
                let low = self.low[v].min(self.index[w]);
                self.low.insert(v, low);
            }
        }
        if self.low[v] == self.index[v] {
            let mut component = Vec::new();
            loop {
                let w = self.stack.pop().expect("v is on the stack");
                self.on_stack.remove(w);
                component.push(w);
                if w == v {
                    break;
                }
            }
            if component.len() > 1 {
                component.sort_unstable();
                self.components.push(component);
            }
        }
    }
}

/// The import cycles of the crate whose sources are under `src`.
fn import_cycles(src: &Path) -> Vec<String> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let mut modules: BTreeSet<Vec<String>> = files.iter().map(|f| module_of(src, f)).collect();
    for f in &files {
        let mut m = module_of(src, f);
        while m.pop().is_some() {
            modules.insert(m.clone());
        }
    }
    let mut edges: BTreeMap<Vec<String>, BTreeSet<(String, String)>> = BTreeMap::new();
    for file in &files {
        let tests = file.file_name().is_some_and(|n| n == "tests.rs")
            || file.components().any(|c| c.as_os_str() == "tests");
        if tests {
            continue;
        }
        let here = module_of(src, file);
        let code = code_of(&fs::read_to_string(file).expect("readable source"));
        for reference in references(&code) {
            let Some(target) = resolve(&here, &reference) else {
                continue;
            };
            let common = here.iter().zip(&target).take_while(|(a, b)| a == b).count();
            if common >= here.len() || common >= target.len() {
                continue;
            }
            let parent = here[..common].to_vec();
            let mut sibling = parent.clone();
            sibling.push(target[common].clone());
            if modules.contains(&sibling) {
                edges
                    .entry(parent)
                    .or_default()
                    .insert((here[common].clone(), target[common].clone()));
            }
        }
    }
    cycles(&edges)
}

#[test]
fn no_crate_has_an_import_cycle() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut sources = vec![root.join("src")];
    for entry in fs::read_dir(root.join("crates")).expect("the workspace's crates") {
        let src = entry.expect("crate directory").path().join("src");
        if src.is_dir() {
            sources.push(src);
        }
    }
    assert!(
        sources.len() > 8,
        "found the workspace's crates: {sources:?}"
    );
    let found: Vec<String> = sources
        .iter()
        .flat_map(|src| {
            import_cycles(src)
                .into_iter()
                .map(move |c| format!("{}: {c}", src.display()))
        })
        .collect();
    assert!(found.is_empty(), "import cycles:\n{}", found.join("\n"));
}

#[test]
fn the_check_finds_a_cycle_it_is_shown() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let src = dir.path();
    fs::create_dir(src.join("inner")).unwrap();
    fs::write(src.join("lib.rs"), "mod a;\nmod b;\nmod inner;\n").unwrap();
    fs::write(src.join("a.rs"), "use crate::b::{Thing, other::{X}};\n").unwrap();
    fs::write(
        src.join("b.rs"),
        "// use crate::a::Not;\nfn f() { crate::a::g(); }\n",
    )
    .unwrap();
    fs::write(src.join("inner/mod.rs"), "mod x;\nmod y;\n").unwrap();
    fs::write(src.join("inner/x.rs"), "pub use super::y::Y;\n").unwrap();
    fs::write(src.join("inner/y.rs"), "use super::super::a::A;\n").unwrap();
    let found = import_cycles(src);
    assert_eq!(found, vec!["in `crate`: a ↔ b".to_owned()], "{found:?}");
    // A comment is not an import, and an edge between folders that only goes one way is not a
    // cycle: breaking the call in `b` leaves none.
    fs::write(src.join("b.rs"), "// crate::a::g();\n").unwrap();
    assert!(import_cycles(src).is_empty());
    fs::write(src.join("inner/y.rs"), "use super::x::X;\n").unwrap();
    assert_eq!(import_cycles(src), vec!["in `inner`: x ↔ y".to_owned()]);
}
