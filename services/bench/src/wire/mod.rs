//! `roam bench wire`: the wire's own latency, so that a fleet is sized from
//! figures measured on its own machines instead of guessed.
//!
//! Two Zenoh sessions in this process, a *sender* and a *receiver*, meet on loopback in
//! four topologies ([`Topology`]): peer to peer and through a roam router
//! ([`Router`], as `roam router` runs one), each over TCP and over TLS. In each, for
//! every payload size:
//! - `put`: the sender's publisher puts a sample (`Block` congestion control, as roam
//!   sends what a subscriber must not miss) and the receiver's subscriber reads it from
//!   Zenoh's FIFO channel in an async task, as roam's services read theirs; the time is
//!   from just before the put to the subscriber's task holding the sample;
//! - `get`: the sender's `get` (a 16-byte query: the sequence number and the size
//!   wanted) to a queryable on the receiver, which answers with a reply of the payload
//!   size; the time is from just before the `get` to the sender holding the reply, read
//!   as [`roam_runtime::Requester`] reads it (the first reply from Zenoh's channel, with
//!   Zenoh's default consolidation, which hands a reply over when the query ends).
//!
//! One sample at a time (the latency of an idle wire, not its throughput), each matched
//! by its sequence number; [`WARMUP`] samples first, measured and thrown away (the
//! first ones pay for connections and buffers). The sender and receiver share the
//! process, so one clock times both ends and no clock sync is needed; they also share
//! its cores with each other and, through a router, with the router, as they would on
//! one small machine. No serialization is timed: payloads are raw bytes. The sessions
//! are built as every roam session is ([`SessionArgs`]), so a `ZENOH_CONFIG` in the
//! environment applies to them too (to measure a site's own transport settings).
//!
//! **TLS.** The TLS certificates are a throwaway P-256 CA and a certificate for
//! `localhost` / `127.0.0.1` it signs, made at bench time in a temporary directory with
//! the openssl CLI, as `deploy/secure/make-secrets.sh` makes a site's (the workspace has
//! no certificate-making crate); the TLS rows need `openssl` on the `PATH`. The side that
//! listens (the router, or the receiving peer) holds the certificate, the side that
//! connects checks it against the CA, as in `deploy/secure/`. Peer to peer over TLS
//! works in Zenoh 1.x like over TCP: the receiving peer listens on `tls/…` with the
//! certificate and the sender connects with the CA. Not measured: the secure site's
//! user/password authentication and access control, which the router checks per
//! message on top of TLS.
//!
//! [`Router`]: roam_stack::router::Router
//! [`SessionArgs`]: roam_runtime::SessionArgs

mod measure;
mod payload;
mod sessions;
mod tls;
mod topology;

use serde::Serialize;

use crate::{setup, BenchError};
use sessions::Wire;
use tls::Certs;
pub use topology::{Operation, Topology};

/// Samples per topology, operation and payload size when none are given.
pub const DEFAULT_SAMPLES: usize = 500;
/// The most samples a row takes: they go one at a time, so at 1.5 ms each (a 64 KiB
/// get through a router here) 100,000 take 2.5 minutes a row.
pub const MAX_SAMPLES: usize = 100_000;
/// The payload sizes when none are given, bytes: a small message (a command, an
/// estimate) and a large one (a plan, a small layer).
pub const DEFAULT_PAYLOADS: [usize; 2] = [64, 64 * 1024];
/// The smallest payload, bytes: the sequence number it carries.
pub const MIN_PAYLOAD_BYTES: usize = 8;
/// The largest payload, bytes (roam's own messages go larger; `roam bench map` times
/// a 1.7-million-cell layer).
pub const MAX_PAYLOAD_BYTES: usize = 4 * 1024 * 1024;
/// The most payload sizes a run takes.
pub const MAX_PAYLOADS: usize = 8;
/// Samples measured and thrown away before each row's.
pub const WARMUP: usize = 20;

/// One topology, operation and payload size.
#[derive(Debug, Clone, Serialize)]
pub struct WireRow {
    pub topology: Topology,
    pub operation: Operation,
    /// The put's payload, or the reply's.
    pub payload_bytes: usize,
    /// Samples timed (after the warm-up).
    pub samples: usize,
    /// Nearest-rank percentiles and the largest, milliseconds.
    pub p50_ms: f64,
    pub p99_ms: f64,
    pub max_ms: f64,
}

/// What `roam bench wire --json` prints.
#[derive(Debug, Clone, Serialize)]
pub struct WireBench {
    /// Samples per row, and the warm-up before each row's.
    pub samples: usize,
    pub warmup: usize,
    pub payloads: Vec<usize>,
    pub cores: usize,
    /// Topology by topology, each `put` then `get`, by payload size.
    pub rows: Vec<WireRow>,
}

/// Why a run cannot be measured; each names the flag and its limit.
#[derive(Debug, PartialEq, thiserror::Error)]
pub enum WireArgsError {
    #[error("--samples must be 1..={MAX_SAMPLES}, not {0}")]
    Samples(usize),
    #[error("--payloads: give 1 to {MAX_PAYLOADS} sizes, not {0}")]
    PayloadCount(usize),
    #[error("--payloads: {0} bytes is not in {MIN_PAYLOAD_BYTES}..={MAX_PAYLOAD_BYTES} (a payload carries its 8-byte sequence number)")]
    PayloadSize(usize),
}

