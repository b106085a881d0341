//! No two files of a crate import each other, directly or round a loop: each crate's
//! files stand in floors, every import pointing down.
//!
//! Each file is parsed with `syn` (the parser Rust's own derive macros use), so what
//! counts is code, never a comment, a doc link or a string. A file's imports are the
//! `crate::…`, `super::…` and `self::…` paths, and the paths that start with a module
//! the file declares (`mod child;` then `use child::X`), in its items, its `use` trees (groups
//! nested to any depth) and the tokens of its macro calls (`tracing::warn!(…
//! crate::x::LIMIT)`), each resolved to the file of the longest module path it names.
//! Test code (`#[cfg(test)]` items and the files of `#[cfg(test)] mod x;`) is left out:
//! a test may use what it tests from anywhere; the floors are the shipped code's.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use syn::visit::{self, Visit};

/// Every crate with a `src/` in the workspace.
fn crate_sources(root: &Path) -> Vec<PathBuf> {
    let mut crates = vec![root.join("proto/src"), root.join("tests/src")];
    let services = std::fs::read_dir(root.join("services")).expect("services/");
    for entry in services.flatten() {
        let src = entry.path().join("src");
        if src.is_dir() {
            crates.push(src);
        }
    }
    crates.sort();
    crates
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir)
        .expect("a source directory")
        .flatten()
    {
        let path = entry.path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// `src/a/b.rs` and `src/a/b/mod.rs` → `["a", "b"]`; `lib.rs`, `main.rs` → `[]`.
fn module_path(src: &Path, file: &Path) -> Vec<String> {
    let relative = file.strip_prefix(src).expect("a file under src/");
    let mut parts: Vec<String> = relative
        .iter()
        .map(|p| p.to_string_lossy().trim_end_matches(".rs").to_owned())
        .collect();
    if matches!(
        parts.last().map(String::as_str),
        Some("mod" | "lib" | "main")
    ) {
        parts.pop();
    }
    parts
}

fn is_test(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|a| {
        a.path().is_ident("cfg")
            && a.parse_args::<syn::Ident>()
                .is_ok_and(|ident| ident == "test")
    })
}

/// What one file's shipped code names: module paths from the crate's root, and the
/// modules it declares test-only in files of their own.
struct Named<'m> {
    module: &'m [String],
    /// The modules this file declares (`mod child;`, shipped code): a path may start
    /// with one of them, relative to this file's module.
    children: BTreeSet<String>,
    paths: Vec<Vec<String>>,
    test_modules: Vec<String>,
}

impl Named<'_> {
    /// `segments` as a path from the crate's root, when it starts at `crate`, `super`,
    /// `self` or a module this file declares (any other path is another crate's or a
    /// local name).
    fn push(&mut self, segments: &[String]) {
        let (mut base, mut rest) = match segments.first().map(String::as_str) {
            Some("crate") => (Vec::new(), &segments[1..]),
            Some("super" | "self") => (self.module.to_vec(), &segments[1..]),
            Some(child) if self.children.contains(child) => (self.module.to_vec(), segments),
            _ => return,
        };
        if segments[0] == "super" {
            base.pop();
            while rest.first().is_some_and(|s| s == "super") {
                base.pop();
                rest = &rest[1..];
            }
        }
        base.extend(rest.iter().cloned());
        self.paths.push(base);
    }

    fn use_tree(&mut self, tree: &syn::UseTree, prefix: &mut Vec<String>) {
        match tree {
            syn::UseTree::Path(p) => {
                prefix.push(p.ident.to_string());
                self.use_tree(&p.tree, prefix);
                prefix.pop();
            }
            syn::UseTree::Name(n) => self.push_with(prefix, &n.ident),
            syn::UseTree::Rename(r) => self.push_with(prefix, &r.ident),
            syn::UseTree::Glob(_) => self.push(&prefix.clone()),
            syn::UseTree::Group(g) => {
                for item in &g.items {
                    self.use_tree(item, prefix);
                }
            }
        }
    }

    fn push_with(&mut self, prefix: &[String], last: &syn::Ident) {
        let mut path = prefix.to_vec();
        path.push(last.to_string());
        self.push(&path);
    }

    /// Paths in a macro call's tokens: `crate`, `super` or `self`, then `:: ident`…
    fn macro_tokens(&mut self, tokens: proc_macro2::TokenStream) {
        let flat = flatten(tokens);
        for (i, tree) in flat.iter().enumerate() {
            let proc_macro2::TokenTree::Ident(start) = tree else {
                continue;
            };
            if !["crate", "super", "self"].contains(&start.to_string().as_str()) {
                continue;
            }
            let mut path = vec![start.to_string()];
            let mut k = i + 1;
            while let (
                Some(proc_macro2::TokenTree::Punct(a)),
                Some(proc_macro2::TokenTree::Punct(b)),
                Some(proc_macro2::TokenTree::Ident(next)),
            ) = (flat.get(k), flat.get(k + 1), flat.get(k + 2))
            {
                if a.as_char() != ':' || b.as_char() != ':' {
                    break;
                }
                path.push(next.to_string());
                k += 3;
            }
            if path.len() > 1 {
                self.push(&path);
            }
        }
    }
}

