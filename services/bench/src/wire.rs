//! `roam bench wire`: the wire's own latency (issue 30), so that a fleet is sized from
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

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use roam_runtime::session::SessionError;
use roam_runtime::SessionArgs;
use roam_stack::router::{free_loopback_port, Router};
use serde::Serialize;
use zenoh::qos::CongestionControl;
use zenoh::Session;

use crate::load::percentile;
use crate::{ms, setup, BenchError};

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
/// How long one sample may take before the bench gives up on the wire.
const SAMPLE_TIMEOUT: Duration = Duration::from_secs(10);
/// How long the sender may take to see the receiver's subscriber or queryable.
const MATCH_TIMEOUT: Duration = Duration::from_secs(10);
/// Attempts at a free loopback port (another process may take the one found).
const PORT_ATTEMPTS: usize = 5;

/// How the two sessions meet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Topology {
    /// Two peers, the receiver listening on `tcp/127.0.0.1:<port>`, the sender
    /// connected to it.
    PeerTcp,
    /// Two clients of a router on `tcp/127.0.0.1:<port>`.
    RouterTcp,
    /// [`Topology::PeerTcp`] over `tls/…`.
    PeerTls,
    /// [`Topology::RouterTcp`] over `tls/…`.
    RouterTls,
}

impl Topology {
    pub const ALL: [Topology; 4] = [
        Topology::PeerTcp,
        Topology::RouterTcp,
        Topology::PeerTls,
        Topology::RouterTls,
    ];

    fn tls(self) -> bool {
        matches!(self, Topology::PeerTls | Topology::RouterTls)
    }

    fn via_router(self) -> bool {
        matches!(self, Topology::RouterTcp | Topology::RouterTls)
    }
}

/// What is timed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Operation {
    /// A put, to the receiver's subscriber reading it.
    Put,
    /// A get, to the sender reading the receiver's reply.
    Get,
}

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

/// The key the bench uses for `operation`, the same in every topology (each has its own
/// sessions and router). `put`: the sender publishes, the receiver subscribes; payload:
/// the sequence number (little-endian u64), then zeros to the payload size. `get`: the
/// receiver answers; query: the sequence number and the reply's size (little-endian u64
/// each); reply: as a put's payload.
fn key(operation: Operation) -> &'static str {
    match operation {
        Operation::Put => "roam-bench-wire/put",
        Operation::Get => "roam-bench-wire/get",
    }
}

/// A payload of `bytes` bytes carrying `seq`.
fn payload(seq: u64, bytes: usize) -> Vec<u8> {
    let mut out = vec![0u8; bytes.max(MIN_PAYLOAD_BYTES)];
    out[..8].copy_from_slice(&seq.to_le_bytes());
    out
}

/// The sequence number a payload carries, if it is long enough to carry one.
fn seq_of(bytes: &[u8]) -> Option<u64> {
    Some(u64::from_le_bytes(bytes.get(..8)?.try_into().ok()?))
}

/// The throwaway CA and the listening side's certificate; the directory goes when this
/// is dropped.
struct Certs {
    _dir: tempfile::TempDir,
    ca: PathBuf,
    cert: PathBuf,
    key: PathBuf,
}

/// The openssl commands that make [`Certs`], run in its directory, each split at its
/// spaces: a CA, then a key and a certificate the CA signs for `localhost` and
/// `127.0.0.1` (`wire.ext`).
const OPENSSL_STEPS: [&str; 5] = [
    "genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out ca.key",
    "req -x509 -new -key ca.key -sha256 -days 1 -subj /CN=roam-bench-wire-CA \
     -addext basicConstraints=critical,CA:TRUE -addext keyUsage=critical,keyCertSign,cRLSign \
     -out ca.crt",
    "genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out wire.key",
    "req -new -key wire.key -subj /CN=localhost -out wire.csr",
    "x509 -req -in wire.csr -CA ca.crt -CAkey ca.key -CAcreateserial -sha256 -days 1 \
     -extfile wire.ext -out wire.crt",
];

impl Certs {
    /// A P-256 CA and a certificate it signs for `localhost` and `127.0.0.1`, valid one
    /// day, made with the openssl CLI the way `deploy/secure/make-secrets.sh` makes a
    /// site's.
    fn make() -> Result<Certs, BenchError> {
        let dir = tempfile::tempdir().map_err(setup)?;
        std::fs::write(
            dir.path().join("wire.ext"),
            "basicConstraints=critical,CA:FALSE\n\
             keyUsage=critical,digitalSignature,keyEncipherment\n\
             extendedKeyUsage=serverAuth\n\
             subjectAltName=DNS:localhost,IP:127.0.0.1\n",
        )
        .map_err(setup)?;
        for args in OPENSSL_STEPS {
            let out = Command::new("openssl")
                .args(args.split_whitespace())
                .current_dir(dir.path())
                .output()
                .map_err(|e| {
                    BenchError::Setup(format!(
                        "the TLS rows need the openssl CLI to make a throwaway certificate: {e}"
                    ))
                })?;
            if !out.status.success() {
                return Err(BenchError::Setup(format!(
                    "openssl {args} failed: {}",
                    String::from_utf8_lossy(&out.stderr).trim()
                )));
            }
        }
        Ok(Certs {
            ca: dir.path().join("ca.crt"),
            cert: dir.path().join("wire.crt"),
            key: dir.path().join("wire.key"),
            _dir: dir,
        })
    }
}

