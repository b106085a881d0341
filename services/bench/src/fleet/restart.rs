//! The restart phase: the router's process killed and started again on its endpoint,
//! and how the loop came back.

use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use roam_experiments::progress::{Done, Progress};
use roam_proto::sim::{SimControl, SimStatus};
use roam_runtime::Requester;

use super::router::RouterProcess;
use super::seen::Seen;
use crate::BenchError;

/// How long the restart phase runs steadily before the router is killed.
pub const RESTART_LEAD: Duration = Duration::from_secs(2);
/// How long the router stays down: from its SIGKILL to the start of the new one (what
/// `deploy/systemd/roam@.service` waits before it restarts a role, `RestartSec=1s`).
pub const ROUTER_DOWN: Duration = Duration::from_secs(1);
/// How long after the restart the bench waits for every robot to be commanded again
/// before it reports how many were.
pub const RECOVERY_LIMIT: Duration = Duration::from_secs(30);
/// How long the restart phase runs on after every robot has been commanded again.
pub const RESTART_TAIL: Duration = Duration::from_secs(2);

/// What the router's restart did.
pub(super) struct Restart {
    pub(super) down: Duration,
    pub(super) first: Option<Duration>,
    pub(super) all: Option<Duration>,
    pub(super) commanded: usize,
    /// Steps, and the commands on time in them.
    pub(super) outside: (u64, u64),
    pub(super) inside: (u64, u64),
}

/// The restart phase: the sim runs again, the router is killed and started again on its
/// endpoint, and the bench waits until every robot is commanded again.
#[expect(clippy::too_many_arguments)]
pub(super) async fn restart(
    router: &mut RouterProcess,
    router_program: &Path,
    client: &Requester,
    control_key: &str,
    rate_hz: f64,
    (seen, latest): (&Mutex<Seen>, &AtomicU64),
    robots: usize,
    progress: Progress<'_>,
) -> Result<Restart, BenchError> {
    let status: SimStatus = client
        .request(control_key, Some(&SimControl::Status))
        .await?;
    let from_step = latest.load(Ordering::Acquire) + 1;
    client
        .request::<SimControl, SimStatus>(
            control_key,
            Some(&SimControl::Resume {
                rate: rate_hz * status.step_s,
            }),
        )
        .await?;
    tokio::time::sleep(RESTART_LEAD).await;
    let kill_step = latest.load(Ordering::Acquire);
    let killed = Instant::now();
    router.kill();
    tokio::time::sleep(ROUTER_DOWN).await;
    let endpoint = router.endpoint.clone();
    *router = RouterProcess::spawn(router_program, &endpoint)?;
    let restarted = Instant::now();
    roam_runtime::lock(seen).since = Some(restarted);
    loop {
        let again = roam_runtime::lock(seen).again.len();
        progress(Done::of("router restart", "robots", again, robots));
        if again >= robots || restarted.elapsed() >= RECOVERY_LIMIT {
            break;
        }
        if let Some(status) = router.exited() {
            return Err(BenchError::Setup(format!(
                "the restarted router on {endpoint} exited ({status})"
            )));
        }
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    let recovered_step = latest.load(Ordering::Acquire);
    tokio::time::sleep(RESTART_TAIL).await;
    client
        .request::<SimControl, SimStatus>(control_key, Some(&SimControl::Pause))
        .await?;
    // The last step's commands.
    tokio::time::sleep(Duration::from_millis(500)).await;
    let last_step = latest.load(Ordering::Acquire);

    let seen = roam_runtime::lock(seen);
    let after = |t: &Instant| t.saturating_duration_since(restarted);
    let commanded = seen.again.len();
    // The steps from..=to and the commands on time for them.
    let count = |from: u64, to: u64| {
        if from > to {
            return (0, 0);
        }
        let on_time: u64 = seen.on_time_at.range(from..=to).map(|(_, n)| n).sum();
        (to - from + 1, on_time)
    };
    let inside = count(kill_step, recovered_step);
    let before = count(from_step, kill_step.saturating_sub(1));
    let tail = count(recovered_step + 1, last_step);
    Ok(Restart {
        down: restarted - killed,
        first: seen.again.values().min().map(after),
        all: (commanded >= robots)
            .then(|| seen.again.values().max().map(after))
            .flatten(),
        commanded,
        outside: (before.0 + tail.0, before.1 + tail.1),
        inside,
    })
}
