//! Where the view's messages go: the Foxglove WebSocket server (the app's live
//! connection) and an MCAP file, both sinks of one Foxglove context owned by the view.
//!
//! The WebSocket protocol keeps no history: a client sees only what is logged after it
//! subscribed. The state a late client needs (each map layer, the anchors, the missions,
//! the driven paths) is logged on *latched* topics, whose last message is kept (one per
//! topic, so the memory is bounded by the number of topics) and sent to each client that
//! subscribes, to that client alone.

use std::collections::HashMap;
use std::fs::File;
use std::io::BufWriter;
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use foxglove::websocket::{ChannelView, Client, ServerListener};
use foxglove::{ChannelId, Context, Encode, McapWriterHandle, RawChannel, WebSocketServerHandle};

use crate::ViewError;

/// Messages each WebSocket client may have queued before the oldest are dropped (the
/// server's own bound; a slow client loses messages, never memory).
pub const CLIENT_BACKLOG: usize = 256;

/// How long a stop waits for the WebSocket server's clients to close.
const STOP_GRACE: Duration = Duration::from_secs(2);

/// A topic the view logs to.
#[derive(Debug, Clone)]
pub(crate) struct Topic {
    channel: Arc<RawChannel>,
    latched: bool,
}

/// A latched topic's channel and its last message, encoded.
type Kept = (Arc<RawChannel>, Arc<[u8]>);

/// The last message of each latched topic, for clients that subscribe later.
#[derive(Default)]
struct Latch {
    last: Mutex<HashMap<ChannelId, Kept>>,
}

impl Latch {
    fn keep(&self, channel: &Arc<RawChannel>, bytes: Arc<[u8]>) {
        let mut last = self.last.lock().unwrap_or_else(|p| p.into_inner());
        last.insert(channel.id(), (channel.clone(), bytes));
    }

    fn get(&self, id: ChannelId) -> Option<Kept> {
        let last = self.last.lock().unwrap_or_else(|p| p.into_inner());
        last.get(&id).cloned()
    }
}

/// Sends a latched topic's last message to a client when it subscribes.
struct Replay(Arc<Latch>);

impl ServerListener for Replay {
    fn on_subscribe(&self, client: Client, channel: ChannelView) {
        if let Some((raw, bytes)) = self.0.get(channel.id()) {
            raw.log_to_sink(&bytes, client.sink_id());
        }
    }
}

/// What the view did, for its log and its tests.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ViewStats {
    /// Messages logged to the Foxglove topics.
    pub logged: u64,
    /// roam messages that could not be decoded or drawn (logged and dropped).
    pub dropped: u64,
}

#[derive(Debug, Default)]
pub(crate) struct Counters {
    logged: AtomicU64,
    dropped: AtomicU64,
}

impl Counters {
    /// Counts a message that could not be used; warns for the first few and then for
    /// every thousandth, so a stream of bad payloads cannot flood the log.
    pub(crate) fn dropped(&self, key: &str, reason: &dyn std::fmt::Display) {
        let n = self.dropped.fetch_add(1, Ordering::Relaxed) + 1;
        if n <= 10 || n.is_multiple_of(1000) {
            tracing::warn!(key, dropped = n, "roam view: dropped a message: {reason}");
        } else {
            tracing::debug!(key, "roam view: dropped a message: {reason}");
        }
    }

    pub(crate) fn stats(&self) -> ViewStats {
        ViewStats {
            logged: self.logged.load(Ordering::Relaxed),
            dropped: self.dropped.load(Ordering::Relaxed),
        }
    }
}

/// The Foxglove context, its sinks and the latch.
pub(crate) struct Outputs {
    context: Arc<Context>,
    latch: Arc<Latch>,
    pub(crate) counters: Counters,
    server: Mutex<Option<WebSocketServerHandle>>,
    mcap: Mutex<Option<(PathBuf, McapWriterHandle<BufWriter<File>>)>>,
    /// Where the WebSocket server listens (the port it got when asked for 0).
    pub(crate) listening: Option<SocketAddr>,
}

