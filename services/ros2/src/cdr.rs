//! CDR payloads as rmw_zenoh sends them: a 4-byte encapsulation header (`00 01 00 00`,
//! CDR little-endian; `00 00` is big-endian) and the message in plain CDR (XCDR1),
//! aligned from the byte after the header.
//!
//! The encoding itself is `cdr-encoding` (RustDDS's serde codec): a maintained crate of
//! about 2,000 lines whose dependencies roam already builds but one small macro crate.
//! Decoding from the wire never trusts a length: a payload is refused over its kind's cap
//! before it is read, and a sequence's claimed length only ever grows the vector as its
//! elements are really read (the codec gives serde no size hint), so a 12-byte payload
//! claiming four billion cells fails at its end without allocating them.

use byteorder::{BigEndian, LittleEndian};
use cdr_encoding as codec;
use serde::{de::DeserializeOwned, Serialize};

/// The encapsulation header of CDR little-endian, the one rmw_zenoh writes.
pub const CDR_LE: [u8; 4] = [0x00, 0x01, 0x00, 0x00];
/// The encapsulation header of CDR big-endian (read, never written).
pub const CDR_BE: [u8; 4] = [0x00, 0x00, 0x00, 0x00];

/// Why a payload was not decoded.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CdrError {
    #[error("{bytes} bytes; a {what} payload is read only up to {max} bytes")]
    TooLarge {
        what: &'static str,
        bytes: usize,
        max: usize,
    },
    #[error("{bytes} bytes: too short for the 4-byte CDR encapsulation header")]
    NoHeader { bytes: usize },
    #[error("encapsulation {0:02x?} is not CDR (00 01 little-endian or 00 00 big-endian)")]
    Encapsulation([u8; 2]),
    #[error("not a valid {what}: {reason}")]
    Invalid { what: &'static str, reason: String },
    #[error("{what}: {extra} bytes after the message")]
    Trailing { what: &'static str, extra: usize },
    #[error("could not encode: {0}")]
    Encode(String),
}

/// Encodes `message` with the little-endian encapsulation header.
pub fn encode<T: Serialize>(message: &T) -> Result<Vec<u8>, CdrError> {
    let body =
        codec::to_vec::<T, LittleEndian>(message).map_err(|e| CdrError::Encode(e.to_string()))?;
    let mut out = Vec::with_capacity(4 + body.len());
    out.extend_from_slice(&CDR_LE);
    out.extend_from_slice(&body);
    Ok(out)
}

/// Decodes the first fields of a payload as a `T` (a message's head, e.g. a map's header
/// and size, read before its cells), ignoring what follows them.
pub fn decode_prefix<T: DeserializeOwned>(
    payload: &[u8],
    what: &'static str,
) -> Result<T, CdrError> {
    decode_inner(payload, what, usize::MAX).map(|(message, _)| message)
}

/// Decodes a `T` (named `what` in errors) from a payload of at most `max` bytes. Up to 3
/// bytes of padding may follow the message (CDR writers pad to 4); more is refused.
pub fn decode<T: DeserializeOwned>(
    payload: &[u8],
    what: &'static str,
    max: usize,
) -> Result<T, CdrError> {
    let (message, extra) = decode_inner(payload, what, max)?;
    if extra > 3 {
        return Err(CdrError::Trailing { what, extra });
    }
    Ok(message)
}

/// Decodes a `T` and says how many bytes followed it.
fn decode_inner<T: DeserializeOwned>(
    payload: &[u8],
    what: &'static str,
    max: usize,
) -> Result<(T, usize), CdrError> {
    if payload.len() > max {
        return Err(CdrError::TooLarge {
            what,
            bytes: payload.len(),
            max,
        });
    }
    let Some((header, body)) = payload.split_first_chunk::<4>() else {
        return Err(CdrError::NoHeader {
            bytes: payload.len(),
        });
    };
    let invalid = |e: codec::Error| CdrError::Invalid {
        what,
        reason: e.to_string(),
    };
    let (message, used) = match [header[0], header[1]] {
        [0x00, 0x01] => codec::from_bytes::<T, LittleEndian>(body).map_err(invalid)?,
        [0x00, 0x00] => codec::from_bytes::<T, BigEndian>(body).map_err(invalid)?,
        other => return Err(CdrError::Encapsulation(other)),
    };
    Ok((message, body.len() - used.min(body.len())))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msg::*;

    #[test]
    fn a_header_is_aligned_after_the_encapsulation() {
        let header = Header {
            stamp: Time { sec: 1, nanosec: 2 },
            frame_id: "map".into(),
        };
        let bytes = encode(&header).expect("encode");
        assert_eq!(
            bytes,
            [
                0, 1, 0, 0, // encapsulation
                1, 0, 0, 0, 2, 0, 0, 0, // stamp
                4, 0, 0, 0, b'm', b'a', b'p', 0 // frame_id with its NUL
            ]
        );
        assert_eq!(decode::<Header>(&bytes, "header", 1024), Ok(header));
    }

    #[test]
    fn bad_payloads_are_refused_with_a_reason() {
        let grid = OccupancyGrid {
            data: vec![0, 100, -1],
            ..OccupancyGrid::default()
        };
        let bytes = encode(&grid).expect("encode");
        for cut in [0, 3, 10, bytes.len() - 2] {
            assert!(
                decode::<OccupancyGrid>(&bytes[..cut], "map", 1 << 20).is_err(),
                "cut at {cut}"
            );
        }
        assert!(matches!(
            decode::<OccupancyGrid>(&bytes, "map", 8),
            Err(CdrError::TooLarge { max: 8, .. })
        ));
        let mut xcdr2 = bytes.clone();
        xcdr2[1] = 0x07;
        assert_eq!(
            decode::<OccupancyGrid>(&xcdr2, "map", 1 << 20),
            Err(CdrError::Encapsulation([0x00, 0x07]))
        );
        // A sequence claiming four billion cells, in a short payload: refused, not allocated.
        let mut liar = bytes.clone();
        let n = liar.len();
        liar[n - 7..n - 3].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(decode::<OccupancyGrid>(&liar, "map", 1 << 20).is_err());
        let mut long = bytes.clone();
        long.extend_from_slice(&[0; 8]);
        assert!(matches!(
            decode::<OccupancyGrid>(&long, "map", 1 << 20),
            Err(CdrError::Trailing { .. })
        ));
    }
}
