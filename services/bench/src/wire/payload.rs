//! What goes over the wire: the bench's keys, and payloads that carry their sequence
//! number.

use super::{Operation, MIN_PAYLOAD_BYTES};

/// The key the bench uses for `operation`, the same in every topology (each has its own
/// sessions and router). `put`: the sender publishes, the receiver subscribes; payload:
/// the sequence number (little-endian u64), then zeros to the payload size. `get`: the
/// receiver answers; query: the sequence number and the reply's size (little-endian u64
/// each); reply: as a put's payload.
pub(super) fn key(operation: Operation) -> &'static str {
    match operation {
        Operation::Put => "roam-bench-wire/put",
        Operation::Get => "roam-bench-wire/get",
    }
}

/// A payload of `bytes` bytes carrying `seq`.
pub(super) fn payload(seq: u64, bytes: usize) -> Vec<u8> {
    let mut out = vec![0u8; bytes.max(MIN_PAYLOAD_BYTES)];
    out[..8].copy_from_slice(&seq.to_le_bytes());
    out
}

/// The sequence number a payload carries, if it is long enough to carry one.
pub(super) fn seq_of(bytes: &[u8]) -> Option<u64> {
    Some(u64::from_le_bytes(bytes.get(..8)?.try_into().ok()?))
}
