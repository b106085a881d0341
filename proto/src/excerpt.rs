//! Bounded, escaped echoes of wire data.
//!
//! Anything a peer sent (a kind, a robot name, an id, a key, a parser's complaint that
//! quotes the input) may be megabytes long and may hold newlines or terminal escapes.
//! Error replies and log lines carry it only through [`Excerpt`]: at most
//! [`MAX_EXCERPT_CHARS`] characters, every control character, backslash and invisible
//! formatting character escaped as `char::escape_debug` does, and, when cut, the length of the whole. So a 5 MB `kind` comes
//! back as 64 characters and "… (5000000 bytes)", and `"a\n2026-01-01 INFO forged"` cannot
//! start a log line of its own.

use std::fmt;

/// The most characters of wire data an error reply or a log line carries.
pub const MAX_EXCERPT_CHARS: usize = 64;

/// The most characters of a parser's message (which may quote the input) kept in a reply.
pub const MAX_REASON_CHARS: usize = 160;

/// Displays wire data as a short escaped prefix plus its length when cut.
#[derive(Debug, Clone, Copy)]
pub struct Excerpt<'a> {
    text: &'a str,
    max_chars: usize,
}

/// `text` as an [`Excerpt`] of at most [`MAX_EXCERPT_CHARS`] characters.
pub fn excerpt(text: &str) -> Excerpt<'_> {
    Excerpt {
        text,
        max_chars: MAX_EXCERPT_CHARS,
    }
}

/// `text` as an [`Excerpt`] of at most `max_chars` characters.
pub fn excerpt_n(text: &str, max_chars: usize) -> Excerpt<'_> {
    Excerpt { text, max_chars }
}

/// Raw bytes (a payload that may not be UTF-8) as an excerpt of their lossy text, with
/// the length in bytes of the whole when cut.
pub fn excerpt_bytes(bytes: &[u8]) -> String {
    let head = &bytes[..bytes.len().min(MAX_EXCERPT_CHARS * 4)];
    let text = String::from_utf8_lossy(head);
    let kept: String = text.chars().take(MAX_EXCERPT_CHARS).collect();
    let shown = excerpt(&kept).to_string();
    if kept.len() < text.len() || head.len() < bytes.len() {
        format!("{shown}… ({} bytes)", bytes.len())
    } else {
        shown
    }
}

impl fmt::Display for Excerpt<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (shown, c) in self.text.chars().enumerate() {
            if shown == self.max_chars {
                return write!(f, "… ({} bytes)", self.text.len());
            }
            // Quotes stay as they are (messages quote names in them); control
            // characters, backslashes and invisible formatting (bidi overrides) do not.
            match c {
                '\'' | '"' => write!(f, "{c}")?,
                _ => write!(f, "{}", c.escape_debug())?,
            }
        }
        Ok(())
    }
}

/// A number from the wire, displayed in a bounded length: as Rust writes it (`12.5`)
/// when that is short, in scientific notation (`1e300`, `1e-300`) otherwise. Rust
/// writes an `f64` without an exponent, so a forged `1e300` would otherwise be 301
/// digits in a log line or a reply.
#[derive(Debug, Clone, Copy)]
pub struct Number(pub f64);

/// `x` as a [`Number`] for a log line or a message.
pub fn number(x: f64) -> Number {
    Number(x)
}

impl fmt::Display for Number {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        let magnitude = x.abs();
        if !x.is_finite() || x == 0.0 || (1e-5..1e16).contains(&magnitude) {
            write!(f, "{x}")
        } else {
            write!(f, "{x:e}")
        }
    }
}

/// A parser's message (serde_json's, serde_yaml's) made safe to send back: serde quotes
/// offending strings whole (`invalid type: string "<the whole input>", expected ...`), so
/// the message is cut to [`MAX_REASON_CHARS`] and escaped, and the position it ends
/// with (`at line L column C`) is kept.
pub fn parser_reason(message: &str) -> String {
    let (text, position) = split_position(message);
    format!("{}{position}", excerpt_n(text, MAX_REASON_CHARS))
}

/// A parser's message about a *file* with nothing of the file in it: serde quotes what
/// it found (`invalid type: string "root:x:0:0:...", expected struct ...`, ``unknown
/// field `root` ``), which would hand a peer who asked for `/etc/passwd` its content.
/// Every quoted piece before "expected" is replaced by `…`; what was expected (the
/// schema, roam's own words) and the position (`at line L column C`) are kept.
pub fn file_parse_reason(message: &str) -> String {
    let (text, position) = split_position(message);
    let (found, expected) = match text.find("expected") {
        Some(at) => text.split_at(at),
        None => (text, ""),
    };
    format!(
        "{}{}{position}",
        excerpt_n(&redact_quoted(found), MAX_REASON_CHARS),
        excerpt_n(expected, MAX_REASON_CHARS)
    )
}

