//! The 33-byte attachment rmw_zenoh puts on every sample, query and reply
//! (`attachment_helpers.cpp`, written with zenoh-ext's serializer): the sequence number
//! (i64 little-endian, from 1 per publisher or client), the source timestamp (i64
//! little-endian, nanoseconds since the epoch), the GID's length as a one-byte LEB128
//! (always 16, so `0x10`), and the 16-byte GID. A reply carries the request's sequence
//! number and the client's GID back. rmw_zenoh drops a sample without one.

/// The attachment's size on the wire.
pub const LEN: usize = 33;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Attachment {
    pub sequence_number: i64,
    pub source_timestamp_ns: i64,
    pub gid: [u8; 16],
}

/// Why bytes are not an attachment.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum AttachmentError {
    #[error("{0} bytes; rmw_zenoh's attachment is 33 (sequence number, timestamp, GID)")]
    Length(usize),
    #[error("the GID length byte is {0}, not 16")]
    GidLength(u8),
}

impl Attachment {
    pub fn to_bytes(&self) -> [u8; LEN] {
        let mut out = [0u8; LEN];
        out[..8].copy_from_slice(&self.sequence_number.to_le_bytes());
        out[8..16].copy_from_slice(&self.source_timestamp_ns.to_le_bytes());
        out[16] = 16;
        out[17..].copy_from_slice(&self.gid);
        out
    }

    pub fn parse(bytes: &[u8]) -> Result<Attachment, AttachmentError> {
        let bytes: &[u8; LEN] = bytes
            .try_into()
            .map_err(|_| AttachmentError::Length(bytes.len()))?;
        if bytes[16] != 16 {
            return Err(AttachmentError::GidLength(bytes[16]));
        }
        let mut seq = [0u8; 8];
        seq.copy_from_slice(&bytes[..8]);
        let mut ts = [0u8; 8];
        ts.copy_from_slice(&bytes[8..16]);
        let mut gid = [0u8; 16];
        gid.copy_from_slice(&bytes[17..]);
        Ok(Attachment {
            sequence_number: i64::from_le_bytes(seq),
            source_timestamp_ns: i64::from_le_bytes(ts),
            gid,
        })
    }
}

/// Nanoseconds since the epoch now (0 before 1970, the maximum after 2262).
pub fn now_ns() -> i64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| i64::try_from(d.as_nanos()).unwrap_or(i64::MAX))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_layout_is_rmw_zenoh_s() {
        let a = Attachment {
            sequence_number: 1,
            source_timestamp_ns: 0x0102_0304_0506_0708,
            gid: [0xab; 16],
        };
        let bytes = a.to_bytes();
        assert_eq!(&bytes[..8], &[1, 0, 0, 0, 0, 0, 0, 0]);
        assert_eq!(&bytes[8..16], &[8, 7, 6, 5, 4, 3, 2, 1]);
        assert_eq!(bytes[16], 0x10);
        assert_eq!(Attachment::parse(&bytes), Ok(a));
        assert_eq!(
            Attachment::parse(&bytes[..32]),
            Err(AttachmentError::Length(32))
        );
        let mut bad = bytes;
        bad[16] = 15;
        assert_eq!(Attachment::parse(&bad), Err(AttachmentError::GidLength(15)));
    }
}
