//! Request ids and cancel tokens: unguessable ids for requests that bring none, the
//! check of a client's secret `cancel_token`, and the constant-time comparison that
//! decides whether a cancel comes from the requester.
//!
//! Progress keys (`<root>/planner/progress/<request_id>`) are public, so an id is not a
//! secret: anyone subscribed to `progress/*` sees every id in flight. What proves a
//! cancel comes from the requester is the token, which only the requester and the
//! planner ever hold (the planner never logs it nor echoes it in an error).

use rand::Rng;

/// Shortest cancel token accepted, in characters (with 64 symbols, 16 characters are
/// 96 bits).
pub const MIN_TOKEN_LEN: usize = 16;
/// Longest cancel token accepted, in characters.
pub const MAX_TOKEN_LEN: usize = 128;

/// 128 random bits as 32 lowercase hex characters: a request id the planner makes up,
/// or a cancel token a roam client makes up.
///
/// Drawn from `rand::rng()`, a cryptographically secure generator seeded from the
/// operating system. This is deliberately not one of the planner's algorithmic random
/// choices, which all take their seed from the request so that plans repeat bit for
/// bit (DESIGN.md): an id must be unguessable, not reproducible, and no plan depends on
/// it.
pub fn random_hex128() -> String {
    format!("{:032x}", rand::rng().random::<u128>())
}

/// Why a cancel token was refused. The message never contains the token itself.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TokenError {
    #[error("cancel_token has {0} characters; use {MIN_TOKEN_LEN} to {MAX_TOKEN_LEN} (e.g. 32 hex characters of 16 random bytes)")]
    Length(usize),
    #[error("cancel_token has a character outside a-z, A-Z, 0-9, '-' and '_' at position {0}; use only those (e.g. hex of random bytes)")]
    Alphabet(usize),
}

/// Checks a client's cancel token: [`MIN_TOKEN_LEN`] to [`MAX_TOKEN_LEN`] characters
/// from a-z, A-Z, 0-9, '-' and '_' (hex and URL-safe base64 both fit).
pub fn check_token(token: &str) -> Result<(), TokenError> {
    let len = token.chars().count();
    if !(MIN_TOKEN_LEN..=MAX_TOKEN_LEN).contains(&len) {
        return Err(TokenError::Length(len));
    }
    match token
        .bytes()
        .position(|b| !(b.is_ascii_alphanumeric() || b == b'-' || b == b'_'))
    {
        Some(at) => Err(TokenError::Alphabet(at)),
        None => Ok(()),
    }
}

/// Whether `given` equals `expected`, in time that depends only on their lengths: the
/// bytes are combined without an early exit, so the time a comparison takes says
/// nothing about how many leading characters were right. Tokens of another length fail
/// at once; the length of a token is not secret (it is bounded and a client's choice).
pub fn tokens_match(expected: &str, given: &str) -> bool {
    let (a, b) = (expected.as_bytes(), given.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let difference = a.iter().zip(b).fold(0u8, |acc, (x, y)| acc | (x ^ y));
    std::hint::black_box(difference) == 0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn random_ids_are_32_hex_characters_and_distinct() {
        let ids: std::collections::BTreeSet<String> = (0..1000).map(|_| random_hex128()).collect();
        assert_eq!(ids.len(), 1000);
        for id in &ids {
            assert_eq!(id.len(), 32);
            assert!(id
                .bytes()
                .all(|b| b.is_ascii_hexdigit() && !b.is_ascii_uppercase()));
            // A made-up id is a valid key segment and a valid token.
            assert!(roam_proto::keys::check_name("request id", id).is_ok());
            assert!(check_token(id).is_ok());
        }
    }

    #[test]
    fn tokens_are_checked_for_length_and_alphabet() {
        assert_eq!(check_token(&"a".repeat(15)), Err(TokenError::Length(15)));
        assert_eq!(check_token(&"a".repeat(129)), Err(TokenError::Length(129)));
        assert_eq!(check_token(""), Err(TokenError::Length(0)));
        assert!(check_token(&"a".repeat(16)).is_ok());
        assert!(check_token(&"Z9-_".repeat(32)).is_ok());
        assert_eq!(
            check_token("abcdefgh/ijklmnop"),
            Err(TokenError::Alphabet(8))
        );
        assert_eq!(
            check_token("abcdefghijklmnop "),
            Err(TokenError::Alphabet(16))
        );
        // Sixteen multi-byte characters are sixteen characters, but not the alphabet.
        assert_eq!(check_token(&"é".repeat(16)), Err(TokenError::Alphabet(0)));
        // The message never repeats the token.
        let secret = "s3cret!s3cret!s3cret!";
        let message = check_token(secret).expect_err("refused").to_string();
        assert!(!message.contains("s3cret"), "{message}");
    }

    #[test]
    fn only_the_same_token_matches() {
        let token = "0123456789abcdef0123456789abcdef";
        assert!(tokens_match(token, token));
        assert!(!tokens_match(token, "0123456789abcdef0123456789abcdee"));
        assert!(!tokens_match(token, "1123456789abcdef0123456789abcdef"));
        assert!(!tokens_match(token, &token[..31]));
        assert!(!tokens_match(token, ""));
    }
}
