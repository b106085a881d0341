//! Printing a command's result as JSON.

/// Prints `value` as JSON on stdout: one line when `compact`, else indented.
pub(crate) fn print_json<T: serde::Serialize>(value: &T, compact: bool) -> anyhow::Result<()> {
    if compact {
        println!("{}", serde_json::to_string(value)?);
    } else {
        println!("{}", serde_json::to_string_pretty(value)?);
    }
    Ok(())
}