/// A token stream with its groups opened, in order.
fn flatten(tokens: proc_macro2::TokenStream) -> Vec<proc_macro2::TokenTree> {
    let mut out = Vec::new();
    for tree in tokens {
        match tree {
            proc_macro2::TokenTree::Group(g) => out.extend(flatten(g.stream())),
            other => out.push(other),
        }
    }
    out
}

impl<'ast> Visit<'ast> for Named<'_> {
    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        if is_test(&m.attrs) {
            if m.content.is_none() {
                self.test_modules.push(m.ident.to_string());
            }
            return;
        }
        visit::visit_item_mod(self, m);
    }

    fn visit_item_fn(&mut self, f: &'ast syn::ItemFn) {
        if !is_test(&f.attrs) {
            visit::visit_item_fn(self, f);
        }
    }

    fn visit_item_impl(&mut self, i: &'ast syn::ItemImpl) {
        if !is_test(&i.attrs) {
            visit::visit_item_impl(self, i);
        }
    }

    fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
        if !is_test(&u.attrs) {
            self.use_tree(&u.tree, &mut Vec::new());
        }
    }

    /// `pub(super)` and `pub(in crate::x)` name a module to say who may see an item, not
    /// to use it: no import.
    fn visit_visibility(&mut self, _: &'ast syn::Visibility) {}

    fn visit_path(&mut self, p: &'ast syn::Path) {
        let segments: Vec<String> = p.segments.iter().map(|s| s.ident.to_string()).collect();
        self.push(&segments);
        visit::visit_path(self, p);
    }

    fn visit_macro(&mut self, m: &'ast syn::Macro) {
        self.macro_tokens(m.tokens.clone());
        visit::visit_macro(self, m);
    }
}

/// The import graph of one crate: file → the files it imports (itself excluded).
fn import_graph(src: &Path) -> BTreeMap<PathBuf, BTreeSet<PathBuf>> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let modules: BTreeMap<Vec<String>, PathBuf> = files
        .iter()
        .map(|f| (module_path(src, f), f.clone()))
        .collect();
    let mut named = BTreeMap::new();
    let mut test_only = BTreeSet::new();
    for file in &files {
        let text = std::fs::read_to_string(file).expect("a source file");
        let parsed = syn::parse_file(&text).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        let module = module_path(src, file);
        let children = parsed
            .items
            .iter()
            .filter_map(|item| match item {
                syn::Item::Mod(m) if m.content.is_none() && !is_test(&m.attrs) => {
                    Some(m.ident.to_string())
                }
                _ => None,
            })
            .collect();
        let mut visitor = Named {
            module: &module,
            children,
            paths: Vec::new(),
            test_modules: Vec::new(),
        };
        visitor.visit_file(&parsed);
        for name in visitor.test_modules {
            let mut test_module = module.clone();
            test_module.push(name);
            if let Some(f) = modules.get(&test_module) {
                test_only.insert(f.clone());
            }
        }
        named.insert(file.clone(), visitor.paths);
    }
    let mut graph = BTreeMap::new();
    for (file, paths) in named {
        if test_only.contains(&file) {
            continue;
        }
        let imports: BTreeSet<PathBuf> = paths
            .iter()
            .filter_map(|path| (1..=path.len()).rev().find_map(|n| modules.get(&path[..n])))
            .filter(|target| **target != file && !test_only.contains(*target))
            .cloned()
            .collect();
        graph.insert(file, imports);
    }
    graph
}

