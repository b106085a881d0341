//! Seeded random streams: every random choice in roam draws from one of these.
//!
//! - [`stream`]: ChaCha8 keyed by a seed, on one of ChaCha's 2⁶⁴ independent streams
//!   picked by a label (`"world"`, `"robot/<name>"`, `"explorer/goals"`, …). Each
//!   consumer draws only from its own stream, so adding a consumer (a robot, a kind of
//!   draw) changes no other consumer's numbers.
//! - [`derive`] and [`labelled`]: a run's seed from a base seed and the run's place (a
//!   path of numbers, or a label such as `"es1/0/7"`), so a run's noise never depends on
//!   which other runs exist or the order they run in. The experiments leave the compared
//!   variant out of the place on purpose: every variant meets the same noise (common
//!   random numbers).
//!
//! Hashes are FNV-1a and SplitMix64, written out here rather than taken from `std`,
//! whose hashers may change between Rust releases and would change every stream.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// The stream `label` under `seed`.
pub fn stream(seed: u64, label: &str) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(fnv1a(label.as_bytes()));
    rng
}

/// A seed derived from a base seed and a path of numbers (mode, repetition, …): a
/// SplitMix64 chain, so nearby inputs give unrelated seeds.
pub fn derive(base: u64, path: &[u64]) -> u64 {
    path.iter()
        .fold(splitmix64(base), |h, &x| splitmix64(h ^ splitmix64(x)))
}

/// A seed derived from a base seed and a label (`"es1/0/7"`: experiment, mission, run).
pub fn labelled(base: u64, label: &str) -> u64 {
    splitmix64(base ^ fnv1a(label.as_bytes()))
}

/// 64-bit FNV-1a: a stable hash of bytes.
pub fn fnv1a(bytes: &[u8]) -> u64 {
    fnv1a_extend(FNV1A_OFFSET, bytes)
}

/// FNV-1a's starting value: `fnv1a_extend(FNV1A_OFFSET, b)` is `fnv1a(b)`.
pub const FNV1A_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

/// FNV-1a of what `hash` covered followed by `bytes`: hashes a concatenation piece by
/// piece, without building it.
pub fn fnv1a_extend(hash: u64, bytes: &[u8]) -> u64 {
    bytes.iter().fold(hash, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// SplitMix64's finaliser: spreads nearby inputs over the whole range.
pub fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngCore;

    #[test]
    fn streams_are_reproducible_and_distinct() {
        assert_eq!(stream(7, "a").next_u64(), stream(7, "a").next_u64());
        assert_ne!(stream(7, "a").next_u64(), stream(7, "b").next_u64());
        assert_ne!(stream(7, "a").next_u64(), stream(8, "a").next_u64());
        assert_eq!(derive(1, &[2, 3]), derive(1, &[2, 3]));
        assert_ne!(derive(1, &[2, 3]), derive(1, &[3, 2]));
        assert_ne!(derive(1, &[0]), derive(1, &[]));
        assert_ne!(labelled(1, "es1/0/0"), labelled(1, "es1/0/1"));
    }

    /// The published test vectors: a change to either hash would change every stream.
    #[test]
    fn the_hashes_are_the_published_ones() {
        assert_eq!(fnv1a(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a(b"foobar"), 0x8594_4171_f739_67e8);
        // SplitMix64 seeded with 0: its first output is splitmix64(0).
        assert_eq!(splitmix64(0), 0xe220_a839_7b1d_cdaf);
    }
}
