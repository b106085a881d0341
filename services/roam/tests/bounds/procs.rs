//! The stack under attack as separate `roam` processes, so each one's memory is its
//! own: spawned with their logs in one folder, measured from the kernel's accounting,
//! killed when the test ends.

use std::fs::File;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use roam_proto::keys;

pub(crate) const ROAM: &str = env!("CARGO_BIN_EXE_roam");

/// One `roam` process.
pub(crate) struct Proc {
    pub(crate) name: String,
    child: Child,
}

impl Proc {
    /// Starts `roam <args>` as a client of `endpoint`, logging to `<dir>/<name>.log`.
    pub(crate) fn start(dir: &Path, name: &str, args: &[&str]) -> Proc {
        let log = File::create(dir.join(format!("{name}.log"))).expect("log file");
        let child = Command::new(ROAM)
            .args(args)
            .env("RUST_LOG", "info")
            .stdout(Stdio::null())
            .stderr(log)
            .spawn()
            .expect("spawn roam");
        Proc {
            name: name.to_owned(),
            child,
        }
    }

    /// Peak resident memory so far (`VmHWM`), MiB.
    pub(crate) fn peak_mib(&self) -> u64 {
        self.status_kib("VmHWM:") / 1024
    }

    /// Resident memory now (`VmRSS`), MiB.
    pub(crate) fn rss_mib(&self) -> u64 {
        self.status_kib("VmRSS:") / 1024
    }

    fn status_kib(&self, field: &str) -> u64 {
        std::fs::read_to_string(format!("/proc/{}/status", self.child.id()))
            .ok()
            .and_then(|s| {
                s.lines()
                    .find(|l| l.starts_with(field))
                    .and_then(|l| l.split_whitespace().nth(1))
                    .and_then(|v| v.parse().ok())
            })
            .unwrap_or(0)
    }

    /// Whether the process is still running (it did not crash or exit).
    pub(crate) fn running(&mut self) -> bool {
        matches!(self.child.try_wait(), Ok(None))
    }
}

impl Drop for Proc {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A client session of the router at `endpoint`, once the router process listens.
pub(crate) async fn connect(endpoint: &str) -> zenoh::Session {
    let started = std::time::Instant::now();
    loop {
        let config = roam_runtime::SessionArgs::client_of(endpoint)
            .zenoh_config(None)
            .expect("config");
        match roam_runtime::session::open(config).await {
            Ok(session) => return session,
            Err(e) if started.elapsed() > Duration::from_secs(30) => panic!("no router: {e}"),
            Err(_) => tokio::time::sleep(Duration::from_millis(100)).await,
        }
    }
}

/// Waits until `<root>/@live/<service>/*` holds a token.
pub(crate) async fn wait_live(session: &zenoh::Session, root: &str, service: &str) {
    roam_runtime::wait_for_liveliness(
        session,
        &keys::liveliness_of(root, service),
        Duration::from_secs(60),
    )
    .await
    .unwrap_or_else(|e| panic!("{service} never came up: {e:?}"));
}