/// `--cfg key:"path"`.
fn cfg_path(key: &str, path: &Path) -> String {
    format!(
        "{key}:{}",
        serde_json::Value::from(path.to_string_lossy().into_owned())
    )
}

/// The settings of the side that listens over TLS: the certificate and its key.
fn tls_listen(certs: &Certs) -> Vec<String> {
    vec![
        cfg_path("transport/link/tls/listen_certificate", &certs.cert),
        cfg_path("transport/link/tls/listen_private_key", &certs.key),
    ]
}

/// The settings of the side that connects over TLS: the CA it checks the listener's
/// certificate against.
fn tls_connect(certs: &Certs) -> Vec<String> {
    vec![cfg_path(
        "transport/link/tls/root_ca_certificate",
        &certs.ca,
    )]
}

async fn open(args: &SessionArgs) -> Result<Session, BenchError> {
    let config = args.zenoh_config(None).map_err(setup)?;
    roam_runtime::session::open(config).await.map_err(setup)
}

/// Two sessions with the same flags: the receiver's, then the sender's.
async fn open_two(args: &SessionArgs) -> Result<(Session, Session), BenchError> {
    Ok((open(args).await?, open(args).await?))
}

/// The two sessions of one topology, and its router.
struct Wire {
    sender: Session,
    receiver: Session,
    router: Option<Router>,
}

/// The side that listens: the router, or the receiving peer.
enum Listener {
    Router(Router),
    Peer(Session),
}

impl Listener {
    /// Listens on `endpoint` with `cfg` (the TLS certificate, if any), multicast off.
    async fn start(
        topology: Topology,
        endpoint: &str,
        cfg: &[String],
    ) -> Result<Listener, SessionError> {
        if topology.via_router() {
            let args = SessionArgs {
                cfg: cfg.to_vec(),
                ..SessionArgs::router_on(endpoint)
            };
            return Ok(Listener::Router(
                Router::start(&args, endpoint.to_owned()).await?,
            ));
        }
        let args = SessionArgs {
            mode: Some("peer".into()),
            listen: vec![endpoint.to_owned()],
            no_multicast: true,
            cfg: cfg.to_vec(),
            ..SessionArgs::default()
        };
        let session = roam_runtime::session::open(args.zenoh_config(None)?).await?;
        Ok(Listener::Peer(session))
    }
}

impl Wire {
    /// Opens `topology` on a free loopback port.
    async fn open(topology: Topology, certs: &Certs) -> Result<Wire, BenchError> {
        let (protocol, listen, connect) = if topology.tls() {
            ("tls", tls_listen(certs), tls_connect(certs))
        } else {
            ("tcp", Vec::new(), Vec::new())
        };
        let mut last = String::new();
        for _ in 0..PORT_ATTEMPTS {
            let port = free_loopback_port().map_err(setup)?;
            let endpoint = format!("{protocol}/127.0.0.1:{port}");
            let listener = match Listener::start(topology, &endpoint, &listen).await {
                Ok(listener) => listener,
                Err(e) => {
                    last = e.to_string();
                    continue;
                }
            };
            return match listener {
                Listener::Router(router) => {
                    let client = SessionArgs {
                        cfg: connect,
                        ..SessionArgs::client_of(&endpoint)
                    };
                    match open_two(&client).await {
                        Ok((receiver, sender)) => Ok(Wire {
                            sender,
                            receiver,
                            router: Some(router),
                        }),
                        Err(e) => {
                            router.close().await;
                            Err(e)
                        }
                    }
                }
                Listener::Peer(receiver) => {
                    // The sender only connects: no listener of its own. Its open returns
                    // without waiting for the receiver's declarations (Zenoh then waited
                    // out its 500 ms scouting delay in one run in two, with a warning):
                    // the bench waits for its subscriber and queryable itself.
                    let mut cfg = connect;
                    cfg.push("listen/endpoints:[]".into());
                    cfg.push("open/return_conditions/connect_scouted:false".into());
                    let args = SessionArgs {
                        mode: Some("peer".into()),
                        connect: vec![endpoint],
                        no_multicast: true,
                        cfg,
                        ..SessionArgs::default()
                    };
                    match open(&args).await {
                        Ok(sender) => Ok(Wire {
                            sender,
                            receiver,
                            router: None,
                        }),
                        Err(e) => {
                            let _ = receiver.close().await;
                            Err(e)
                        }
                    }
                }
            };
        }
        Err(BenchError::Setup(format!(
            "no {protocol} listener could be started on loopback in {PORT_ATTEMPTS} attempts: {last}"
        )))
    }

    /// Both operations at every payload size, `samples` each.
    async fn measure(
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
        // Declarations propagate asynchronously: wait until the publisher sees the
        // subscriber.
        let matched = tokio::time::timeout(MATCH_TIMEOUT, async {
            while !publisher
                .matching_status()
                .await
                .map(|s| s.matching())
                .unwrap_or(false)
            {
                tokio::time::sleep(Duration::from_millis(10)).await;
            }
        })
        .await;
        if matched.is_err() {
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

    /// Closes the sessions, then the router.
    async fn close(self) {
        let _ = self.sender.close().await;
        let _ = self.receiver.close().await;
        if let Some(router) = self.router {
            router.close().await;
        }
    }
}

/// A row's summary of its samples (which it sorts).
fn row(
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

#[cfg(test)]
mod tests {
    use super::*;

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
