//! What the view takes from the wire, bounded before it is read and escaped before it is
//! shown.
//!
//! Anyone who can put on the stack's root can publish on the keys the view follows, so
//! nothing from there is trusted: each payload's length is checked against its kind's cap
//! *before* it is decoded (a 60 MB mission is dropped unread, never parsed), and every
//! string from a message that reaches a log line or a Foxglove name or label goes through
//! [`shown`] (a short escaped prefix and the length), so a name with a newline or an ANSI
//! escape cannot forge log lines or recolour a terminal.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

use roam_map_server::store::DEFAULT_LIMITS;
use roam_proto::excerpt::excerpt_n;
use roam_proto::{decode, DecodeError, ErrorReply, Message};
use zenoh::bytes::ZBytes;
use zenoh::Session;

/// Characters of a string from the wire that are shown (escaped) before it is cut.
pub const SHOWN_CHARS: usize = roam_proto::excerpt::MAX_EXCERPT_CHARS;
/// Characters of an error's text that are logged (its control characters escaped).
const CLIPPED_CHARS: usize = 256;

/// Room for a message's envelope and its fields other than the bulk (names, ids,
/// numbers).
const ENVELOPE_BYTES: usize = 64 * 1024;

/// The largest mission payload read: the controller's own limit (a mission of
/// `MAX_WAYPOINTS` waypoints at their longest). A larger one cannot be a mission any
/// controller drives.
pub use roam_proto::controller::MAX_MISSION_BYTES;
/// The largest position estimate read (a robot, numbers and the anchors used).
pub const MAX_ESTIMATE_BYTES: usize = 64 * 1024;
/// The largest true position read (a robot name and four numbers).
pub const MAX_TRUTH_BYTES: usize = 4 * 1024;
/// The largest layer read: the map server's `max_layer_cells` (16,777,216) of its widest
/// cell type (f32), as the base64 the codec sends them in, and the envelope (about 90 MB).
pub const MAX_LAYER_BYTES: usize =
    base64_len(DEFAULT_LIMITS.max_layer_cells as usize * 4) + ENVELOPE_BYTES;
/// The largest layer index read (the map server holds at most `max_layers`, 64).
pub const MAX_LAYER_LIST_BYTES: usize = 256 * 1024;
/// The largest sim status read (its robots and anchors).
pub const MAX_SIM_STATUS_BYTES: usize = 1024 * 1024;
/// The largest error reply read.
const MAX_ERROR_REPLY_BYTES: usize = 16 * 1024;

const fn base64_len(bytes: usize) -> usize {
    bytes.div_ceil(3) * 4
}

/// A string from the wire as it may appear in a log line or a Foxglove name or label:
/// its first [`SHOWN_CHARS`] characters with [`char::escape_debug`] (newlines, escapes,
/// quotes and invisible characters written out), then `… (N bytes)` when it is longer.
/// A name that is a valid key segment is shown unchanged.
pub fn shown(text: &str) -> String {
    excerpt_n(text, SHOWN_CHARS).to_string()
}

/// An error's text (which may quote what it failed on) as it may appear in a log line:
/// control characters escaped, cut at 256 characters.
pub fn clipped(text: &str) -> String {
    excerpt_n(text, CLIPPED_CHARS).to_string()
}

/// Lets the first few warnings of a kind through, then every thousandth, so a stream of
/// bad input cannot flood the log; the others go to debug.
#[derive(Debug, Default)]
pub(crate) struct Throttle(AtomicU64);

impl Throttle {
    /// Counts one more; returns the count and whether to warn about this one.
    pub(crate) fn count(&self) -> (u64, bool) {
        let n = self.0.fetch_add(1, Ordering::Relaxed) + 1;
        (n, n <= 10 || n.is_multiple_of(1000))
    }

    pub(crate) fn total(&self) -> u64 {
        self.0.load(Ordering::Relaxed)
    }
}

/// Why a payload from the wire was not used.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum WireError {
    /// Dropped unread: longer than its kind's cap.
    #[error("{bytes} bytes; a '{kind}' payload is read only up to {max} bytes")]
    TooLarge {
        kind: &'static str,
        bytes: usize,
        max: usize,
    },
    #[error(transparent)]
    Decode(#[from] DecodeError),
    #[error("the service refused: {0}")]
    Refused(String),
    #[error("no reply within {0:?}")]
    NoReply(Duration),
    #[error("zenoh: {0}")]
    Zenoh(String),
}

/// Decodes `payload` as a `T` when it is at most `max` bytes long; a longer one is
/// refused before any byte of it is read.
pub(crate) fn decode_bounded<T: Message>(payload: &ZBytes, max: usize) -> Result<T, WireError> {
    let bytes = payload.len();
    if bytes > max {
        return Err(WireError::TooLarge {
            kind: T::KIND,
            bytes,
            max,
        });
    }
    Ok(decode::<T>(&payload.to_bytes())?)
}

