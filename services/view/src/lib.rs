//! roam's live view: what a running stack does, in the Foxglove app.
//!
//! [`run`] follows roam's keys on a Zenoh session (the map server's layers, the robots'
//! true positions, estimates and missions, the sim's anchors) and logs them as Foxglove
//! messages (`foxglove.Grid`, `foxglove.SceneUpdate`) to a Foxglove WebSocket server that
//! the Foxglove app connects to, and/or to an MCAP file. See `README.md` beside this
//! crate for how to open it and what each topic holds.
//!
//! - [`convert`]: roam messages as Foxglove messages (pure functions);
//! - `follow`: the Zenoh subscriptions and queries, and what is logged where;
//! - `wire`: the caps on what is read from Zenoh and the escaping of what is shown;
//! - `roster`: per-robot state for a bounded number of robots;
//! - `output`: the WebSocket server, the MCAP file and the latch that lets a client that
//!   connects late see the maps.

pub mod convert;
mod follow;
mod output;
mod roster;
pub mod wire;

use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::Arc;

use tokio::task::JoinHandle;
use tokio_util::sync::CancellationToken;

pub use follow::{
    ANCHORS_TOPIC, DRIVEN_POINTS, DRIVEN_TOPIC, ESTIMATE_TOPIC, MAX_LAYERS, MAX_LAYER_BYTES_SHOWN,
    MAX_LAYER_CELLS, MAX_ROBOTS, MISSION_TOPIC, REFRESH_PERIOD, TRUTH_TOPIC,
};
pub use output::{ViewStats, CLIENT_BACKLOG};

/// The port the Foxglove app suggests for a WebSocket connection.
pub const DEFAULT_PORT: u16 = 8765;

/// What the view follows and where it sends it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ViewConfig {
    /// The key root of the stack to show.
    pub root: String,
    /// Where the Foxglove WebSocket server listens (port 0 picks a free one); no server
    /// when `None`.
    pub listen: Option<SocketAddr>,
    /// Record every message to this MCAP file (replaced if it exists); no recording when
    /// `None`.
    pub mcap: Option<PathBuf>,
}

/// Why the view could not start or stop cleanly.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    #[error(transparent)]
    Root(#[from] roam_proto::keys::KeyError),
    #[error("the view has nowhere to send its messages: give it a WebSocket address, an MCAP file or both")]
    NoOutput,
    #[error("the Foxglove WebSocket server cannot listen on {addr}: {reason}")]
    Listen { addr: SocketAddr, reason: String },
    #[error("cannot record to {path}: {reason}")]
    Record { path: PathBuf, reason: String },
    #[error("zenoh: {0}")]
    Zenoh(String),
    #[error("the view's task failed: {0}")]
    Task(String),
}

/// A running view. It runs until the token given to [`run`] is cancelled; then
/// [`ViewHandle::join`] stops the WebSocket server and finishes the MCAP file.
#[derive(Debug)]
pub struct ViewHandle {
    listening: Option<SocketAddr>,
    mcap: Option<PathBuf>,
    counters: Arc<output::Counters>,
    task: JoinHandle<Result<ViewStats, ViewError>>,
}

impl ViewHandle {
    /// Where the WebSocket server listens (with the port it got when asked for port 0).
    pub fn websocket_addr(&self) -> Option<SocketAddr> {
        self.listening
    }

    /// The URL to give the Foxglove app: `ws://HOST:PORT`.
    pub fn websocket_url(&self) -> Option<String> {
        self.listening.map(|addr| format!("ws://{addr}"))
    }

    /// What the view has done so far.
    pub fn stats(&self) -> ViewStats {
        self.counters.stats()
    }

    /// The MCAP file being recorded.
    pub fn mcap_path(&self) -> Option<&std::path::Path> {
        self.mcap.as_deref()
    }

    /// Waits until the view has stopped (after its token is cancelled): the WebSocket
    /// server closed and the MCAP file complete. Returns what it logged.
    pub async fn join(self) -> Result<ViewStats, ViewError> {
        self.task
            .await
            .unwrap_or_else(|e| Err(ViewError::Task(e.to_string())))
    }
}

/// Starts the view on `session`: the WebSocket server and the MCAP file are open and the
/// subscriptions declared when this returns. It runs until `cancel`.
pub async fn run(
    session: zenoh::Session,
    config: ViewConfig,
    cancel: CancellationToken,
) -> Result<ViewHandle, ViewError> {
    roam_proto::keys::check_root(&config.root)?;
    if config.listen.is_none() && config.mcap.is_none() {
        return Err(ViewError::NoOutput);
    }
    let subscriptions = follow::Subscriptions::declare(&session, &config.root).await?;
    let out = Arc::new(output::Outputs::start(config.listen, config.mcap.as_deref()).await?);
    let listening = out.listening;
    if let Some(addr) = listening {
        tracing::info!(root = %config.root, "roam view: Foxglove WebSocket on ws://{addr}");
    }
    if let Some(path) = &config.mcap {
        tracing::info!(root = %config.root, "roam view: recording to {}", path.display());
    }
    let root = config.root.clone();
    let counters = out.counters.clone();
    let task = tokio::spawn(async move {
        follow::follow(session, root, subscriptions, out.clone(), cancel).await;
        out.stop().await?;
        let stats = out.counters.stats();
        tracing::info!(
            logged = stats.logged,
            dropped = stats.dropped,
            oversized = stats.oversized,
            "roam view stopped"
        );
        Ok(stats)
    });
    Ok(ViewHandle {
        listening,
        mcap: config.mcap,
        counters,
        task,
    })
}
