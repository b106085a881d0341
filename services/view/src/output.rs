//! Where the view's messages go: the Foxglove WebSocket server (the app's live
//! connection) and an MCAP file, both sinks of one Foxglove context owned by the view.
//!
//! The WebSocket protocol keeps no history: a client sees only what is logged after it
//! subscribed. The state a late client needs (each map layer, the anchors, the missions,
//! the driven paths) is logged on *latched* topics, whose last message is kept and sent to
//! each client that subscribes, to that client alone: one message per topic, or on the
//! per-robot topics one per robot (at most [`MAX_LATCHED_KEYS`]), so the memory is bounded
//! by the number of topics and robots.
//!
//! The SDK's WebSocket server listens only on a private loopback port ([`INNER_PORTS`]);
//! clients reach it through the gate (`gate.rs`), which checks who they are.

use std::collections::{BTreeMap, HashMap};
use std::fs::File;
use std::io::BufWriter;
use std::net::{Ipv4Addr, SocketAddr};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use foxglove::messages::SceneUpdate;
use foxglove::websocket::{ChannelView, Client, ServerListener};
use foxglove::{ChannelId, Context, Encode, McapWriterHandle, RawChannel, WebSocketServerHandle};

use crate::roster::MAX_ROBOTS;
use crate::wire::{clipped, shown, Throttle, WireError};
use crate::ViewError;

/// Messages each WebSocket client may have queued before the oldest are dropped (the
/// server's own bound; a slow client loses messages, never memory).
pub const CLIENT_BACKLOG: usize = 256;

/// How long a stop waits for the WebSocket server's clients to close.
const STOP_GRACE: Duration = Duration::from_secs(2);

/// The loopback ports tried, in order, for the SDK's own server behind the gate. The
/// SDK's server checks nobody, and a web page can open a WebSocket to any loopback port
/// it guesses, so these are ports that browsers refuse to connect to at all (the "bad
/// ports" of the Fetch standard, which WebSocket connections obey): a page cannot reach
/// the SDK's server around the gate. These eleven are on the lists of Chromium, Firefox
/// and WebKit alike. Local programs can still reach it, as they can reach Zenoh. When
/// every one is taken an ephemeral port is used, with a warning.
pub const INNER_PORTS: [u16; 11] = [
    6665, 6666, 6667, 6668, 6669, 6697, 3659, 6566, 1719, 1720, 10080,
];

/// The most per-robot messages kept on one latched topic.
pub const MAX_LATCHED_KEYS: usize = MAX_ROBOTS;

/// A topic the view logs to.
#[derive(Debug, Clone)]
pub(crate) struct Topic {
    channel: Arc<RawChannel>,
    latched: bool,
}

/// The most bytes of per-robot messages sent to a subscriber as one message.
const REPLAY_BATCH_BYTES: usize = 4 << 20;

/// A latched topic's kept messages, encoded.
struct Kept {
    channel: Arc<RawChannel>,
    /// The topic's last message, on a topic latched as a whole.
    whole: Option<Arc<[u8]>>,
    /// Each robot's last `SceneUpdate`, on a per-robot topic.
    robots: BTreeMap<String, Arc<[u8]>>,
}

impl Kept {
    /// What a new subscriber gets: the whole-topic message, and the robots' messages
    /// concatenated into a few large ones. Concatenated protobuf messages are one message
    /// with their repeated fields appended, and every field of a `SceneUpdate` is
    /// repeated: so 256 robots' missions arrive as a handful of `SceneUpdate`s, and a
    /// client's queue of [`CLIENT_BACKLOG`] messages cannot overflow with them.
    fn replay(&self) -> Vec<Vec<u8>> {
        let mut out: Vec<Vec<u8>> = self.whole.iter().map(|w| w.to_vec()).collect();
        let mut batch: Vec<u8> = Vec::new();
        for bytes in self.robots.values() {
            if !batch.is_empty() && batch.len() + bytes.len() > REPLAY_BATCH_BYTES {
                out.push(std::mem::take(&mut batch));
            }
            batch.extend_from_slice(bytes);
        }
        if !batch.is_empty() {
            out.push(batch);
        }
        out
    }
}

/// The last messages of each latched topic, for clients that subscribe later.
#[derive(Default)]
struct Latch {
    last: Mutex<HashMap<ChannelId, Kept>>,
}

