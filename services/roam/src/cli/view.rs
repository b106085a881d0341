//! `roam view`: a running stack in the Foxglove app (a Foxglove WebSocket server) and an
//! MCAP recording of it. The work is in `roam_view`; see `services/view/README.md`.

use std::net::SocketAddr;
use std::path::PathBuf;

use anyhow::{bail, Context};
use clap::Args;
use roam_runtime::signals;
use roam_view::{Access, Token, ViewConfig, TOKEN_ENV};

use super::client::{connect, ClientArgs};

/// Who may connect to the live view: shared by `roam view` and `roam demo --view`.
#[derive(Debug, Args)]
pub(crate) struct AccessArgs {
    /// A web origin (scheme://host[:port]) whose pages may open the live view; repeat for
    /// several. The list replaces the default, https://app.foxglove.dev (the Foxglove web
    /// app). Browser pages from any other origin get HTTP 403; clients that send no
    /// Origin (the Foxglove desktop app, scripts) are not browser pages and pass.
    #[arg(long = "allow-origin", value_name = "ORIGIN")]
    allow_origin: Vec<String>,
    /// Require this token (the file's one line: 16 to 256 of A-Z a-z 0-9 - . _ ~, e.g.
    /// from `openssl rand -hex 32`) from every client, as ws://HOST:PORT/?token=TOKEN or
    /// an `Authorization: Bearer TOKEN` header; others get HTTP 401. Also read from
    /// ROAM_VIEW_TOKEN. Needed to listen on an address other than loopback.
    #[arg(long, value_name = "FILE")]
    token_file: Option<PathBuf>,
}

impl AccessArgs {
    pub(crate) fn access(&self) -> anyhow::Result<Access> {
        let from_env = std::env::var(TOKEN_ENV).ok().filter(|t| !t.is_empty());
        let token = match (&self.token_file, from_env) {
            (Some(_), Some(_)) => {
                bail!("the view's token is given twice: use --token-file or {TOKEN_ENV}, not both")
            }
            (Some(path), None) => Some(Token::from_file(path)?),
            (None, Some(text)) => {
                Some(Token::new(&text).with_context(|| format!("in {TOKEN_ENV}"))?)
            }
            (None, None) => None,
        };
        let access = if self.allow_origin.is_empty() {
            Access::new([roam_view::FOXGLOVE_APP_ORIGIN], token)?
        } else {
            Access::new(&self.allow_origin, token)?
        };
        Ok(access)
    }
}

#[derive(Debug, Args)]
pub(crate) struct ViewArgs {
    #[command(flatten)]
    client: ClientArgs,
    /// Where the Foxglove WebSocket server listens: open ws://ADDR in the Foxglove app.
    /// Loopback by default; any other address (e.g. 0.0.0.0:8765) opens the fleet's
    /// positions and maps to the network and needs --token-file.
    /// (`--listen` is the Zenoh session's own endpoint.)
    #[arg(long, value_name = "ADDR", default_value_t = SocketAddr::from(([127, 0, 0, 1], roam_view::DEFAULT_PORT)))]
    ws: SocketAddr,
    /// No WebSocket server: only record (needs --mcap).
    #[arg(long)]
    no_ws: bool,
    /// Record every message to this MCAP file (replaced if it exists); it is complete once
    /// the view stops (Ctrl-C or SIGTERM).
    #[arg(long, value_name = "FILE")]
    mcap: Option<PathBuf>,
    #[command(flatten)]
    access: AccessArgs,
    /// Also record the ROS 2 topics (`roam ros2`'s: /map, the layers, each robot's plan,
    /// pose and driven path) as a rosbag2 (MCAP, profile ros2) in this new directory,
    /// for `ros2 bag play`; complete once the view stops.
    #[arg(long, value_name = "DIR")]
    rosbag: Option<PathBuf>,
}

pub(crate) async fn view(args: ViewArgs) -> anyhow::Result<()> {
    if args.no_ws && args.mcap.is_none() && args.rosbag.is_none() {
        bail!("--no-ws leaves the view nothing to do: add --mcap FILE or --rosbag DIR");
    }
    let access = args.access.access()?;
    let (_, session) = connect(&args.client).await?;
    let cancel = signals::cancel_on_signal();
    let config = ViewConfig {
        root: args.client.root.clone(),
        listen: (!args.no_ws).then_some(args.ws),
        mcap: args.mcap,
        access,
    };
    // The rosbag2 recorder is roam ros2's node without its ROS 2 endpoints: the same
    // conversions and CDR bytes, written to the bag instead of offered.
    let recorder = match &args.rosbag {
        Some(dir) => {
            let ros2 = roam_ros2::node::Ros2Config {
                service: roam_runtime::service_config::ServiceConfig::at(args.client.root.clone()),
                offer: false,
                rosbag: Some(dir.clone()),
                ..roam_ros2::node::Ros2Config::default()
            };
            let zenoh = args.client.session.zenoh_config(None)?;
            let stop = cancel.clone();
            eprintln!("roam view: recording the ROS 2 topics to {}", dir.display());
            Some(tokio::spawn(roam_ros2::node::run(ros2, zenoh, stop)))
        }
        None => None,
    };
    if config.listen.is_none() && config.mcap.is_none() {
        cancel.cancelled().await;
        if let Some(recorder) = recorder {
            recorder.await??;
        }
        let _ = session.close().await;
        return Ok(());
    }
    let view = roam_view::run(session.clone(), config, cancel).await?;
    if let Some(url) = view.websocket_url() {
        eprintln!("roam view: in the Foxglove app, Open connection -> Foxglove WebSocket -> {url}");
    }
    if let Some(path) = view.mcap_path() {
        eprintln!("roam view: recording to {}", path.display());
    }
    eprintln!("roam view: stop with Ctrl-C or SIGTERM");
    let outcome = view.join().await;
    if let Some(recorder) = recorder {
        recorder.await??;
    }
    let _ = session.close().await;
    let stats = outcome?;
    eprintln!(
        "roam view: {} messages logged, {} dropped ({} over their size cap, unread)",
        stats.logged, stats.dropped, stats.oversized
    );
    Ok(())
}
