//! The gate: roam's own listener in front of the Foxglove SDK's WebSocket server.
//!
//! The SDK's server has no hook for the upgrade's `Origin` or for credentials, so it
//! listens on a private loopback port and the gate takes the public address. For each
//! connection the gate reads the HTTP request head (at most [`MAX_HEAD_BYTES`], within
//! [`HEAD_TIMEOUT`]), lets [`Access::check`] decide, and then either answers with a short
//! HTTP refusal (403, 401, …, logged as one bounded, escaped, throttled line) or forwards
//! the connection to the SDK's server: the head as checked, the bytes read after it, and
//! then everything both ways (`copy_bidirectional`).
//!
//! **Two pools, so that half-open connections cannot lock clients out** (slowloris).
//! A connection still sending its head holds one of [`MAX_HALF_OPEN`] places; when they
//! are all taken, a newcomer takes the place of the connection that has been sending
//! its head the longest (answered 503 and closed). A real client sends its head in one
//! packet, so it is never the oldest for long: any number of trickling connections
//! delays it by nothing. Only a connection whose head was admitted takes one of the
//! [`MAX_CONNECTIONS`] served slots (a 503 beyond), so the served slots are held by
//! clients the gate let in, never by strangers still talking.
//!
//! Clients that offer only the protocol's older name, `foxglove.websocket.v1`
//! (`@foxglove/ws-protocol`, Lichtblick), get it translated: the gate offers the SDK
//! `foxglove.sdk.v1` instead and writes the old name back into the SDK's `101` answer.
//! The two names carry the same protocol (the SDK's `foxglove.sdk.v1` sends the
//! `serverInfo`, inline-schema `advertise`, `subscribe` and `messageData` of the
//! `foxglove.websocket.v1` spec; only `foxglove.sdk.v1.1` changes `advertise`, and a
//! client offering that is passed through untouched), and the subprotocol is not part of
//! the WebSocket key exchange, so nothing after the heads changes.

use std::collections::VecDeque;
use std::net::SocketAddr;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use tokio::io::{AsyncRead, AsyncReadExt, AsyncWriteExt};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::Semaphore;
use tokio_util::sync::CancellationToken;
use tokio_util::task::TaskTracker;

use crate::access::{Access, Admitted, Refusal, Status, LEGACY_SUBPROTOCOL, SDK_SUBPROTOCOL};
use crate::head::{head_end, HeadError, RequestHead, ResponseHead, MAX_HEAD_BYTES};
use crate::wire::{clipped, Throttle};

/// How long a client has to send its request head.
pub const HEAD_TIMEOUT: Duration = Duration::from_secs(5);
/// Connections forwarded to the SDK's server at once (their heads admitted).
pub const MAX_CONNECTIONS: usize = 32;
/// Connections sending their request head at once; beyond, the oldest is dropped.
pub const MAX_HALF_OPEN: usize = 256;
/// How long connecting to the SDK's server, reading its answer or writing a refusal may take.
const INNER_TIMEOUT: Duration = Duration::from_secs(2);
/// How long a stop waits for the forwarded connections to end.
const STOP_GRACE: Duration = Duration::from_secs(2);

const HEADER_PROTOCOL: &str = "Sec-WebSocket-Protocol";
/// The most bytes read and dropped from a refused client before its connection is closed.
const LINGER_BYTES: usize = 256 * 1024;

/// A running gate.
#[derive(Debug)]
pub(crate) struct Gate {
    cancel: CancellationToken,
    tracker: TaskTracker,
}

/// Why a connection was not forwarded.
#[derive(Debug)]
enum Outcome {
    Refused(Refusal),
    /// The client went away or broke the connection before its head was read.
    Gone,
}

impl From<Refusal> for Outcome {
    fn from(r: Refusal) -> Outcome {
        Outcome::Refused(r)
    }
}

impl Gate {
    /// Serves `listener` until [`Gate::stop`]: each admitted connection is forwarded to
    /// the SDK's server at `inner`.
    pub(crate) fn start(listener: TcpListener, inner: SocketAddr, access: Access) -> Gate {
        let cancel = CancellationToken::new();
        let tracker = TaskTracker::new();
        let shared = Arc::new(Shared {
            access,
            inner,
            slots: Arc::new(Semaphore::new(MAX_CONNECTIONS)),
            half_open: HalfOpen::default(),
            refused: Throttle::default(),
            cancel: cancel.clone(),
        });
        tracker.spawn(accept_loop(listener, shared, tracker.clone()));
        Gate { cancel, tracker }
    }