/// Checks a run's arguments: 1 to [`MAX_SAMPLES`] samples, 1 to [`MAX_PAYLOADS`]
/// payload sizes, each [`MIN_PAYLOAD_BYTES`] to [`MAX_PAYLOAD_BYTES`].
pub fn check(samples: usize, payloads: &[usize]) -> Result<(), WireArgsError> {
    if samples == 0 || samples > MAX_SAMPLES {
        return Err(WireArgsError::Samples(samples));
    }
    if payloads.is_empty() || payloads.len() > MAX_PAYLOADS {
        return Err(WireArgsError::PayloadCount(payloads.len()));
    }
    match payloads
        .iter()
        .find(|&&b| !(MIN_PAYLOAD_BYTES..=MAX_PAYLOAD_BYTES).contains(&b))
    {
        Some(&bytes) => Err(WireArgsError::PayloadSize(bytes)),
        None => Ok(()),
    }
}

/// Runs the bench: every [`Topology`], both operations, every payload size, `samples`
/// each.
pub async fn wire(samples: usize, payloads: &[usize]) -> Result<WireBench, BenchError> {
    check(samples, payloads).map_err(setup)?;
    let certs = tokio::task::spawn_blocking(Certs::make)
        .await
        .map_err(setup)??;
    let mut rows = Vec::new();
    for topology in Topology::ALL {
        let wire = Wire::open(topology, &certs).await?;
        let measured = wire.measure(topology, samples, payloads).await;
        wire.close().await;
        rows.extend(measured?);
    }
    Ok(WireBench {
        samples,
        warmup: WARMUP,
        payloads: payloads.to_vec(),
        cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
        rows,
    })
}

#[cfg(test)]
mod tests {
    use super::measure::{row, SAMPLE_TIMEOUT};
    use super::payload::{payload, seq_of};
    use super::*;
    use std::time::Duration;

    #[test]
    fn a_run_outside_its_limits_is_refused_naming_them() {
        assert_eq!(check(DEFAULT_SAMPLES, &DEFAULT_PAYLOADS), Ok(()));
        assert_eq!(check(1, &[MIN_PAYLOAD_BYTES, MAX_PAYLOAD_BYTES]), Ok(()));
        for samples in [0, MAX_SAMPLES + 1] {
            let e = check(samples, &[64]).expect_err("refused");
            assert_eq!(e, WireArgsError::Samples(samples));
            assert!(e.to_string().contains(&format!("1..={MAX_SAMPLES}")), "{e}");
        }
        assert_eq!(check(10, &[]), Err(WireArgsError::PayloadCount(0)));
        let many = vec![64; MAX_PAYLOADS + 1];
        assert_eq!(
            check(10, &many),
            Err(WireArgsError::PayloadCount(MAX_PAYLOADS + 1))
        );
        for bytes in [0, MIN_PAYLOAD_BYTES - 1, MAX_PAYLOAD_BYTES + 1] {
            let e = check(10, &[64, bytes]).expect_err("refused");
            assert_eq!(e, WireArgsError::PayloadSize(bytes));
            assert!(
                e.to_string().contains(&MAX_PAYLOAD_BYTES.to_string()),
                "{e}"
            );
        }
    }

    #[test]
    fn a_rows_summary_is_read_off_its_samples() {
        let mut times: Vec<f64> = (1..=100).rev().map(f64::from).collect();
        let r = row(Topology::PeerTcp, Operation::Put, 64, &mut times);
        assert_eq!(r.samples, 100);
        // Nearest rank over 100 samples: index round(99 q).
        assert_eq!((r.p50_ms, r.p99_ms, r.max_ms), (51.0, 99.0, 100.0));
    }

    #[test]
    fn a_payload_carries_its_sequence_number_and_size() {
        let p = payload(0x0102_0304_0506_0708, 64);
        assert_eq!(p.len(), 64);
        assert_eq!(seq_of(&p), Some(0x0102_0304_0506_0708));
        assert_eq!(seq_of(&p[..7]), None);
    }

    /// A short real run: every topology, both operations, the samples asked for, and
    /// ordered percentiles. Needs the openssl CLI (as the access-control tests do).
    #[tokio::test(flavor = "multi_thread", worker_threads = 2)]
    async fn every_topology_and_operation_is_measured_with_every_sample() {
        let samples = 15;
        let bench = tokio::time::timeout(Duration::from_secs(60), wire(samples, &[64, 4096]))
            .await
            .expect("the run ends")
            .expect("the run succeeds");
        assert_eq!(bench.rows.len(), Topology::ALL.len() * 2 * 2);
        for topology in Topology::ALL {
            for operation in [Operation::Put, Operation::Get] {
                for bytes in [64, 4096] {
                    let r = bench
                        .rows
                        .iter()
                        .find(|r| {
                            r.topology == topology
                                && r.operation == operation
                                && r.payload_bytes == bytes
                        })
                        .unwrap_or_else(|| panic!("{topology:?} {operation:?} {bytes}"));
                    assert_eq!(r.samples, samples, "{r:?}");
                    assert!(
                        0.0 < r.p50_ms && r.p50_ms <= r.p99_ms && r.p99_ms <= r.max_ms,
                        "{r:?}"
                    );
                    assert!(r.max_ms < SAMPLE_TIMEOUT.as_secs_f64() * 1000.0, "{r:?}");
                }
            }
        }
    }
}
