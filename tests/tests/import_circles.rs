//! No two files of a crate import each other, directly or round a loop: each crate's
//! files stand in floors, every import pointing down (issue 29: the planner's
//! `world ↔ resolution`, the map server's `store ↔ persist`, the sim's
//! `robot ↔ unicycle` and the others were cut, and this keeps them cut).
//!
//! A file's imports are the `crate::…` and `super::…` paths in its code (comments and
//! doc comments are not code: a doc link is not an import), each resolved to the file
//! of the longest module path it names. Test code (`#[cfg(test)]` items and the files
//! of `#[cfg(test)] mod x;`) is left out: a test may use what it tests from anywhere;
//! the floors are the shipped code's.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

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

/// The code of a file without comments (line comments, doc comments, block comments)
/// and without string literals' contents, so neither a doc link nor a message naming a
/// path counts as an import.
fn code_only(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let chars: Vec<char> = text.chars().collect();
    let (mut i, mut block_depth, mut in_string) = (0, 0usize, false);
    while i < chars.len() {
        let (c, next) = (chars[i], chars.get(i + 1).copied());
        if block_depth > 0 {
            if c == '*' && next == Some('/') {
                block_depth -= 1;
                i += 2;
            } else if c == '/' && next == Some('*') {
                block_depth += 1;
                i += 2;
            } else {
                i += 1;
            }
            continue;
        }
        if in_string {
            if c == '\\' {
                i += 2;
                continue;
            }
            if c == '"' {
                in_string = false;
                out.push('"');
            }
            i += 1;
            continue;
        }
        // A char literal of a quote ('"') opens no string.
        if c == '\'' && next == Some('"') && chars.get(i + 2) == Some(&'\'') {
            i += 3;
            continue;
        }
        // A raw string (r"…", r#"…"#, br##"…"##) ends only at its own closing quote.
        let after_ident = i > 0 && (chars[i - 1].is_alphanumeric() || chars[i - 1] == '_');
        if c == 'r' && !after_ident || (c == 'b' && next == Some('r') && !after_ident) {
            let mut j = i + if c == 'b' { 2 } else { 1 };
            let mut hashes = 0;
            while chars.get(j) == Some(&'#') {
                hashes += 1;
                j += 1;
            }
            if chars.get(j) == Some(&'"') {
                let close: Vec<char> = std::iter::once('"')
                    .chain(std::iter::repeat_n('#', hashes))
                    .collect();
                j += 1;
                while j < chars.len() && !chars[j..].starts_with(&close) {
                    j += 1;
                }
                out.push_str("\"\"");
                i = j + close.len();
                continue;
            }
        }
        match (c, next) {
            ('/', Some('/')) => {
                while i < chars.len() && chars[i] != '\n' {
                    i += 1;
                }
            }
            ('/', Some('*')) => {
                block_depth = 1;
                i += 2;
            }
            ('"', _) => {
                in_string = true;
                out.push('"');
                i += 1;
            }
            _ => {
                out.push(c);
                i += 1;
            }
        }
    }
    out
}

/// `code` without its `#[cfg(test)]` items (an inline module or function, to its
/// closing brace), and the names of the modules it declares test-only in files of their
/// own (`#[cfg(test)] mod tests;`).
fn without_tests(code: &str) -> (String, Vec<String>) {
    const MARK: &str = "#[cfg(test)]";
    let (mut out, mut test_files, mut rest) = (String::new(), Vec::new(), code);
    while let Some(at) = rest.find(MARK) {
        out.push_str(&rest[..at]);
        let after = &rest[at + MARK.len()..];
        let (brace, semi) = (after.find('{'), after.find(';'));
        match (brace, semi) {
            (_, Some(semi)) if brace.is_none_or(|b| semi < b) => {
                let item = after[..semi].trim();
                if let Some(name) = item.strip_prefix("mod ").or(item.strip_prefix("pub mod ")) {
                    test_files.push(name.trim().to_owned());
                }
                rest = &after[semi + 1..];
            }
            (Some(open), _) => {
                let mut depth = 0usize;
                let mut end = after.len();
                for (k, ch) in after[open..].char_indices() {
                    match ch {
                        '{' => depth += 1,
                        '}' => {
                            depth -= 1;
                            if depth == 0 {
                                end = open + k + 1;
                                break;
                            }
                        }
                        _ => {}
                    }
                }
                rest = &after[end..];
            }
            _ => rest = "",
        }
    }
    out.push_str(rest);
    (out, test_files)
}

/// The module paths a file's code names: `crate::a::b::C` → `[a, b, C]`,
/// `super::x` from module `[p, q]` → `[p, x]`, and `use crate::{a::X, b}` → both.
fn named_paths(code: &str, module: &[String]) -> Vec<Vec<String>> {
    let mut paths = Vec::new();
    let bytes: Vec<char> = code.chars().collect();
    let is_ident = |c: char| c.is_alphanumeric() || c == '_';
    let mut i = 0;
    while i < bytes.len() {
        let starts_word = i == 0 || !is_ident(bytes[i - 1]);
        let rest: String = bytes[i..bytes.len().min(i + 7)].iter().collect();
        let (prefix, base): (usize, Vec<String>) = if starts_word && rest.starts_with("crate::") {
            (7, Vec::new())
        } else if starts_word && rest.starts_with("super::") {
            // In `a/b.rs` and in `a/b/mod.rs` (both module [a, b]) super is [a], and
            // each further `super::` one level up. (In an inline `mod tests`, super is
            // the file's own module: read as its parent, at worst an edge to a file
            // the module sits in, which imports it anyway.)
            let mut parent = module.to_vec();
            parent.pop();
            let mut skip = 7;
            while bytes[i + skip..].starts_with(&['s', 'u', 'p', 'e', 'r', ':', ':']) {
                parent.pop();
                skip += 7;
            }
            (skip, parent)
        } else {
            i += 1;
            continue;
        };
        i += prefix;
        for tail in path_tails(&bytes, &mut i) {
            let mut full = base.clone();
            full.extend(tail);
            paths.push(full);
        }
    }
    paths
}

