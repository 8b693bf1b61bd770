//! The module graph of src/ follows the data path: every file's imports (its `use` items and the paths it names
//! through `crate::`, `super::` or a child module) point to files of its own layer or of a layer below it in
//! [`LAYERS`], and never form a circle. Test modules (`#[cfg(test)]`) are left out: they may import anything.
//! docs/ARCHITECTURE.md shows the listing; `cargo test --test it architecture:: -- --nocapture` prints it.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use syn::visit::Visit;

/// The layers of src/, top to bottom, each a list of folders (ending in `/`) and files. A file may import files of
/// its own layer and of the layers after it, never of a layer before it. Every file of src/ must be in a layer.
pub const LAYERS: &[(&str, &[&str])] = &[
    ("commands", &["commands/"]),
    ("results", &["results/"]),
    ("cli", &["cli/"]),
    ("measure", &["measure/"]),
    ("methods", &["methods/"]),
    ("gpu", &["gpu/"]),
    ("scene", &["scene/"]),
    ("effects", &["effects/"]),
    ("geometry", &["geometry/"]),
    (
        "base",
        &[
            "lib.rs",
            "error.rs",
            "defaults.rs",
            "formats.rs",
            "numbers.rs",
            "raster.rs",
            "rng.rs",
        ],
    ),
];

/// The index in `layers` of the layer holding `file` (relative to src/).
fn layer_of(layers: &[(&str, &[&str])], file: &str) -> Option<usize> {
    layers.iter().position(|(_, members)| {
        members.iter().any(|m| {
            if m.ends_with('/') {
                file.starts_with(m)
            } else {
                file == *m
            }
        })
    })
}

/// The imports against the layer order (`file -> dep (layer -> layer)`), and the files in no layer.
fn against_layers(
    layers: &[(&str, &[&str])],
    edges: &BTreeMap<String, BTreeSet<String>>,
) -> Vec<String> {
    let mut out = Vec::new();
    for (file, deps) in edges {
        let Some(me) = layer_of(layers, file) else {
            out.push(format!("{file} is in no layer"));
            continue;
        };
        for dep in deps {
            match layer_of(layers, dep) {
                Some(l) if l < me => out.push(format!(
                    "{file} -> {dep} ({} imports {}, a layer above it)",
                    layers[me].0, layers[l].0
                )),
                _ => {}
            }
        }
    }
    out
}

/// A file's module path: src/gpu/mod.rs -> [gpu], src/gpu/targets.rs -> [gpu, targets].
fn module_path(rel: &Path) -> Vec<String> {
    let mut parts: Vec<String> = rel
        .with_extension("")
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    if matches!(parts.last().map(String::as_str), Some("mod" | "lib")) {
        parts.pop();
    }
    parts
}

struct Graph {
    /// Module path -> file (relative to src/).
    modules: BTreeMap<Vec<String>, String>,
}

impl Graph {
    /// The file of the deepest module that `path` names.
    fn file_of(&self, path: &[String]) -> Option<&String> {
        (1..=path.len())
            .rev()
            .find_map(|n| self.modules.get(&path[..n]))
    }
}

struct Refs<'g> {
    graph: &'g Graph,
    me: Vec<String>,
    deps: BTreeSet<String>,
}

impl Refs<'_> {
    fn add(&mut self, segments: Vec<String>) {
        let Some(first) = segments.first() else {
            return;
        };
        let absolute: Vec<String> = match first.as_str() {
            "crate" => segments[1..].to_vec(),
            "super" => {
                let mut base = self.me.clone();
                let mut rest = &segments[..];
                while rest.first().is_some_and(|s| s == "super") {
                    base.pop();
                    rest = &rest[1..];
                }
                base.extend_from_slice(rest);
                base
            }
            "self" => [self.me.clone(), segments[1..].to_vec()].concat(),
            child => {
                let mut p = self.me.clone();
                p.push(child.to_string());
                if !self.graph.modules.contains_key(&p) {
                    return;
                }
                [self.me.clone(), segments].concat()
            }
        };
        if let Some(f) = self.graph.file_of(&absolute) {
            self.deps.insert(f.clone());
        }
    }

    fn use_tree(&mut self, prefix: Vec<String>, tree: &syn::UseTree) {
        match tree {
            syn::UseTree::Path(p) => {
                let mut next = prefix;
                next.push(p.ident.to_string());
                self.use_tree(next, &p.tree);
            }
            syn::UseTree::Name(n) => {
                let mut full = prefix;
                if n.ident != "self" {
                    full.push(n.ident.to_string());
                }
                self.add(full);
            }
            syn::UseTree::Rename(r) => {
                let mut full = prefix;
                full.push(r.ident.to_string());
                self.add(full);
            }
            syn::UseTree::Glob(_) => self.add(prefix),
            syn::UseTree::Group(g) => {
                for t in &g.items {
                    self.use_tree(prefix.clone(), t);
                }
            }
        }
    }
}