impl Latch {
    fn kept<'a>(last: &'a mut HashMap<ChannelId, Kept>, channel: &Arc<RawChannel>) -> &'a mut Kept {
        last.entry(channel.id()).or_insert_with(|| Kept {
            channel: channel.clone(),
            whole: None,
            robots: BTreeMap::new(),
        })
    }

    fn keep(&self, channel: &Arc<RawChannel>, bytes: Arc<[u8]>) {
        let mut last = roam_runtime::lock(&self.last);
        Self::kept(&mut last, channel).whole = Some(bytes);
    }

    /// Keeps `bytes` as robot `robot`'s message; a new robot beyond
    /// [`MAX_LATCHED_KEYS`] is not kept (the callers evict robots before that).
    fn keep_robot(&self, channel: &Arc<RawChannel>, robot: &str, bytes: Arc<[u8]>) {
        let mut last = roam_runtime::lock(&self.last);
        let robots = &mut Self::kept(&mut last, channel).robots;
        if robots.len() < MAX_LATCHED_KEYS || robots.contains_key(robot) {
            robots.insert(robot.to_owned(), bytes);
        }
    }

    fn forget_robot(&self, channel: &Arc<RawChannel>, robot: &str) {
        let mut last = roam_runtime::lock(&self.last);
        if let Some(kept) = last.get_mut(&channel.id()) {
            kept.robots.remove(robot);
        }
    }

    fn replay(&self, id: ChannelId) -> Option<(Arc<RawChannel>, Vec<Vec<u8>>)> {
        let last = roam_runtime::lock(&self.last);
        last.get(&id)
            .map(|kept| (kept.channel.clone(), kept.replay()))
    }
}

/// Sends a latched topic's last messages to a client when it subscribes.
struct Replay(Arc<Latch>);

impl ServerListener for Replay {
    fn on_subscribe(&self, client: Client, channel: ChannelView) {
        if let Some((raw, messages)) = self.0.replay(channel.id()) {
            for bytes in messages {
                raw.log_to_sink(&bytes, client.sink_id());
            }
        }
    }
}

/// What the view did, for its log and its tests.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ViewStats {
    /// Messages logged to the Foxglove topics.
    pub logged: u64,
    /// roam messages that could not be decoded or drawn (logged and dropped), the
    /// oversized ones included.
    pub dropped: u64,
    /// Of those, payloads dropped unread because they were over their kind's cap.
    pub oversized: u64,
    /// Robots with a mission or a driven path kept now (at most [`MAX_ROBOTS`] each).
    pub robots: usize,
    /// Robots the sim named in its last status.
    pub sim_robots: usize,
}

#[derive(Debug, Default)]
pub(crate) struct Counters {
    logged: AtomicU64,
    dropped: Throttle,
    oversized: AtomicU64,
    pub(crate) robots: AtomicUsize,
    pub(crate) sim_robots: AtomicUsize,
}

impl Counters {
    /// Counts a message that could not be used; warns for the first few and then for
    /// every thousandth, so a stream of bad payloads cannot flood the log. The key comes
    /// from the wire too: it is shown escaped, the reason clipped.
    pub(crate) fn dropped(&self, key: &str, reason: &dyn std::fmt::Display) {
        let (n, warn) = self.dropped.count();
        let key = shown(key);
        let reason = clipped(&reason.to_string());
        if warn {
            tracing::warn!(key, dropped = n, "roam view: dropped a message: {reason}");
        } else {
            tracing::debug!(key, "roam view: dropped a message: {reason}");
        }
    }

    /// [`Counters::dropped`] for a payload that could not be read, counting the oversized.
    pub(crate) fn unread(&self, key: &str, error: &WireError) {
        if matches!(error, WireError::TooLarge { .. }) {
            self.oversized.fetch_add(1, Ordering::Relaxed);
        }
        self.dropped(key, error);
    }

    pub(crate) fn stats(&self) -> ViewStats {
        ViewStats {
            logged: self.logged.load(Ordering::Relaxed),
            dropped: self.dropped.total(),
            oversized: self.oversized.load(Ordering::Relaxed),
            robots: self.robots.load(Ordering::Relaxed),
            sim_robots: self.sim_robots.load(Ordering::Relaxed),
        }
    }
}

/// The Foxglove context, its sinks and the latch.
pub(crate) struct Outputs {
    context: Arc<Context>,
    latch: Arc<Latch>,
    pub(crate) counters: Arc<Counters>,
    server: Mutex<Option<WebSocketServerHandle>>,
    mcap: Mutex<Option<(PathBuf, McapWriterHandle<BufWriter<File>>)>>,
    /// Where the SDK's WebSocket server listens, on loopback behind the gate.
    pub(crate) inner: Option<SocketAddr>,
}

impl std::fmt::Debug for Outputs {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Outputs")
            .field("inner", &self.inner)
            .field("counters", &self.counters)
            .finish_non_exhaustive()
    }
}

/// Starts the SDK's WebSocket server on the first free port of [`INNER_PORTS`] on
/// 127.0.0.1, else on an ephemeral one.
async fn start_inner(
    context: &Arc<Context>,
    latch: &Arc<Latch>,
) -> Result<WebSocketServerHandle, ViewError> {
    let start = |port: u16| {
        context
            .websocket_server()
            .name("roam")
            .bind(Ipv4Addr::LOCALHOST.to_string(), port)
            .message_backlog_size(CLIENT_BACKLOG)
            .listener(Arc::new(Replay(latch.clone())))
            .start()
    };
    for port in INNER_PORTS {
        if let Ok(handle) = start(port).await {
            return Ok(handle);
        }
    }
    let handle = start(0).await.map_err(|e| ViewError::Listen {
        addr: SocketAddr::from((Ipv4Addr::LOCALHOST, 0)),
        reason: e.to_string(),
    })?;
    tracing::warn!(
        "roam view: every browser-blocked loopback port is taken; the WebSocket server behind \
         the gate listens on 127.0.0.1:{}, which a web page that finds it can reach",
        handle.port()
    );
    Ok(handle)
}