/// Reads `a::b::C`, or `a::{b::C, d}` (one level of braces, nested ones flattened),
/// from `chars[*i..]`, advancing `*i`.
fn path_tails(chars: &[char], i: &mut usize) -> Vec<Vec<String>> {
    let is_ident = |c: char| c.is_alphanumeric() || c == '_';
    let mut head = Vec::new();
    loop {
        let start = *i;
        while *i < chars.len() && is_ident(chars[*i]) {
            *i += 1;
        }
        if *i > start {
            head.push(chars[start..*i].iter().collect::<String>());
        }
        if chars.get(*i) == Some(&':') && chars.get(*i + 1) == Some(&':') {
            *i += 2;
            if chars.get(*i) == Some(&'{') {
                // A group: each comma-separated item is a tail of `head`.
                let mut depth = 0;
                let start = *i;
                while *i < chars.len() {
                    match chars[*i] {
                        '{' => depth += 1,
                        '}' => {
                            depth -= 1;
                            if depth == 0 {
                                *i += 1;
                                break;
                            }
                        }
                        _ => {}
                    }
                    *i += 1;
                }
                let inner: String = chars[start + 1..(*i).saturating_sub(1)].iter().collect();
                return inner
                    .split([',', '{', '}'])
                    .map(|item| {
                        let mut path = head.clone();
                        path.extend(
                            item.split("::")
                                .map(|s| s.trim().to_owned())
                                .filter(|s| !s.is_empty() && s.chars().all(is_ident)),
                        );
                        path
                    })
                    .collect();
            }
            continue;
        }
        return vec![head];
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
    let mut code = BTreeMap::new();
    let mut test_only = BTreeSet::new();
    for file in &files {
        let text = std::fs::read_to_string(file).expect("a source file");
        let module = module_path(src, file);
        let (shipped, test_files) = without_tests(&code_only(&text));
        for name in test_files {
            let mut test_module = module.clone();
            test_module.push(name);
            if let Some(f) = modules.get(&test_module) {
                test_only.insert(f.clone());
            }
        }
        code.insert(file.clone(), (module, shipped));
    }
    let mut graph = BTreeMap::new();
    for (file, (module, shipped)) in &code {
        if test_only.contains(file) {
            continue;
        }
        let mut imports = BTreeSet::new();
        for path in named_paths(shipped, module) {
            // The longest prefix that is a file's module.
            let target = (1..=path.len()).rev().find_map(|n| modules.get(&path[..n]));
            if let Some(target) = target {
                if target != file && !test_only.contains(target) {
                    imports.insert(target.clone());
                }
            }
        }
        graph.insert(file.clone(), imports);
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
fn the_check_sees_a_circle_and_ignores_comments_and_strings() {
    let dir = std::env::temp_dir().join(format!("roam-import-circles-{}", std::process::id()));
    let src = dir.join("src");
    std::fs::create_dir_all(src.join("store")).expect("a temporary crate");
    let write = |path: &str, text: &str| std::fs::write(src.join(path), text).expect("write");
    write("lib.rs", "pub mod edits;\npub mod store;\npub mod quiet;\n");
    write(
        "store/mod.rs",
        "use crate::edits::CellEdits;\npub mod stage;\n",
    );
    write(
        "store/stage.rs",
        "use super::super::quiet as _;\nconst J: &str = r#\"a \"crate::store\" b\"#;\n",
    );
    write("edits.rs", "fn f() { let _ = crate::store::OCCUPANCY; }\n");
    // Names the store only in a doc link, a comment and a string: no import.
    write(
        "quiet.rs",
        "//! See [`crate::store`].\n/* crate::store */\nconst S: &str = \"crate::store\";\n\
         #[cfg(test)]\nmod tests {\n    use crate::store::stage;\n}\n",
    );
    let graph = import_graph(&src);
    let found = circles(&graph);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(found.len(), 1, "{found:?}");
    let names: BTreeSet<String> = found[0]
        .iter()
        .map(|f| {
            f.file_name()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    assert_eq!(
        names,
        ["edits.rs", "mod.rs"]
            .map(str::to_owned)
            .into_iter()
            .collect()
    );
    let quiet = src.join("quiet.rs");
    assert!(
        graph.get(&quiet).is_some_and(BTreeSet::is_empty),
        "{graph:?}"
    );
    // `super::super::quiet` from store/stage.rs is quiet.rs; the raw string is no path.
    let stage = graph.get(&src.join("store/stage.rs"));
    assert_eq!(stage, Some(&BTreeSet::from([quiet])), "{graph:?}");
}