/// The files on some loop, each loop as found first (depth-first, in path order).
fn circles(graph: &BTreeMap<PathBuf, BTreeSet<PathBuf>>) -> Vec<Vec<PathBuf>> {
    #[derive(Clone, Copy, PartialEq)]
    enum Mark {
        New,
        Open,
        Done,
    }
    fn visit(
        node: &PathBuf,
        graph: &BTreeMap<PathBuf, BTreeSet<PathBuf>>,
        marks: &mut BTreeMap<PathBuf, Mark>,
        stack: &mut Vec<PathBuf>,
        found: &mut Vec<Vec<PathBuf>>,
    ) {
        marks.insert(node.clone(), Mark::Open);
        stack.push(node.clone());
        for next in graph.get(node).into_iter().flatten() {
            match marks.get(next).copied().unwrap_or(Mark::New) {
                Mark::New => visit(next, graph, marks, stack, found),
                Mark::Open => {
                    let from = stack.iter().position(|f| f == next).unwrap_or(0);
                    found.push(stack[from..].to_vec());
                }
                Mark::Done => {}
            }
        }
        stack.pop();
        marks.insert(node.clone(), Mark::Done);
    }
    let mut marks = BTreeMap::new();
    let mut found = Vec::new();
    for node in graph.keys() {
        if marks.get(node).copied().unwrap_or(Mark::New) == Mark::New {
            visit(node, graph, &mut marks, &mut Vec::new(), &mut found);
        }
    }
    found
}

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ sits in the workspace")
        .to_path_buf()
}

#[test]
fn no_crate_has_files_that_import_each_other() {
    let root = workspace_root();
    let mut report = Vec::new();
    let mut files = 0;
    for src in crate_sources(&root) {
        let graph = import_graph(&src);
        files += graph.len();
        for circle in circles(&graph) {
            let names: Vec<String> = circle
                .iter()
                .map(|f| f.strip_prefix(&root).unwrap_or(f).display().to_string())
                .collect();
            report.push(names.join(" → "));
        }
    }
    assert!(
        files > 300,
        "read only {files} files: is the workspace where it was?"
    );
    assert!(
        report.is_empty(),
        "files that import each other:\n{}",
        report.join("\n")
    );
}

#[test]
fn the_check_sees_a_circle_and_ignores_comments_strings_and_tests() {
    let dir = tempfile::tempdir().expect("a temporary crate");
    let src = dir.path().join("src");
    std::fs::create_dir_all(src.join("store")).expect("src/store");
    let write = |path: &str, text: &str| std::fs::write(src.join(path), text).expect("write");
    write(
        "lib.rs",
        "pub mod edits;\npub mod store;\npub mod quiet;\npub mod loud;\n",
    );
    write(
        "store/mod.rs",
        "use crate::edits::CellEdits;\npub mod stage;\npub mod shelf;\nuse shelf::Shelf;\nmod bin;\nuse bin::Bin;\n",
    );
    write(
        "store/stage.rs",
        "use super::super::quiet as _;\nconst J: &str = r#\"a \"crate::store\" b\"#;\n",
    );
    // A child the parent names by a relative path (`use shelf::Shelf`) importing the
    // parent back: a circle too.
    write(
        "store/shelf.rs",
        "use super::CellEdits;\npub struct Shelf;\n",
    );
    // A visibility naming the parent is no import of it.
    write(
        "store/bin.rs",
        "pub(super) struct Bin;\npub(in crate::store) fn b() {}\n",
    );
    write("edits.rs", "fn f() { let _ = crate::store::OCCUPANCY; }\n");
    // Names the store only in a doc link, a comment, a string and test code: no import.
    write(
        "quiet.rs",
        "//! See [`crate::store`].\n/* crate::store */\nconst S: &str = \"crate::store\";\n\
         #[cfg(test)]\nmod tests {\n    use crate::store::stage;\n}\n",
    );
    // A nested use group and a path inside a macro call.
    write(
        "loud.rs",
        "use crate::{quiet as _, store::{stage::{self as _}}};\n\
         fn f() { println!(\"{}\", crate::edits::X); }\n",
    );
    let graph = import_graph(&src);
    let found = circles(&graph);
    let names: BTreeSet<BTreeSet<String>> = found
        .iter()
        .map(|circle| {
            circle
                .iter()
                .map(|f| {
                    f.file_name()
                        .unwrap_or_default()
                        .to_string_lossy()
                        .into_owned()
                })
                .collect()
        })
        .collect();
    let circle = |files: [&str; 2]| files.map(str::to_owned).into_iter().collect();
    assert_eq!(
        names,
        BTreeSet::from([
            circle(["edits.rs", "mod.rs"]),
            circle(["mod.rs", "shelf.rs"])
        ]),
        "{found:?}"
    );
    let quiet = src.join("quiet.rs");
    assert!(
        graph.get(&quiet).is_some_and(BTreeSet::is_empty),
        "{graph:?}"
    );
    // `super::super::quiet` from store/stage.rs is quiet.rs; the raw string is no path.
    let stage = graph.get(&src.join("store/stage.rs"));
    assert_eq!(stage, Some(&BTreeSet::from([quiet.clone()])), "{graph:?}");
    let loud = graph.get(&src.join("loud.rs"));
    let expected = BTreeSet::from([quiet, src.join("store/stage.rs"), src.join("edits.rs")]);
    assert_eq!(loud, Some(&expected), "{graph:?}");
}
