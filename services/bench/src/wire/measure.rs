//! Timing puts and gets one at a time over an open topology, and each row's summary.

use std::time::{Duration, Instant};

use zenoh::qos::CongestionControl;

use super::payload::{key, payload, seq_of};
use super::sessions::Wire;
use super::{Operation, Topology, WireRow, MIN_PAYLOAD_BYTES, WARMUP};
use crate::load::percentile;
use crate::{ms, setup, BenchError};

/// How long one sample may take before the bench gives up on the wire.
pub(super) const SAMPLE_TIMEOUT: Duration = Duration::from_secs(10);
/// How long the sender may take to see the receiver's subscriber or queryable.
const MATCH_TIMEOUT: Duration = Duration::from_secs(10);

impl Wire {
    /// Both operations at every payload size, `samples` each.
    pub(super) async fn measure(
        &self,
        topology: Topology,
        samples: usize,
        payloads: &[usize],
    ) -> Result<Vec<WireRow>, BenchError> {
        let mut rows = Vec::new();
        let publisher = self
            .sender
            .declare_publisher(key(Operation::Put))
            .congestion_control(CongestionControl::Block)
            .await
            .map_err(setup)?;
        let subscriber = self
            .receiver
            .declare_subscriber(key(Operation::Put))
            .await
            .map_err(setup)?;
        if !crate::matched(&publisher, MATCH_TIMEOUT).await {
            return Err(BenchError::Setup(format!(
                "{topology:?}: the subscriber never matched the publisher within {MATCH_TIMEOUT:?}"
            )));
        }
        let mut seq = 0u64;
        for &bytes in payloads {
            let mut times = Vec::with_capacity(samples);
            for n in 0..WARMUP + samples {
                seq += 1;
                let body = payload(seq, bytes);
                let started = Instant::now();
                publisher.put(body).await.map_err(setup)?;
                loop {
                    let sample = tokio::time::timeout(SAMPLE_TIMEOUT, subscriber.recv_async())
                        .await
                        .map_err(|_| BenchError::Lost(SAMPLE_TIMEOUT))?
                        .map_err(setup)?;
                    let got = sample.payload().to_bytes();
                    match seq_of(&got) {
                        Some(s) if s == seq && got.len() == bytes => break,
                        Some(s) if s < seq => continue,
                        other => {
                            return Err(BenchError::Setup(format!(
                                "{topology:?}: put {seq} of {bytes} bytes arrived as {other:?} of {} bytes",
                                got.len()
                            )))
                        }
                    }
                }
                if n >= WARMUP {
                    times.push(ms(started.elapsed()));
                }
            }
            rows.push(row(topology, Operation::Put, bytes, &mut times));
        }
        drop(subscriber);
        drop(publisher);

        let queryable = self
            .receiver
            .declare_queryable(key(Operation::Get))
            .await
            .map_err(setup)?;
        let answering = tokio::spawn(async move {
            while let Ok(query) = queryable.recv_async().await {
                let asked = query.payload().map(|p| p.to_bytes().into_owned());
                let (Some(seq), Some(size)) = (
                    asked.as_deref().and_then(seq_of),
                    asked.as_deref().and_then(|a| seq_of(a.get(8..)?)),
                ) else {
                    continue;
                };
                let body = payload(seq, size as usize);
                if let Err(e) = query.reply(query.key_expr().clone(), body).await {
                    tracing::warn!("the bench's reply failed: {e}");
                }
            }
        });
        let measured = self.gets(topology, samples, payloads, &mut seq).await;
        answering.abort();
        rows.extend(measured?);
        Ok(rows)
    }

    /// The `get` rows; the first replies wait for the queryable's declaration to reach
    /// the sender (a `get` before it has no one to answer).
    async fn gets(
        &self,
        topology: Topology,
        samples: usize,
        payloads: &[usize],
        seq: &mut u64,
    ) -> Result<Vec<WireRow>, BenchError> {
        let matched = tokio::time::timeout(MATCH_TIMEOUT, async {
            loop {
                *seq += 1;
                if self
                    .get(*seq, MIN_PAYLOAD_BYTES, Duration::from_millis(200))
                    .await
                    .is_ok()
                {
                    break;
                }
            }
        })
        .await;
        if matched.is_err() {
            return Err(BenchError::Setup(format!(
                "{topology:?}: the queryable never answered within {MATCH_TIMEOUT:?}"
            )));
        }
        let mut rows = Vec::new();
        for &bytes in payloads {
            let mut times = Vec::with_capacity(samples);
            for n in 0..WARMUP + samples {
                *seq += 1;
                let started = Instant::now();
                self.get(*seq, bytes, SAMPLE_TIMEOUT).await.map_err(|e| {
                    BenchError::Setup(format!("{topology:?}: get {seq} of {bytes} bytes: {e}"))
                })?;
                if n >= WARMUP {
                    times.push(ms(started.elapsed()));
                }
            }
            rows.push(row(topology, Operation::Get, bytes, &mut times));
        }
        Ok(rows)
    }

    /// One `get` of a reply of `bytes` bytes carrying `seq`, read as
    /// [`roam_runtime::Requester`] reads one: the first reply from Zenoh's channel.
    async fn get(&self, seq: u64, bytes: usize, timeout: Duration) -> Result<(), String> {
        let mut query = seq.to_le_bytes().to_vec();
        query.extend_from_slice(&(bytes as u64).to_le_bytes());
        let replies = self
            .sender
            .get(key(Operation::Get))
            .payload(query)
            .timeout(timeout)
            .await
            .map_err(|e| e.to_string())?;
        let reply = tokio::time::timeout(timeout + Duration::from_secs(1), replies.recv_async())
            .await
            .ok()
            .and_then(Result::ok)
            .ok_or_else(|| format!("no reply within {timeout:?}"))?;
        let sample = reply
            .result()
            .map_err(|e| format!("an error reply: {e:?}"))?;
        let got = sample.payload().to_bytes();
        match seq_of(&got) {
            Some(s) if s == seq && got.len() == bytes => Ok(()),
            other => Err(format!("the reply was {other:?} of {} bytes", got.len())),
        }
    }
}

/// A row's summary of its samples (which it sorts).
pub(super) fn row(
    topology: Topology,
    operation: Operation,
    payload_bytes: usize,
    times: &mut [f64],
) -> WireRow {
    WireRow {
        topology,
        operation,
        payload_bytes,
        samples: times.len(),
        p50_ms: percentile(times, 0.5),
        p99_ms: percentile(times, 0.99),
        max_ms: times.iter().copied().fold(0.0, f64::max),
    }
}