    /// Stops accepting and ends the forwarded connections (waiting up to 2 s).
    pub(crate) async fn stop(&self) {
        self.cancel.cancel();
        self.tracker.close();
        if tokio::time::timeout(STOP_GRACE, self.tracker.wait())
            .await
            .is_err()
        {
            tracing::warn!("roam view: connections did not end within {STOP_GRACE:?}");
        }
    }
}

struct Shared {
    access: Access,
    inner: SocketAddr,
    slots: Arc<Semaphore>,
    half_open: HalfOpen,
    refused: Throttle,
    cancel: CancellationToken,
}

/// The connections sending their head, oldest first (see the module doc).
#[derive(Default)]
struct HalfOpen {
    inner: Mutex<HalfOpenInner>,
}

#[derive(Default)]
struct HalfOpenInner {
    next_id: u64,
    /// (id, woken when the place is taken by a newcomer), oldest first.
    open: VecDeque<(u64, CancellationToken)>,
}

/// A connection's place among the half-open ones; given back when dropped.
struct Place<'a> {
    pool: &'a HalfOpen,
    id: u64,
    evicted: CancellationToken,
}

impl HalfOpen {
    /// A place for a new connection, taken from the oldest when all are held.
    fn enter(&self) -> Place<'_> {
        let mut inner = roam_runtime::lock(&self.inner);
        if inner.open.len() >= MAX_HALF_OPEN {
            if let Some((_, oldest)) = inner.open.pop_front() {
                oldest.cancel();
            }
        }
        let id = inner.next_id;
        inner.next_id += 1;
        let evicted = CancellationToken::new();
        inner.open.push_back((id, evicted.clone()));
        Place {
            pool: self,
            id,
            evicted,
        }
    }

    #[cfg(test)]
    fn len(&self) -> usize {
        roam_runtime::lock(&self.inner).open.len()
    }
}

impl Drop for Place<'_> {
    fn drop(&mut self) {
        let mut inner = roam_runtime::lock(&self.pool.inner);
        if let Some(at) = inner.open.iter().position(|(id, _)| *id == self.id) {
            inner.open.remove(at);
        }
    }
}

async fn accept_loop(listener: TcpListener, shared: Arc<Shared>, tracker: TaskTracker) {
    let accept_errors = Throttle::default();
    loop {
        let accepted = tokio::select! {
            _ = shared.cancel.cancelled() => return,
            accepted = listener.accept() => accepted,
        };
        let (stream, peer) = match accepted {
            Ok(accepted) => accepted,
            Err(e) => {
                // Out of file descriptors and the like: wait a little rather than spin.
                if accept_errors.count().1 {
                    tracing::warn!("roam view: accepting a WebSocket client failed: {e}");
                }
                tokio::time::sleep(Duration::from_millis(100)).await;
                continue;
            }
        };
        let shared = shared.clone();
        tracker.spawn(async move {
            let _ = stream.set_nodelay(true);
            tokio::select! {
                _ = shared.cancel.cancelled() => {}
                _ = serve(stream, peer, &shared) => {}
            }
        });
    }
}

/// Reads a connection's head among the half-open ones, checks it, and forwards it in a
/// served slot, or refuses it.
async fn serve(mut client: TcpStream, peer: SocketAddr, shared: &Shared) {
    let mut buf = Vec::with_capacity(1024);
    let place = shared.half_open.enter();
    let read = tokio::time::timeout(HEAD_TIMEOUT, read_head(&mut client, &mut buf));
    let checked = tokio::select! {
        _ = place.evicted.cancelled() => Err(Outcome::Refused(Refusal {
            status: Status::Unavailable,
            why: format!("{MAX_HALF_OPEN} connections are sending their head; this one the longest"),
        })),
        read = read => match read {
            Ok(Ok(len)) => admit(&buf[..len], &shared.access).map(|(head, a)| (head, a, len)),
            Ok(Err(outcome)) => Err(outcome),
            Err(_) => Err(Outcome::Refused(Refusal {
                status: Status::RequestTimeout,
                why: format!("no request head within {HEAD_TIMEOUT:?}"),
            })),
        },
    };
    drop(place);
    let (head, admitted, len) = match checked {
        Ok(checked) => checked,
        Err(Outcome::Refused(refusal)) => {
            return refuse(client, peer, &refusal, &shared.refused).await
        }
        Err(Outcome::Gone) => return,
    };
    let Ok(_slot) = shared.slots.clone().try_acquire_owned() else {
        let full = Refusal {
            status: Status::Unavailable,
            why: format!("{MAX_CONNECTIONS} connections are open"),
        };
        return refuse(client, peer, &full, &shared.refused).await;
    };
    if let Err(why) = forward(&mut client, head, admitted, &buf[len..], shared.inner).await {
        let refusal = Refusal {
            status: Status::BadGateway,
            why,
        };
        return refuse(client, peer, &refusal, &shared.refused).await;
    }
}

