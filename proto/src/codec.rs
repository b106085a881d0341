//! The codec: one `encode` / `decode` pair for every message.
//!
//! On the wire a message is a JSON object `{"v": 1, "kind": "<kind>", "body": {...}}`.
//! `v` is [`PROTOCOL_VERSION`]; a different one is refused before the body is read, so a
//! newer client gets "unsupported version" rather than a confusing field error. `kind`
//! names the message type, so a payload sent to the wrong key is refused by name.
//! Anything after the closing brace other than whitespace is refused. What a refusal
//! quotes of the payload (the kind, the parser's complaint) is a bounded, escaped
//! [`excerpt`](crate::excerpt), so a huge or forged field never comes back whole.
//!
//! Grid cells travel inside the JSON as base64 of their little-endian bytes (see
//! [`crate::cells`]): a 1.7-million-cell layer is 2.3 MB and decodes in milliseconds,
//! where a JSON array of numbers would be four times larger and ten times slower.

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use serde_json::value::RawValue;

use crate::excerpt::{excerpt, parser_reason};

/// The protocol version every roam message carries.
pub const PROTOCOL_VERSION: u32 = 1;

/// A message type of the protocol. `KIND` is its name on the wire.
pub trait Message: Serialize + DeserializeOwned {
    const KIND: &'static str;
}

#[derive(Serialize)]
struct EnvelopeOut<'a, T> {
    v: u32,
    kind: &'a str,
    body: &'a T,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EnvelopeIn<'a> {
    v: u32,
    kind: String,
    #[serde(borrow)]
    body: &'a RawValue,
}

/// Why a payload could not be decoded.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DecodeError {
    #[error("the payload is not a roam message ({0}); send {{\"v\": {PROTOCOL_VERSION}, \"kind\": ..., \"body\": ...}} as JSON")]
    Envelope(String),
    #[error(
        "protocol version {found} is not supported; this service speaks version {PROTOCOL_VERSION}"
    )]
    UnsupportedVersion { found: u32 },
    #[error("expected a '{expected}' message but got '{found}'")]
    WrongKind {
        expected: &'static str,
        found: String,
    },
    #[error("the '{kind}' message body is invalid: {reason}")]
    Body { kind: &'static str, reason: String },
}

/// Encodes a message with the protocol envelope.
pub fn encode<T: Message>(message: &T) -> Vec<u8> {
    let envelope = EnvelopeOut {
        v: PROTOCOL_VERSION,
        kind: T::KIND,
        body: message,
    };
    // Serializing plain structs of strings, numbers and maps with string keys cannot fail.
    serde_json::to_vec(&envelope).unwrap_or_else(|e| {
        format!("{{\"v\":{PROTOCOL_VERSION},\"kind\":\"error\",\"body\":{{\"code\":\"internal\",\"message\":\"encode failed: {e}\"}}}}").into_bytes()
    })
}

/// Decodes a message, refusing other protocol versions, other kinds and trailing bytes.
pub fn decode<T: Message>(bytes: &[u8]) -> Result<T, DecodeError> {
    let envelope: EnvelopeIn<'_> = serde_json::from_slice(bytes)
        .map_err(|e| DecodeError::Envelope(parser_reason(&e.to_string())))?;
    if envelope.v != PROTOCOL_VERSION {
        return Err(DecodeError::UnsupportedVersion { found: envelope.v });
    }
    if envelope.kind != T::KIND {
        return Err(DecodeError::WrongKind {
            expected: T::KIND,
            found: excerpt(&envelope.kind).to_string(),
        });
    }
    serde_json::from_str(envelope.body.get()).map_err(|e| DecodeError::Body {
        kind: T::KIND,
        reason: parser_reason(&e.to_string()),
    })
}
