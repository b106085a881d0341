//! The key table in `proto/README.md` ("## Key space") cannot drift from
//! `proto/src/keys.rs`: every `pub fn` there that builds a key (returns a `String`) is
//! named, in backticks, in the table's `function` column, and every name in that column
//! is such a function.

use std::collections::BTreeSet;

const KEYS_RS: &str = include_str!("../src/keys.rs");
const README: &str = include_str!("../README.md");

/// The `pub fn`s of `keys.rs` whose signature returns `String`: the key functions.
fn key_functions(source: &str) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    let mut rest = source;
    while let Some(at) = rest.find("pub fn ") {
        rest = &rest[at + "pub fn ".len()..];
        let name: String = rest
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect();
        // The signature runs to the body's opening brace (rustfmt may wrap it).
        let signature = &rest[..rest.find('{').unwrap_or(rest.len())];
        if signature.trim_end().ends_with("-> String") {
            found.insert(name);
        }
    }
    found
}

/// The backticked names in the `function` column of the table under "## Key space".
fn table_functions(readme: &str) -> BTreeSet<String> {
    let section = readme
        .split("\n## ")
        .find(|s| s.starts_with("Key space"))
        .expect("proto/README.md has a \"## Key space\" section");
    let mut rows = section.lines().filter(|l| l.trim_start().starts_with('|'));
    let cells = |line: &str| -> Vec<String> {
        line.trim()
            .trim_matches('|')
            .split(" | ")
            .map(|c| c.trim().to_owned())
            .collect()
    };
    let header = cells(rows.next().expect("the key table has a header row"));
    let column = header
        .iter()
        .position(|h| h == "function")
        .expect("the key table has a `function` column");
    let mut found = BTreeSet::new();
    for row in rows.filter(|r| !r.contains("---")) {
        let cells = cells(row);
        let cell = cells
            .get(column)
            .unwrap_or_else(|| panic!("row without a function cell: {row}"));
        let names: Vec<&str> = cell.split('`').skip(1).step_by(2).collect();
        assert!(!names.is_empty(), "row names no function: {row}");
        found.extend(names.into_iter().map(str::to_owned));
    }
    found
}

#[test]
fn the_key_table_lists_every_key_function() {
    let code = key_functions(KEYS_RS);
    assert!(
        code.len() > 20,
        "found only {} key functions in keys.rs: {code:?}",
        code.len()
    );
    let table = table_functions(README);
    let missing: Vec<_> = code.difference(&table).collect();
    assert!(
        missing.is_empty(),
        "key functions in proto/src/keys.rs missing from the key table in proto/README.md: {missing:?}"
    );
    let unknown: Vec<_> = table.difference(&code).collect();
    assert!(
        unknown.is_empty(),
        "the key table in proto/README.md names functions proto/src/keys.rs does not have: {unknown:?}"
    );
}

#[test]
fn helpers_are_not_key_functions() {
    let code = key_functions(KEYS_RS);
    for helper in ["check_name", "check_root", "robot_of"] {
        assert!(!code.contains(helper), "{helper} counted as a key function");
    }
    assert!(code.contains("map_layer") && code.contains("robot_mission_report"));
}