impl std::fmt::Debug for Outputs {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Outputs")
            .field("listening", &self.listening)
            .field("counters", &self.counters)
            .finish_non_exhaustive()
    }
}

impl Outputs {
    /// Starts the WebSocket server on `listen` and the MCAP file at `mcap` (replacing a file
    /// that is there), each when asked for.
    pub(crate) async fn start(
        listen: Option<SocketAddr>,
        mcap: Option<&Path>,
    ) -> Result<Outputs, ViewError> {
        let context = Context::new();
        let latch = Arc::new(Latch::default());
        let recording = match mcap {
            Some(path) => {
                let file = File::create(path).map_err(|e| ViewError::Record {
                    path: path.to_owned(),
                    reason: e.to_string(),
                })?;
                let handle = context
                    .mcap_writer()
                    .create(BufWriter::new(file))
                    .map_err(|e| ViewError::Record {
                        path: path.to_owned(),
                        reason: e.to_string(),
                    })?;
                Some((path.to_owned(), handle))
            }
            None => None,
        };
        let (server, listening) = match listen {
            Some(addr) => {
                let handle = context
                    .websocket_server()
                    .name("roam")
                    .bind(addr.ip().to_string(), addr.port())
                    .message_backlog_size(CLIENT_BACKLOG)
                    .listener(Arc::new(Replay(latch.clone())))
                    .start()
                    .await
                    .map_err(|e| ViewError::Listen {
                        addr,
                        reason: e.to_string(),
                    })?;
                let bound = SocketAddr::new(addr.ip(), handle.port());
                (Some(handle), Some(bound))
            }
            None => (None, None),
        };
        Ok(Outputs {
            context,
            latch,
            counters: Counters::default(),
            server: Mutex::new(server),
            mcap: Mutex::new(recording),
            listening,
        })
    }

    /// A topic for messages of type `T` (advertised to the sinks at once).
    pub(crate) fn topic<T: Encode>(&self, name: &str, latched: bool) -> Topic {
        let builder = self
            .context
            .channel_builder(name)
            .message_encoding(T::get_message_encoding())
            .schema(T::get_schema());
        // `build_raw` fails only without a message encoding, which is set above.
        let channel = builder
            .build_raw()
            .unwrap_or_else(|_| unreachable!("the message encoding is set"));
        Topic { channel, latched }
    }

    /// Logs `message` on `topic` (and keeps it, when the topic is latched).
    pub(crate) fn log<T: Encode>(&self, topic: &Topic, message: &T) {
        let mut buf = Vec::with_capacity(message.encoded_len().unwrap_or(256));
        if let Err(e) = message.encode(&mut buf) {
            self.counters.dropped(topic.channel.topic(), &e);
            return;
        }
        topic.channel.log(&buf);
        self.counters.logged.fetch_add(1, Ordering::Relaxed);
        if topic.latched {
            self.latch.keep(&topic.channel, buf.into());
        }
    }

    /// Stops the WebSocket server (waiting up to 2 s for its clients) and finishes the
    /// MCAP file (its summary and index are written here: the file is complete only after).
    pub(crate) async fn stop(&self) -> Result<(), ViewError> {
        let server = self.server.lock().unwrap_or_else(|p| p.into_inner()).take();
        if let Some(server) = server {
            if tokio::time::timeout(STOP_GRACE, server.stop().wait())
                .await
                .is_err()
            {
                tracing::warn!("roam view: WebSocket clients did not close within {STOP_GRACE:?}");
            }
        }
        let recording = self.mcap.lock().unwrap_or_else(|p| p.into_inner()).take();
        if let Some((path, handle)) = recording {
            let finish = tokio::task::spawn_blocking(move || {
                let writer = handle.close().map_err(|e| e.to_string())?;
                let file = writer.into_inner().map_err(|e| e.error().to_string())?;
                file.sync_all().map_err(|e| e.to_string())
            });
            let outcome = finish
                .await
                .unwrap_or_else(|e| Err(format!("the MCAP writer panicked: {e}")));
            outcome.map_err(|reason| ViewError::Record { path, reason })?;
        }
        Ok(())
    }
}
