//! Bounded echo of untrusted strings: what a request sent (a request id, a layer name)
//! goes into log lines and error messages only as a short escaped prefix plus its
//! length, so a megabyte id cannot come back a megabyte long, nor a control character
//! reach a terminal raw.
//!
//! The planner's own helper for now; proto is getting a shared one, and this module is
//! the only place to swap.

/// Characters of an untrusted string that an excerpt keeps.
pub const EXCERPT_CHARS: usize = 64;

/// `text` escaped (`escape_debug`: quotes, backslashes, control and non-printable
/// characters written as escapes), cut to its first [`EXCERPT_CHARS`] characters; a cut
/// string ends with `… (N bytes)`, N the original length.
pub fn excerpt(text: &str) -> String {
    let mut out: String = text
        .chars()
        .take(EXCERPT_CHARS)
        .flat_map(char::escape_debug)
        .collect();
    if text.chars().nth(EXCERPT_CHARS).is_some() {
        out.push_str(&format!("… ({} bytes)", text.len()));
    }
    out
}

/// The longest message [`bound_message`] lets through unchanged, in bytes.
pub const MAX_MESSAGE_BYTES: usize = 512;

/// A message built elsewhere from untrusted input (a decoder's error that quotes the
/// payload), bounded: kept whole up to [`MAX_MESSAGE_BYTES`], otherwise its head and
/// tail (where a decoder says what it expected) around `… (N bytes cut) …`.
pub fn bound_message(message: &str) -> String {
    if message.len() <= MAX_MESSAGE_BYTES {
        return message.to_owned();
    }
    let keep = MAX_MESSAGE_BYTES / 2;
    let head_end = floor_char_boundary(message, keep);
    let tail_start = ceil_char_boundary(message, message.len() - keep / 2);
    format!(
        "{} … ({} bytes cut) … {}",
        &message[..head_end],
        tail_start - head_end,
        &message[tail_start..]
    )
}

fn floor_char_boundary(s: &str, mut i: usize) -> usize {
    while i > 0 && !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

fn ceil_char_boundary(s: &str, mut i: usize) -> usize {
    while i < s.len() && !s.is_char_boundary(i) {
        i += 1;
    }
    i
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_short_string_is_kept_and_escaped() {
        assert_eq!(excerpt("trip-42"), "trip-42");
        assert_eq!(excerpt("a\nb\"c"), "a\\nb\\\"c");
        assert_eq!(excerpt(""), "");
    }

    #[test]
    fn a_long_string_is_cut_with_its_length() {
        let id = "x".repeat(1 << 20);
        let cut = excerpt(&id);
        assert_eq!(cut, format!("{}… (1048576 bytes)", "x".repeat(64)));
        // Exactly the limit is not cut.
        assert_eq!(excerpt(&"y".repeat(64)), "y".repeat(64));
        // Multi-byte characters are counted as characters, the length in bytes.
        let wide = "é".repeat(100);
        assert_eq!(excerpt(&wide), format!("{}… (200 bytes)", "é".repeat(64)));
    }

    #[test]
    fn a_long_message_keeps_its_head_and_tail() {
        let message = format!(
            "unknown variant `{}`, expected one of `a`, `b`",
            "é".repeat(10_000)
        );
        let bounded = bound_message(&message);
        assert!(bounded.len() < MAX_MESSAGE_BYTES + 64, "{}", bounded.len());
        assert!(bounded.starts_with("unknown variant `"));
        assert!(bounded.ends_with("expected one of `a`, `b`"));
        assert!(bounded.contains("bytes cut"));
        assert_eq!(bound_message("short"), "short");
    }
}