/// `text` with the inside of every `"..."`, `` `...` `` and `'...'` span replaced by `…`;
/// an unclosed span runs to the end.
fn redact_quoted(text: &str) -> String {
    let mut out = String::with_capacity(text.len().min(256));
    let mut open: Option<char> = None;
    for c in text.chars() {
        match open {
            Some(q) if c == q => {
                out.push(c);
                open = None;
            }
            Some(_) => {}
            None => {
                out.push(c);
                if matches!(c, '"' | '`' | '\'') {
                    out.push('…');
                    open = Some(c);
                }
            }
        }
    }
    out
}

/// Splits off a trailing ` at line L column C`, as serde's parsers write it.
fn split_position(message: &str) -> (&str, &str) {
    match message.rfind(" at line ") {
        Some(at) if message[at..].contains(" column ") && message.len() - at < 48 => {
            message.split_at(at)
        }
        _ => (message, ""),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_plain_text_is_unchanged() {
        assert_eq!(excerpt("robot-1").to_string(), "robot-1");
    }

    #[test]
    fn quotes_stay_and_bidi_overrides_are_escaped() {
        assert_eq!(excerpt("it's \"x\"").to_string(), "it's \"x\"");
        assert_eq!(excerpt("a\u{202e}b").to_string(), "a\\u{202e}b");
    }

    #[test]
    fn long_text_is_cut_with_its_length() {
        let long = "k".repeat(5_000_000);
        let shown = excerpt(&long).to_string();
        assert_eq!(shown, format!("{}… (5000000 bytes)", "k".repeat(64)));
    }

    #[test]
    fn control_characters_are_escaped() {
        let forged = "a\n2026-01-01T00:00:00Z INFO forged\u{1b}[31m";
        let shown = excerpt(forged).to_string();
        assert!(
            !shown.contains('\n') && !shown.contains('\u{1b}'),
            "{shown}"
        );
        assert!(shown.starts_with("a\\n2026"), "{shown}");
        assert!(shown.contains("\\u{1b}"), "{shown}");
    }

    #[test]
    fn a_parser_reason_keeps_its_position_and_drops_the_quoted_input() {
        let quoted = format!(
            "invalid type: string \"{}\", expected u32 at line 1 column 5000012",
            "root:x:0:0".repeat(500_000)
        );
        let reason = parser_reason(&quoted);
        assert!(reason.len() < 400, "{} bytes", reason.len());
        assert!(reason.ends_with(" at line 1 column 5000012"), "{reason}");
        assert!(reason.starts_with("invalid type: string"), "{reason}");
    }

    #[test]
    fn a_file_parse_reason_keeps_nothing_of_the_file() {
        let cases = [
            "invalid type: string \"root:x:0:0:root:/root:/bin/bash\", expected struct MapYaml at line 1 column 1",
            "unknown field `root`, expected one of `image`, `resolution` at line 1 column 1",
            "invalid value: string 'secret', expected a number",
            "unterminated \"root:x:0",
        ];
        for case in cases {
            let reason = file_parse_reason(case);
            assert!(!reason.contains("root"), "{reason}");
            assert!(!reason.contains("secret"), "{reason}");
        }
        assert_eq!(
            file_parse_reason(cases[1]),
            "unknown field `…`, expected one of `image`, `resolution` at line 1 column 1"
        );
    }

    #[test]
    fn numbers_are_short_whatever_their_size() {
        assert_eq!(number(12.5).to_string(), "12.5");
        assert_eq!(number(0.0).to_string(), "0");
        assert_eq!(number(1e300).to_string(), "1e300");
        assert_eq!(number(-1e-300).to_string(), "-1e-300");
        assert_eq!(number(f64::NAN).to_string(), "NaN");
        for x in [f64::MAX, f64::MIN_POSITIVE, 9.999e15, 1.234_567_890_123e-5] {
            let shown = number(x).to_string();
            assert!(shown.len() <= 26, "{shown}");
        }
    }

    #[test]
    fn bytes_that_are_not_text_are_shown_lossily_and_bounded() {
        let bytes = vec![0xff_u8; 10_000];
        let shown = excerpt_bytes(&bytes);
        assert!(shown.len() < 400, "{shown}");
        assert!(shown.ends_with("(10000 bytes)"), "{shown}");
    }
}