/// Parses and checks a request head; the head to forward (its subprotocol translated when
/// the client offered only the old name).
fn admit(bytes: &[u8], access: &Access) -> Result<(RequestHead, Admitted), Outcome> {
    let mut head = RequestHead::parse(bytes).map_err(Refusal::from)?;
    let admitted = access.check(&head)?;
    if admitted.legacy_subprotocol {
        head.headers.set(HEADER_PROTOCOL, SDK_SUBPROTOCOL);
    }
    Ok((head, admitted))
}

/// Reads into `buf` until it holds a whole head (at most [`MAX_HEAD_BYTES`]); returns the
/// head's length (`buf` may hold more after it).
async fn read_head<R: AsyncRead + Unpin>(
    stream: &mut R,
    buf: &mut Vec<u8>,
) -> Result<usize, Outcome> {
    let mut chunk = [0u8; 2048];
    // Where the search for the blank line resumes: a client sending one byte at a time
    // costs a scan of the new bytes, not of the whole buffer, per read.
    let mut scanned = 0;
    loop {
        if let Some(end) = head_end(&buf[scanned..]).map(|e| e + scanned) {
            if end > MAX_HEAD_BYTES {
                return Err(Refusal::from(HeadError::TooLarge).into());
            }
            return Ok(end);
        }
        if buf.len() >= MAX_HEAD_BYTES {
            return Err(Refusal::from(HeadError::TooLarge).into());
        }
        let room = (MAX_HEAD_BYTES + 3 - buf.len()).min(chunk.len());
        match stream.read(&mut chunk[..room]).await {
            Ok(0) | Err(_) => return Err(Outcome::Gone),
            Ok(n) => {
                scanned = buf.len().saturating_sub(3);
                buf.extend_from_slice(&chunk[..n]);
            }
        }
    }
}

/// Opens the connection to the SDK's server, sends it the checked head and what followed
/// it, translates the subprotocol of its answer when needed, then copies both ways until
/// either side closes. An error is the reason the forward failed before any answer was
/// given to the client.
async fn forward(
    client: &mut TcpStream,
    head: RequestHead,
    admitted: Admitted,
    early: &[u8],
    inner: SocketAddr,
) -> Result<(), String> {
    let mut server = tokio::time::timeout(INNER_TIMEOUT, TcpStream::connect(inner))
        .await
        .map_err(|_| "the view's WebSocket server did not answer".to_owned())?
        .map_err(|e| format!("the view's WebSocket server: {e}"))?;
    let _ = server.set_nodelay(true);
    let mut request = head.to_bytes();
    request.extend_from_slice(early);
    server
        .write_all(&request)
        .await
        .map_err(|e| format!("the view's WebSocket server: {e}"))?;
    if admitted.legacy_subprotocol {
        let mut buf = Vec::with_capacity(512);
        let len = tokio::time::timeout(INNER_TIMEOUT, read_head(&mut server, &mut buf))
            .await
            .map_err(|_| "the view's WebSocket server sent no answer".to_owned())?
            .map_err(|_| "the view's WebSocket server sent no valid answer".to_owned())?;
        let mut answer =
            ResponseHead::parse(&buf[..len]).map_err(|e| format!("its answer: {e}"))?;
        let chosen = answer.headers.single(HEADER_PROTOCOL).ok().flatten();
        if chosen == Some(SDK_SUBPROTOCOL) {
            answer.headers.set(HEADER_PROTOCOL, LEGACY_SUBPROTOCOL);
        }
        let mut out = answer.to_bytes();
        out.extend_from_slice(&buf[len..]);
        // From here on the client has an answer: a failure only ends the connection.
        if client.write_all(&out).await.is_err() {
            return Ok(());
        }
    }
    let _ = tokio::io::copy_bidirectional(client, &mut server).await;
    Ok(())
}

