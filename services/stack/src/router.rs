//! A Zenoh router inside roam: `roam router` for a fleet (nothing else to install) and
//! the in-process router of `roam stack` and the tests.

use std::net::TcpListener;

use roam_runtime::{session, SessionArgs, SessionError};

/// A running router session and the endpoint clients connect to.
#[derive(Debug)]
pub struct Router {
    pub session: zenoh::Session,
    pub endpoint: String,
}

/// A free TCP port on loopback, found by binding port 0 and letting it go. Another
/// process could take it in between; [`Router::on_loopback`] retries for that reason.
pub fn free_loopback_port() -> std::io::Result<u16> {
    Ok(TcpListener::bind("127.0.0.1:0")?.local_addr()?.port())
}

impl Router {
    /// A router on `tcp/127.0.0.1:<free port>` with multicast scouting off: what the
    /// in-process stack and every integration test run around.
    pub async fn on_loopback() -> Result<Router, SessionError> {
        let mut last = None;
        for _ in 0..5 {
            let port = free_loopback_port()
                .map_err(|e| SessionError::Open(format!("no free loopback port: {e}")))?;
            let endpoint = format!("tcp/127.0.0.1:{port}");
            match Router::start(&SessionArgs::router_on(&endpoint), endpoint.clone()).await {
                Ok(router) => return Ok(router),
                Err(e) => last = Some(e),
            }
        }
        Err(last.unwrap_or_else(|| SessionError::Open("no router could be started".into())))
    }

    /// A router with the given session flags (mode forced to router).
    pub async fn start(args: &SessionArgs, endpoint: String) -> Result<Router, SessionError> {
        let mut args = args.clone();
        args.mode = Some("router".into());
        let config = args.zenoh_config(None)?;
        let session = session::open(config).await?;
        Ok(Router { session, endpoint })
    }

    pub async fn close(self) {
        if let Err(e) = self.session.close().await {
            tracing::warn!("closing the router failed: {e}");
        }
    }
}
