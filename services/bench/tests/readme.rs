//! The README's module table mirrors the crate: every benchmark module has a row, and
//! every row names a module that exists.

use std::collections::BTreeSet;

fn read(path: &str) -> String {
    let full = format!("{}/{path}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&full).unwrap_or_else(|e| panic!("{full}: {e}"))
}

#[test]
fn every_module_has_a_row_and_every_row_a_module() {
    let modules: BTreeSet<String> = read("src/lib.rs")
        .lines()
        .filter_map(|l| l.strip_prefix("pub mod ")?.strip_suffix(';'))
        .map(str::to_owned)
        .collect();
    let rows: BTreeSet<String> = read("README.md")
        .lines()
        .filter_map(|l| l.strip_prefix("| `")?.split('`').next())
        .filter(|name| *name != "module")
        .map(str::to_owned)
        .collect();
    assert!(modules.len() >= 9, "{modules:?}");
    assert_eq!(
        modules, rows,
        "src/lib.rs's modules against README.md's table"
    );
}