/// Answers with a minimal HTTP refusal and logs one line for it (throttled).
async fn refuse(mut client: TcpStream, peer: SocketAddr, refusal: &Refusal, log: &Throttle) {
    let (n, warn) = log.count();
    let status = refusal.status;
    let why = clipped(&refusal.why);
    if warn {
        tracing::warn!(
            %peer,
            refused = n,
            "roam view: refused a WebSocket client: {} {}: {why}",
            status.code(),
            status.reason()
        );
    } else {
        tracing::debug!(%peer, "roam view: refused a WebSocket client: {}: {why}", status.code());
    }
    let body = format!("{} {}\n", status.code(), status.reason());
    let mut response = format!(
        "HTTP/1.1 {} {}\r\nContent-Type: text/plain\r\nContent-Length: {}\r\nConnection: close\r\n",
        status.code(),
        status.reason(),
        body.len()
    );
    if status == Status::Unauthorized {
        response.push_str("WWW-Authenticate: Bearer realm=\"roam view\"\r\n");
    }
    response.push_str("\r\n");
    response.push_str(&body);
    let _ = tokio::time::timeout(INNER_TIMEOUT, async {
        let _ = client.write_all(response.as_bytes()).await;
        let _ = client.shutdown().await;
        // A lingering close: what the client sent and was not read (the rest of an
        // oversized head) is read and dropped, a bounded amount, so that closing does not
        // reset the connection before the client has read the answer.
        let mut sink = [0u8; 4096];
        let mut left = LINGER_BYTES;
        while left > 0 {
            match client.read(&mut sink).await {
                Ok(0) | Err(_) => break,
                Ok(n) => left = left.saturating_sub(n),
            }
        }
    })
    .await;
}

#[cfg(test)]
mod tests {
    use super::*;

    async fn read_from(bytes: &[u8]) -> (Result<usize, Outcome>, Vec<u8>) {
        let mut reader = bytes;
        let mut buf = Vec::new();
        let result = read_head(&mut reader, &mut buf).await;
        (result, buf)
    }

    #[tokio::test]
    async fn a_head_is_read_up_to_its_blank_line_and_the_rest_kept() {
        let (len, buf) = read_from(b"GET / HTTP/1.1\r\nHost: x\r\n\r\n\x81\x80abcd").await;
        let len = len.expect("a head");
        assert_eq!(&buf[..len], b"GET / HTTP/1.1\r\nHost: x\r\n\r\n");
        assert_eq!(&buf[len..], b"\x81\x80abcd");
    }

    #[tokio::test]
    async fn an_endless_head_is_cut_at_the_limit() {
        let mut endless = b"GET / HTTP/1.1\r\nX: ".to_vec();
        endless.extend(std::iter::repeat_n(b'a', 1 << 20));
        let (result, buf) = read_from(&endless).await;
        match result {
            Err(Outcome::Refused(r)) => assert_eq!(r.status, Status::HeadTooLarge),
            other => panic!("{other:?}"),
        }
        assert!(buf.len() <= MAX_HEAD_BYTES + 3, "{} bytes read", buf.len());
        let (result, _) = read_from(b"GET / HTTP/1.1\r\n").await;
        assert!(matches!(result, Err(Outcome::Gone)), "{result:?}");
    }

    #[test]
    fn a_newcomer_takes_the_place_of_the_oldest_half_open_connection() {
        let pool = HalfOpen::default();
        let places: Vec<Place<'_>> = (0..MAX_HALF_OPEN).map(|_| pool.enter()).collect();
        assert!(places.iter().all(|p| !p.evicted.is_cancelled()));
        let newcomer = pool.enter();
        assert!(places[0].evicted.is_cancelled(), "the oldest is dropped");
        assert!(places[1..].iter().all(|p| !p.evicted.is_cancelled()));
        assert_eq!(pool.len(), MAX_HALF_OPEN);
        drop(places);
        assert_eq!(pool.len(), 1, "only the newcomer is left");
        drop(newcomer);
        assert_eq!(pool.len(), 0);
    }

    #[test]
    fn a_legacy_offer_is_forwarded_as_the_sdk_subprotocol() {
        let head = b"GET / HTTP/1.1\r\nSec-WebSocket-Protocol: foxglove.websocket.v1\r\n\r\n";
        let (forwarded, admitted) = admit(head, &Access::default()).expect("admitted");
        assert!(admitted.legacy_subprotocol);
        assert_eq!(
            forwarded.headers.single(HEADER_PROTOCOL),
            Ok(Some(SDK_SUBPROTOCOL))
        );
        let refused = admit(
            b"GET / HTTP/1.1\r\nOrigin: https://evil.example\r\n\r\n",
            &Access::default(),
        );
        assert!(matches!(
            refused,
            Err(Outcome::Refused(Refusal {
                status: Status::Forbidden,
                ..
            }))
        ));
    }
}