impl Outputs {
    /// Starts the SDK's WebSocket server (on loopback, for the gate) when `serve`, and the
    /// MCAP file at `mcap` (replacing a file that is there) when asked for.
    pub(crate) async fn start(serve: bool, mcap: Option<&Path>) -> Result<Outputs, ViewError> {
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
        let (server, inner) = if serve {
            let handle = start_inner(&context, &latch).await?;
            let inner = SocketAddr::from((Ipv4Addr::LOCALHOST, handle.port()));
            (Some(handle), Some(inner))
        } else {
            (None, None)
        };
        Ok(Outputs {
            context,
            latch,
            counters: Arc::new(Counters::default()),
            server: Mutex::new(server),
            mcap: Mutex::new(recording),
            inner,
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
        if let Some(bytes) = self.encode_and_log(topic, message) {
            if topic.latched {
                self.latch.keep(&topic.channel, bytes);
            }
        }
    }

    /// Logs `update` on `topic` as robot `robot`'s: a latched topic keeps the last one of
    /// each robot, and a client that subscribes later gets them all (see [`Kept::replay`],
    /// which is why this takes only a `SceneUpdate`).
    pub(crate) fn log_robot(&self, topic: &Topic, robot: &str, update: &SceneUpdate) {
        if let Some(bytes) = self.encode_and_log(topic, update) {
            if topic.latched {
                self.latch.keep_robot(&topic.channel, robot, bytes);
            }
        }
    }

    /// Forgets robot `robot`'s kept message on `topic` (a client that subscribes later
    /// no longer gets it).
    pub(crate) fn forget_robot(&self, topic: &Topic, robot: &str) {
        self.latch.forget_robot(&topic.channel, robot);
    }

    fn encode_and_log<T: Encode>(&self, topic: &Topic, message: &T) -> Option<Arc<[u8]>> {
        let mut buf = Vec::with_capacity(message.encoded_len().unwrap_or(256));
        if let Err(e) = message.encode(&mut buf) {
            self.counters.dropped(topic.channel.topic(), &e);
            return None;
        }
        topic.channel.log(&buf);
        self.counters.logged.fetch_add(1, Ordering::Relaxed);
        Some(buf.into())
    }

    /// Stops the WebSocket server (waiting up to 2 s for its clients) and finishes the
    /// MCAP file (its summary and index are written here: the file is complete only after).
    pub(crate) async fn stop(&self) -> Result<(), ViewError> {
        let server = roam_runtime::lock(&self.server).take();
        if let Some(server) = server {
            if tokio::time::timeout(STOP_GRACE, server.stop().wait())
                .await
                .is_err()
            {
                tracing::warn!("roam view: WebSocket clients did not close within {STOP_GRACE:?}");
            }
        }
        let recording = roam_runtime::lock(&self.mcap).take();
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

#[cfg(test)]
mod tests {
    use super::*;
    use foxglove::messages::SceneEntity;
    use foxglove::Decode;

    fn update(id: &str, filler: usize) -> Arc<[u8]> {
        let update = SceneUpdate {
            entities: vec![SceneEntity {
                id: id.to_owned(),
                frame_id: "x".repeat(filler),
                ..SceneEntity::default()
            }],
            ..SceneUpdate::default()
        };
        let mut buf = Vec::new();
        update.encode(&mut buf).expect("encode");
        buf.into()
    }

    #[test]
    fn the_robots_kept_are_replayed_as_a_few_scene_updates_holding_them_all() {
        let context = Context::new();
        let channel = context
            .channel_builder("/t")
            .message_encoding("protobuf")
            .build_raw()
            .expect("channel");
        let mut robots = BTreeMap::new();
        for i in 0..300 {
            robots.insert(
                format!("r{i:03}"),
                update(&format!("mission/r{i:03}"), 20_000),
            );
        }
        let kept = Kept {
            channel,
            whole: None,
            robots,
        };
        let messages = kept.replay();
        assert!(messages.len() < 10, "{} messages", messages.len());
        let mut ids = Vec::new();
        for bytes in &messages {
            assert!(bytes.len() <= REPLAY_BATCH_BYTES, "{}", bytes.len());
            let update = SceneUpdate::decode(bytes.as_slice()).expect("one SceneUpdate");
            ids.extend(update.entities.into_iter().map(|e| e.id));
        }
        let expected: Vec<String> = (0..300).map(|i| format!("mission/r{i:03}")).collect();
        assert_eq!(ids, expected);
    }
}
