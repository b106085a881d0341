//! The router in a process of its own, so that its CPU and memory are measured apart
//! from the loop's (by its pid, from `/proc/<pid>`): started on a free loopback port,
//! killed, started again.

use std::path::Path;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use roam_runtime::SessionArgs;
use roam_stack::router::free_loopback_port;

use crate::{setup, BenchError};

/// How long a new router process may take to accept its first client.
const ROUTER_START_LIMIT: Duration = Duration::from_secs(20);

/// The router in its own process, `<program> router --listen <endpoint>
/// --no-multicast`, its output dropped; killed with SIGKILL when dropped.
pub(super) struct RouterProcess {
    child: Child,
    pub(super) endpoint: String,
}

impl RouterProcess {
    pub(super) fn spawn(program: &Path, endpoint: &str) -> Result<RouterProcess, BenchError> {
        let child = Command::new(program)
            .args(["router", "--listen", endpoint, "--no-multicast"])
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .map_err(|e| {
                BenchError::Setup(format!(
                    "cannot start the router ({} router): {e}",
                    program.display()
                ))
            })?;
        Ok(RouterProcess {
            child,
            endpoint: endpoint.to_owned(),
        })
    }

    pub(super) fn pid(&self) -> u32 {
        self.child.id()
    }

    /// How the process ended, if it has.
    pub(super) fn exited(&mut self) -> Option<ExitStatus> {
        self.child.try_wait().ok().flatten()
    }

    /// SIGKILL, and reaps the process.
    pub(super) fn kill(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Drop for RouterProcess {
    fn drop(&mut self) {
        self.kill();
    }
}

/// A router process on a free loopback port, and a client session of it (the bench's).
/// A router that exits before it accepts a client (another process took the port in
/// between) is tried again on another port, five times in all.
pub(super) async fn start_router(
    program: &Path,
) -> Result<(RouterProcess, zenoh::Session), BenchError> {
    let mut last = String::from("no attempt");
    for _ in 0..5 {
        let port = free_loopback_port().map_err(setup)?;
        let mut router = RouterProcess::spawn(program, &format!("tcp/127.0.0.1:{port}"))?;
        let started = Instant::now();
        loop {
            // A session only once the port takes connections: Zenoh warns of each one
            // refused.
            if std::net::TcpStream::connect(("127.0.0.1", port)).is_err() {
                last = format!("nothing listens on {} yet", router.endpoint);
            } else {
                let config = SessionArgs::client_of(&router.endpoint)
                    .zenoh_config(None)
                    .map_err(setup)?;
                match roam_runtime::session::open(config).await {
                    Ok(session) => return Ok((router, session)),
                    Err(e) => last = e.to_string(),
                }
            }
            if let Some(status) = router.exited() {
                last = format!("the router on {} exited ({status})", router.endpoint);
                break;
            }
            if started.elapsed() > ROUTER_START_LIMIT {
                return Err(BenchError::Setup(format!(
                    "the router on {} accepted no client within {ROUTER_START_LIMIT:?}: {last}",
                    router.endpoint
                )));
            }
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
    }
    Err(BenchError::Setup(format!(
        "no router could be started ({} router): {last}",
        program.display()
    )))
}
