//! Help that tells the truth: every command's `--help` begins with the line the
//! command table of `services/roam/README.md` gives it, so a command whose help or
//! README drifts from the other fails here. The commands are found the way a user
//! finds them, by walking the `Commands:` sections of the built binary's help.

use std::collections::BTreeMap;
use std::process::Command;

const ROAM: &str = env!("CARGO_BIN_EXE_roam");
const README: &str = include_str!("../README.md");

/// `roam <path> --help`'s output.
fn help(path: &[String]) -> String {
    let output = Command::new(ROAM)
        .args(path)
        .arg("--help")
        .env("COLUMNS", "100")
        .output()
        .expect("run roam --help");
    assert!(output.status.success(), "roam {path:?} --help failed");
    String::from_utf8(output.stdout).expect("utf-8 help")
}

/// The help's first paragraph, its wrapped lines joined: what the command does.
fn first_paragraph(help: &str) -> String {
    help.lines()
        .take_while(|l| !l.trim().is_empty())
        .map(str::trim)
        .collect::<Vec<_>>()
        .join(" ")
}

/// The subcommands listed under `Commands:` (clap's own `help` left out).
fn subcommands(help: &str) -> Vec<String> {
    help.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .filter(|l| l.starts_with("  ") && !l.starts_with("   "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|name| *name != "help")
        .map(str::to_owned)
        .collect()
}

/// Every command below the top, as `map inspect`, with its help's first paragraph.
fn commands() -> BTreeMap<String, String> {
    let mut found = BTreeMap::new();
    let mut todo: Vec<Vec<String>> = vec![Vec::new()];
    while let Some(path) = todo.pop() {
        let text = help(&path);
        for sub in subcommands(&text) {
            let mut deeper = path.clone();
            deeper.push(sub);
            todo.push(deeper);
        }
        if !path.is_empty() {
            found.insert(path.join(" "), first_paragraph(&text));
        }
    }
    found
}

/// The README's command table: each row's command (the words of its first code span
/// up to the first flag or argument) and its "what it does" cell.
fn readme_table() -> BTreeMap<String, String> {
    let mut rows = BTreeMap::new();
    for line in README.lines().filter(|l| l.starts_with("| `roam ")) {
        let cells: Vec<&str> = split_row(line);
        let (Some(command), Some(what)) = (cells.first(), cells.get(1)) else {
            panic!("a row without two cells: {line}");
        };
        let span = command
            .trim()
            .trim_start_matches('`')
            .split('`')
            .next()
            .unwrap_or_default();
        let words: Vec<&str> = span
            .split_whitespace()
            .skip(1)
            .take_while(|w| !w.starts_with(['-', '[', '<', '.']))
            .collect();
        let previous = rows.insert(words.join(" "), what.trim().to_owned());
        assert!(previous.is_none(), "two rows for roam {}", words.join(" "));
    }
    rows
}

/// A table row's cells, split at the pipes that are not escaped (`\|` is a pipe in a
/// cell).
fn split_row(line: &str) -> Vec<&str> {
    let inner = line.trim().trim_start_matches('|').trim_end_matches('|');
    let mut cells = Vec::new();
    let mut start = 0;
    let bytes = inner.as_bytes();
    for (i, &b) in bytes.iter().enumerate() {
        if b == b'|' && (i == 0 || bytes[i - 1] != b'\\') {
            cells.push(&inner[start..i]);
            start = i + 1;
        }
    }
    cells.push(&inner[start..]);
    cells
}

#[test]
fn every_commands_help_begins_with_its_line_in_the_readme() {
    let commands = commands();
    // The walk found the whole tree, groups and their members alike.
    for known in [
        "demo",
        "map inspect",
        "bench planner",
        "reproduce fleet",
        "sim render",
    ] {
        assert!(commands.contains_key(known), "{known} in {commands:?}");
    }
    let table = readme_table();
    let mut drift = Vec::new();
    for (command, what) in &commands {
        match table.get(command) {
            Some(row) if row == what => {}
            Some(row) => drift.push(format!(
                "roam {command}: --help says\n    {what}\n  the README says\n    {row}"
            )),
            None => drift.push(format!(
                "roam {command} has no row in the README's command table; its line:\n    {what}"
            )),
        }
    }
    for command in table.keys().filter(|c| !commands.contains_key(*c)) {
        drift.push(format!(
            "the README has a row for roam {command}, which does not exist"
        ));
    }
    assert!(drift.is_empty(), "\n{}", drift.join("\n"));
}

#[test]
fn the_table_parser_reads_commands_and_escaped_pipes() {
    let row = r"| `roam sim [--rate R \| --paused]` | Run the sim world | more |";
    assert_eq!(
        split_row(row),
        [
            " `roam sim [--rate R \\| --paused]` ",
            " Run the sim world ",
            " more "
        ]
    );
    let text = "Run it\nover two lines\n\nUsage: roam x\n\nCommands:\n  a  first\n  bb  second\n       wrapped\n  help  Print\n\nOptions:\n";
    assert_eq!(first_paragraph(text), "Run it over two lines");
    assert_eq!(subcommands(text), ["a", "bb"]);
}