fn is_cfg_test(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|a| {
        a.path().is_ident("cfg")
            && a.parse_args::<syn::Meta>()
                .is_ok_and(|m| m.path().is_ident("test"))
    })
}

impl<'ast> Visit<'ast> for Refs<'_> {
    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        if !is_cfg_test(&m.attrs) {
            syn::visit::visit_item_mod(self, m);
        }
    }
    fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
        self.use_tree(Vec::new(), &u.tree);
    }
    // `pub(super)` and `pub(in path)` name who may see an item, not what it uses.
    fn visit_visibility(&mut self, _: &'ast syn::Visibility) {}
    fn visit_path(&mut self, p: &'ast syn::Path) {
        self.add(p.segments.iter().map(|s| s.ident.to_string()).collect());
        syn::visit::visit_path(self, p);
    }
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// file -> the files it imports, for every file of the library under `src`.
fn imports(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    files.retain(|p| !p.ends_with("main.rs"));
    let rel = |p: &PathBuf| p.strip_prefix(src).unwrap().to_path_buf();
    let graph = Graph {
        modules: files
            .iter()
            .map(|p| (module_path(&rel(p)), rel(p).to_string_lossy().into_owned()))
            .collect(),
    };
    let mut edges = BTreeMap::new();
    for p in &files {
        let ast = syn::parse_file(&std::fs::read_to_string(p).unwrap())
            .unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        let name = rel(p).to_string_lossy().into_owned();
        let mut refs = Refs {
            graph: &graph,
            me: module_path(&rel(p)),
            deps: BTreeSet::new(),
        };
        refs.visit_file(&ast);
        refs.deps.remove(&name);
        edges.insert(name, refs.deps);
    }
    edges
}

/// The files that lie on a circle of imports (Tarjan's strongly connected components of more than one file).
fn circles(edges: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct T<'e> {
        edges: &'e BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'e str, usize>,
        low: BTreeMap<&'e str, usize>,
        stack: Vec<&'e str>,
        out: Vec<Vec<String>>,
    }
    impl<'e> T<'e> {
        fn visit(&mut self, v: &'e str) {
            let i = self.index.len();
            self.index.insert(v, i);
            self.low.insert(v, i);
            self.stack.push(v);
            for w in &self.edges[v] {
                let w = w.as_str();
                if !self.index.contains_key(w) {
                    self.visit(w);
                    self.low.insert(v, self.low[v].min(self.low[w]));
                } else if self.stack.contains(&w) {
                    self.low.insert(v, self.low[v].min(self.index[w]));
                }
            }
            if self.low[v] == self.index[v] {
                let mut comp = Vec::new();
                while let Some(w) = self.stack.pop() {
                    comp.push(w.to_string());
                    if w == v {
                        break;
                    }
                }
                if comp.len() > 1 {
                    comp.sort();
                    self.out.push(comp);
                }
            }
        }
    }
    let mut t = T {
        edges,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        out: Vec::new(),
    };
    for v in edges.keys() {
        if !t.index.contains_key(v.as_str()) {
            t.visit(v);
        }
    }
    t.out
}

fn src_dir() -> PathBuf {
    // ARCHITECTURE_SRC points the check at another tree (e.g. an older commit's src/, to compare).
    std::env::var_os("ARCHITECTURE_SRC")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("src"))
}

#[test]
fn imports_follow_the_layer_order() {
    let against = against_layers(LAYERS, &imports(&src_dir()));
    assert!(
        against.is_empty(),
        "imports against the layer order:\n{}",
        against.join("\n")
    );
}

#[test]
fn an_import_against_the_layers_is_found() {
    // The checker itself: a low layer importing a high one, a file in no layer, and an import downwards that
    // is allowed.
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path();
    std::fs::create_dir_all(src.join("top")).unwrap();
    std::fs::create_dir_all(src.join("low")).unwrap();
    std::fs::write(
        src.join("lib.rs"),
        "pub mod low;\npub mod top;\npub mod stray;\n",
    )
    .unwrap();
    std::fs::write(src.join("top/mod.rs"), "pub fn f() { crate::low::g(); }\n").unwrap();
    std::fs::write(
        src.join("low/mod.rs"),
        "use crate::top::f;\npub fn g() {}\n",
    )
    .unwrap();
    std::fs::write(src.join("stray.rs"), "pub fn h() {}\n").unwrap();
    let layers: &[(&str, &[&str])] = &[("top", &["top/"]), ("low", &["low/", "lib.rs"])];
    assert_eq!(
        against_layers(layers, &imports(src)),
        vec![
            "low/mod.rs -> top/mod.rs (low imports top, a layer above it)".to_string(),
            "stray.rs is in no layer".to_string(),
        ]
    );
}

