//! `roam view`: a running stack in the Foxglove app (a Foxglove WebSocket server) and an
//! MCAP recording of it. The work is in `roam_view`; see `services/view/README.md`.

use std::net::SocketAddr;
use std::path::PathBuf;

use anyhow::bail;
use clap::Args;
use roam_runtime::signals;
use roam_view::ViewConfig;

use super::{connect, ClientArgs};

#[derive(Debug, Args)]
pub(crate) struct ViewArgs {
    #[command(flatten)]
    client: ClientArgs,
    /// Where the Foxglove WebSocket server listens: open ws://ADDR in the Foxglove app.
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
}

pub(crate) async fn view(args: ViewArgs) -> anyhow::Result<()> {
    if args.no_ws && args.mcap.is_none() {
        bail!("--no-ws leaves the view nothing to do: add --mcap FILE");
    }
    let (_, session) = connect(&args.client).await?;
    let cancel = signals::cancel_on_signal();
    let config = ViewConfig {
        root: args.client.root.clone(),
        listen: (!args.no_ws).then_some(args.ws),
        mcap: args.mcap,
        access: roam_view::Access::default(),
    };
    let view = roam_view::run(session.clone(), config, cancel).await?;
    if let Some(url) = view.websocket_url() {
        eprintln!("roam view: in the Foxglove app, Open connection -> Foxglove WebSocket -> {url}");
    }
    if let Some(path) = view.mcap_path() {
        eprintln!("roam view: recording to {}", path.display());
    }
    eprintln!("roam view: stop with Ctrl-C or SIGTERM");
    let outcome = view.join().await;
    let _ = session.close().await;
    let stats = outcome?;
    eprintln!(
        "roam view: {} messages logged, {} dropped",
        stats.logged, stats.dropped
    );
    Ok(())
}
