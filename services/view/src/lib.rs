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
//!   connects late see the maps;
//! - [`access`], `head` and `gate`: who may connect (the `Origin` allow-list and the
//!   token), checked by roam's own listener in front of the SDK's server.

pub mod access;
pub mod convert;
mod follow;
mod gate;
mod head;
mod output;
mod roster;
pub mod wire;

use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::Arc;

use tokio::task::JoinHandle;
use tokio_util::sync::CancellationToken;

pub use access::{Access, AccessError, Token, FOXGLOVE_APP_ORIGIN};
pub use follow::{
    ANCHORS_TOPIC, DRIVEN_POINTS, DRIVEN_TOPIC, ESTIMATE_TOPIC, MAX_LAYERS, MAX_LAYER_BYTES_SHOWN,
    MAX_LAYER_CELLS, MAX_ROBOTS, MISSION_TOPIC, REFRESH_PERIOD, TRUTH_TOPIC,
};
pub use gate::{HEAD_TIMEOUT, MAX_CONNECTIONS, MAX_HALF_OPEN};
pub use head::MAX_HEAD_BYTES;
pub use output::{ViewStats, CLIENT_BACKLOG, INNER_PORTS};

/// The port the Foxglove app suggests for a WebSocket connection.
pub const DEFAULT_PORT: u16 = 8765;

/// The environment variable `roam view` reads a token from (see [`Token`]).
pub const TOKEN_ENV: &str = "ROAM_VIEW_TOKEN";

/// What the view follows and where it sends it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ViewConfig {
    /// The key root of the stack to show.
    pub root: String,
    /// Where the Foxglove WebSocket server listens (port 0 picks a free one); no server
    /// when `None`. An address other than loopback needs a token in `access`.
    pub listen: Option<SocketAddr>,
    /// Record every message to this MCAP file (replaced if it exists); no recording when
    /// `None`.
    pub mcap: Option<PathBuf>,
    /// Who may connect to the WebSocket server.
    pub access: Access,
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
    #[error("the live view would be open to the network on {0} without a token: anyone who reaches it could read the fleet's positions and maps; give it a token (--token-file FILE or {TOKEN_ENV}) or listen on loopback (127.0.0.1)")]
    OpenWithoutToken(SocketAddr),
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
    needs_token: bool,
    counters: Arc<output::Counters>,
    task: JoinHandle<Result<ViewStats, ViewError>>,
}

impl ViewHandle {
    /// Where the WebSocket server listens (with the port it got when asked for port 0).
    pub fn websocket_addr(&self) -> Option<SocketAddr> {
        self.listening
    }

    /// The URL to give the Foxglove app: `ws://HOST:PORT`, with `/?token=<token>` to be
    /// added when a token is needed (the token itself is never printed).
    pub fn websocket_url(&self) -> Option<String> {
        self.listening.map(|addr| {
            if self.needs_token {
                format!("ws://{addr}/?token=<token>")
            } else {
                format!("ws://{addr}")
            }
        })
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

/// Refuses to serve the view on an address other than loopback without a token (what
/// [`run`] checks first; callers that do much before starting the view check it early).
pub fn check_exposure(listen: SocketAddr, access: &Access) -> Result<(), ViewError> {
    if listen.ip().is_loopback() || access.needs_token() {
        Ok(())
    } else {
        Err(ViewError::OpenWithoutToken(listen))
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
    if let Some(addr) = config.listen {
        check_exposure(addr, &config.access)?;
    }
    // The public address first, so that a taken one is reported as such.
    let public = match config.listen {
        Some(addr) => {
            let refused = |e: std::io::Error| ViewError::Listen {
                addr,
                reason: e.to_string(),
            };
            let listener = tokio::net::TcpListener::bind(addr).await.map_err(refused)?;
            let bound = listener.local_addr().map_err(refused)?;
            Some((listener, bound))
        }
        None => None,
    };
    let listening = public.as_ref().map(|(_, bound)| *bound);
    let subscriptions = roam_runtime::FleetStreams::declare(&session, &config.root)
        .await
        .map_err(|e| ViewError::Zenoh(e.to_string()))?;
    let out = Arc::new(output::Outputs::start(public.is_some(), config.mcap.as_deref()).await?);
    let gate = match (public, out.inner) {
        (Some((listener, _)), Some(inner)) => {
            Some(gate::Gate::start(listener, inner, config.access.clone()))
        }
        _ => None,
    };
    if let Some(addr) = listening {
        tracing::info!(
            root = %config.root,
            origins = ?config.access.origins(),
            token = config.access.needs_token(),
            "roam view: Foxglove WebSocket on ws://{addr}"
        );
    }
    if let Some(path) = &config.mcap {
        tracing::info!(root = %config.root, "roam view: recording to {}", path.display());
    }
    let root = config.root.clone();
    let counters = out.counters.clone();
    let task = tokio::spawn(async move {
        follow::follow(session, root, subscriptions, out.clone(), cancel).await;
        let stopped = out.stop().await;
        if let Some(gate) = gate {
            gate.stop().await;
        }
        stopped?;
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
        needs_token: config.access.needs_token(),
        counters,
        task,
    })
}