#[test]
fn module_imports_form_no_circle() {
    let edges = imports(&src_dir());
    for line in listing(&edges) {
        println!("{line}");
    }
    let found = circles(&edges);
    assert!(found.is_empty(), "import circles: {found:?}");
}

#[test]
fn a_circle_is_found() {
    // The checker itself: two files importing each other, and a child re-exported by its parent that
    // imports the parent back (the shape the methods' registry had).
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path();
    std::fs::create_dir_all(src.join("m")).unwrap();
    std::fs::write(src.join("lib.rs"), "pub mod a;\npub mod b;\npub mod m;\n").unwrap();
    std::fs::write(src.join("a.rs"), "use crate::b::B;\npub struct A;\n").unwrap();
    std::fs::write(src.join("b.rs"), "pub struct B(crate::a::A);\n").unwrap();
    std::fs::write(
        src.join("m/mod.rs"),
        "pub mod x;\npub struct Opt;\npub fn f() { x::X::new(); }\n",
    )
    .unwrap();
    std::fs::write(
        src.join("m/x.rs"),
        "use super::Opt;\npub struct X;\n#[cfg(test)]\nmod tests { use crate::a::A; }\n",
    )
    .unwrap();
    let found = circles(&imports(src));
    assert_eq!(
        found,
        vec![
            vec!["a.rs".to_string(), "b.rs".to_string()],
            vec!["m/mod.rs".to_string(), "m/x.rs".to_string()],
        ]
    );
}

/// The most lines a function of src/ may span (its signature to its closing brace, doc comments not counted),
/// and the stricter limit of the folders whose functions are steps of a command or a measurement.
const FN_LINES: usize = 100;
const FN_LINES_STRICT: usize = 80;
const STRICT_FOLDERS: &[&str] = &["/measure/", "/commands/"];

/// The functions over the limits today, each at most as long as listed: (file under src/, function, lines).
/// Split one and remove it here; the test fails on any function over its limit that is not listed, on a listed
/// one that grew, and on a listed one that is now within the limit (so the list only shrinks).
const OVER_THE_LIMIT: &[(&str, &str, usize)] = &[];

/// The name of the function a line declares (`[pub[(..)]] [const] [async] [unsafe] fn NAME`), and the
/// line's indentation.
fn fn_declared(line: &str) -> Option<(usize, &str)> {
    let rest = line.trim_start();
    let indent = line.len() - rest.len();
    // One keyword followed by whitespace, or None.
    let word = |s: &'static str, r: &str| -> Option<usize> {
        let after = r.strip_prefix(s)?;
        let ws = after.len() - after.trim_start().len();
        (ws > 0).then_some(r.len() - after.trim_start().len())
    };
    let mut r = rest;
    if let Some(after) = r.strip_prefix("pub") {
        let after = match after.strip_prefix('(') {
            Some(inner) => inner.find(')').map_or(after, |close| &inner[close + 1..]),
            None => after,
        };
        if after.len() > after.trim_start().len() {
            r = after.trim_start();
        }
    }
    for kw in ["const", "async", "unsafe"] {
        if let Some(n) = word(kw, r) {
            r = &r[n..];
        }
    }
    let n = word("fn", r)?;
    let r = &r[n..];
    let end = r
        .find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .unwrap_or(r.len());
    (end > 0).then(|| (indent, &r[..end]))
}

/// Every function of `text` with a body: (name, lines from its `fn` line to the closing brace at its
/// indentation).
fn function_lengths(text: &str) -> Vec<(String, usize)> {
    let lines: Vec<&str> = text.split('\n').collect();
    let mut out = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let Some((indent, name)) = fn_declared(line) else {
            continue;
        };
        let Some(j) = (i..lines.len()).find(|&j| {
            let l = lines[j].trim_end();
            l.ends_with('{') || l.ends_with(';')
        }) else {
            // No body found: counted to one past the end of the file, so a cut-off function is never short.
            out.push((name.to_string(), lines.len() - i + 2));
            continue;
        };
        if lines[j].trim_end().ends_with(';') {
            continue;
        }
        let close = " ".repeat(indent) + "}";
        let k = (j + 1..lines.len())
            .find(|&k| {
                lines[k].starts_with(&close)
                    && lines[k].len() - lines[k].trim_start().len() == indent
            })
            .unwrap_or(lines.len());
        out.push((name.to_string(), k - i + 1));
    }
    out
}

