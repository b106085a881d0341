//! The flags of the client subcommands (key root, answer timeout, Zenoh session), and
//! connecting to a running stack with them.

use std::time::Duration;

use anyhow::bail;
use clap::Args;
use roam_proto::keys;
use roam_runtime::{Requester, SessionArgs};

#[derive(Debug, Args)]
pub(crate) struct ClientArgs {
    #[arg(long, env = "ROAM_ROOT", default_value = keys::DEFAULT_ROOT)]
    pub(crate) root: String,
    /// Seconds to wait for an answer.
    #[arg(long, default_value_t = 5.0)]
    pub(crate) timeout: f64,
    #[command(flatten)]
    pub(crate) session: SessionArgs,
}

pub(crate) async fn connect(client: &ClientArgs) -> anyhow::Result<(Requester, zenoh::Session)> {
    if !(client.timeout.is_finite() && client.timeout > 0.0) {
        bail!("--timeout must be a positive number of seconds");
    }
    let session = roam_runtime::session::open(client.session.zenoh_config(None)?).await?;
    Ok((
        Requester::new(session.clone(), Duration::from_secs_f64(client.timeout)),
        session,
    ))
}
