//! Opening a topology's two sessions (and its router) on a free loopback port, and
//! closing them.

use roam_runtime::session::SessionError;
use roam_runtime::SessionArgs;
use roam_stack::router::{free_loopback_port, Router};
use zenoh::Session;

use super::tls::{tls_connect, tls_listen, Certs};
use super::topology::Topology;
use crate::{setup, BenchError};

/// Attempts at a free loopback port (another process may take the one found).
const PORT_ATTEMPTS: usize = 5;

async fn open(args: &SessionArgs) -> Result<Session, BenchError> {
    let config = args.zenoh_config(None).map_err(setup)?;
    roam_runtime::session::open(config).await.map_err(setup)
}

/// Two sessions with the same flags: the receiver's, then the sender's.
async fn open_two(args: &SessionArgs) -> Result<(Session, Session), BenchError> {
    Ok((open(args).await?, open(args).await?))
}

/// The two sessions of one topology, and its router.
pub(super) struct Wire {
    pub(super) sender: Session,
    pub(super) receiver: Session,
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
    pub(super) async fn open(topology: Topology, certs: &Certs) -> Result<Wire, BenchError> {
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

    /// Closes the sessions, then the router.
    pub(super) async fn close(self) {
        let _ = self.sender.close().await;
        let _ = self.receiver.close().await;
        if let Some(router) = self.router {
            router.close().await;
        }
    }
}