/// (file under src/, function, lines) of every function over its limit.
fn over_the_limit(src: &Path) -> Vec<(String, String, usize)> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    files.sort();
    let mut out = Vec::new();
    for p in files {
        let rel = p
            .strip_prefix(src)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        let limit = if STRICT_FOLDERS.iter().any(|f| format!("/{rel}").contains(f)) {
            FN_LINES_STRICT
        } else {
            FN_LINES
        };
        for (name, n) in function_lengths(&std::fs::read_to_string(&p).unwrap()) {
            if n > limit {
                out.push((rel.clone(), name, n));
            }
        }
    }
    out
}

#[test]
fn functions_stay_within_their_length_limits() {
    let found = over_the_limit(&src_dir());
    let mut problems = Vec::new();
    for (file, name, n) in &found {
        match OVER_THE_LIMIT
            .iter()
            .find(|(f, fun, _)| f == file && fun == name)
        {
            None => problems.push(format!(
                "src/{file}: fn {name} is {n} lines, over the limit ({FN_LINES}, {FN_LINES_STRICT} in \
                 measure/ and commands/): split it into named steps"
            )),
            Some((_, _, max)) if n > max => problems.push(format!(
                "src/{file}: fn {name} grew to {n} lines (listed at {max} in OVER_THE_LIMIT): split it"
            )),
            Some(_) => {}
        }
    }
    for (file, name, max) in OVER_THE_LIMIT {
        if !found.iter().any(|(f, fun, _)| f == file && fun == name) {
            problems.push(format!(
                "src/{file}: fn {name} (listed at {max}) is within the limit now or gone: remove it from \
                 OVER_THE_LIMIT"
            ));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn a_long_function_is_found() {
    // The checker itself: bodies measured from the `fn` line to the closing brace at its indentation,
    // declarations without a body skipped, methods found at their indentation.
    let text = "pub(crate) fn a() {\n    x();\n}\ntrait T {\n    fn b(&self);\n    fn c(&self)\n    where\n        \
                Self: Sized,\n    {\n        y();\n    }\n}\npub const unsafe fn d() {\n    z();\n}\n";
    assert_eq!(
        function_lengths(text),
        vec![
            ("a".to_string(), 3),
            ("c".to_string(), 6),
            ("d".to_string(), 3)
        ]
    );
    assert_eq!(
        fn_declared("    pub(super) async fn e_2() {"),
        Some((4, "e_2"))
    );
    assert_eq!(fn_declared("let f = fn_pointer;"), None);
}

/// The listing as docs/ARCHITECTURE.md shows it: a line per file of src/, `FILE -> IMPORTS`.
fn listing(edges: &BTreeMap<String, BTreeSet<String>>) -> Vec<String> {
    edges
        .iter()
        .map(|(file, deps)| {
            let deps: Vec<&str> = deps.iter().map(String::as_str).collect();
            format!("{file:<24} -> {}", deps.join(", "))
                .trim_end()
                .to_string()
        })
        .collect()
}

/// docs/ARCHITECTURE.md's import listing is the code's: a file added, moved or importing something new without
/// the listing regenerated (`cargo test --release --test it architecture:: -- --nocapture`) fails here.
#[test]
fn the_documented_listing_is_the_code_s() {
    let doc =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/ARCHITECTURE.md"))
            .unwrap();
    let documented: Vec<String> = doc
        .lines()
        .skip_while(|l| !l.starts_with("## The import listing"))
        .skip_while(|l| !l.starts_with("```"))
        .skip(1)
        .take_while(|l| !l.starts_with("```"))
        .map(|l| l.trim_end().to_string())
        .collect();
    let actual = listing(&imports(&src_dir()));
    let missing: Vec<&String> = actual.iter().filter(|l| !documented.contains(l)).collect();
    let stale: Vec<&String> = documented.iter().filter(|l| !actual.contains(l)).collect();
    assert!(
        missing.is_empty() && stale.is_empty(),
        "docs/ARCHITECTURE.md's listing differs from the code (regenerate it):\nmissing:\n{}\nstale:\n{}",
        missing.iter().map(|s| s.as_str()).collect::<Vec<_>>().join("\n"),
        stale.iter().map(|s| s.as_str()).collect::<Vec<_>>().join("\n")
    );
}