/// Sends a `get` on `key` (with `request` as its payload) and decodes the first reply as
/// an `R` of at most `max` bytes. The reply is checked like a published payload: a service
/// answering on the stack's keys is no more trusted than a publisher.
pub(crate) async fn query<Q: Message, R: Message>(
    session: &Session,
    key: &str,
    request: Option<&Q>,
    max: usize,
    timeout: Duration,
) -> Result<R, WireError> {
    let mut get = session.get(key).timeout(timeout);
    if let Some(request) = request {
        get = get.payload(roam_proto::encode(request));
    }
    let replies = get.await.map_err(|e| WireError::Zenoh(e.to_string()))?;
    // Zenoh ends the reply stream at its own timeout; this one guards against a hang.
    let reply = tokio::time::timeout(timeout + Duration::from_secs(1), replies.recv_async())
        .await
        .ok()
        .and_then(Result::ok)
        .ok_or(WireError::NoReply(timeout))?;
    match reply.result() {
        Ok(sample) => decode_bounded::<R>(sample.payload(), max),
        Err(error) => {
            let refusal = decode_bounded::<ErrorReply>(error.payload(), MAX_ERROR_REPLY_BYTES)?;
            Err(WireError::Refused(clipped(&refusal.to_string())))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_proto::controller::Mission;
    use roam_proto::controller::MAX_WAYPOINTS;
    use roam_proto::encode;

    #[test]
    fn shown_text_is_escaped_and_cut() {
        assert_eq!(
            shown("robot-1_a"),
            "robot-1_a",
            "a key segment is unchanged"
        );
        let evil = "r1\n2026-01-01 INFO forged\u{1b}[31m";
        let s = shown(evil);
        assert!(!s.contains('\n') && !s.contains('\u{1b}'), "{s}");
        assert!(s.contains("\\n") && s.contains("\\u{1b}"), "{s}");
        let long = "x".repeat(1_000_000);
        let s = shown(&long);
        assert_eq!(s, format!("{}… (1000000 bytes)", "x".repeat(SHOWN_CHARS)));
        // Escaping counts characters, not bytes: a 64-character prefix, never a cut char.
        let wide = "é".repeat(100);
        assert!(shown(&wide).starts_with(&"é".repeat(SHOWN_CHARS)));
        assert!(shown(&wide).ends_with("(200 bytes)"));
    }

    #[test]
    fn clipped_text_keeps_quotes_but_not_control_characters() {
        let s = clipped("invalid type: string \"a\u{1b}[2Jb\"\r\n");
        assert_eq!(s, "invalid type: string \"a\\u{1b}[2Jb\"\\r\\n");
        assert!(clipped(&"y".repeat(10_000)).ends_with("(10000 bytes)"));
    }

    #[test]
    fn the_longest_mission_the_controller_takes_fits_the_mission_cap() {
        let extreme = -2.225_073_858_507_201_4e-308;
        let mission = Mission {
            after_step: None,
            robot: "r".repeat(roam_proto::keys::MAX_SEGMENT_LEN),
            id: "i".repeat(roam_proto::controller::MAX_MISSION_ID_BYTES),
            waypoints: vec![[extreme, extreme]; MAX_WAYPOINTS],
            recovery: false,
        };
        let bytes = encode(&mission);
        assert!(bytes.len() <= MAX_MISSION_BYTES, "{}", bytes.len());
        let decoded: Mission = decode_bounded(&ZBytes::from(bytes), MAX_MISSION_BYTES)
            .expect("a maximal mission is read");
        assert_eq!(decoded.waypoints.len(), MAX_WAYPOINTS);
    }

    #[test]
    fn a_payload_over_its_cap_is_refused_unread() {
        // Not JSON at all: were it read, the error would be a decode error.
        let payload = ZBytes::from(vec![0xffu8; MAX_TRUTH_BYTES + 1]);
        let refused = decode_bounded::<roam_proto::sim::GroundTruth>(&payload, MAX_TRUTH_BYTES);
        assert_eq!(
            refused,
            Err(WireError::TooLarge {
                kind: "ground_truth",
                bytes: MAX_TRUTH_BYTES + 1,
                max: MAX_TRUTH_BYTES
            })
        );
        let short = ZBytes::from(vec![0xffu8; 16]);
        assert!(matches!(
            decode_bounded::<roam_proto::sim::GroundTruth>(&short, MAX_TRUTH_BYTES),
            Err(WireError::Decode(_))
        ));
    }

    #[test]
    fn the_layer_cap_holds_a_full_size_f32_layer() {
        // 16,777,216 f32 cells are 64 MiB, 89,478,488 bytes of base64.
        assert_eq!(base64_len(64 << 20), 89_478_488);
        assert_eq!(MAX_LAYER_BYTES, 89_478_488 + ENVELOPE_BYTES);
    }
}
