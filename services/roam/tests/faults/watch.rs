//! What the test watches through Zenoh while it kills: liveliness tokens, the map
//! server's layer versions (none may go back), each role's downtime, the window reports.

use std::collections::BTreeMap;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use roam_proto::mission::WindowReport;
use roam_runtime::Requester;

use crate::fleet::Fleet;

/// The whole run, kills and the mission, must end within this.
pub(crate) const RUN_LIMIT: Duration = Duration::from_secs(240);

/// Whether the token `key` is there (`live`) or gone within `limit`.
pub(crate) async fn wait_live(
    session: &zenoh::Session,
    key: &str,
    live: bool,
    limit: Duration,
) -> bool {
    roam_bench::chaos::watch::wait_live(session, key, live, limit)
        .await
        .is_some()
}

pub(crate) use roam_bench::chaos::watch::versions;

/// Every layer seen before is there with at least its version.
pub(crate) fn none_lost(
    before: &BTreeMap<String, u64>,
    after: &BTreeMap<String, u64>,
) -> Result<(), String> {
    let gone = roam_bench::chaos::watch::gone_back(before, after);
    if gone.is_empty() {
        return Ok(());
    }
    Err(format!(
        "layers gone or at a lower version: {gone:?} (before {before:?}, after {after:?})"
    ))
}

/// What the test watches while it kills: the map's versions and each role's downtime.
pub(crate) struct Watch<'a> {
    pub(crate) session: &'a zenoh::Session,
    pub(crate) requester: &'a Requester,
    pub(crate) started: Instant,
    pub(crate) seen: BTreeMap<String, u64>,
    pub(crate) downtime: Vec<(String, Duration)>,
}

impl Watch<'_> {
    /// The latest versions, checked against every version seen before.
    pub(crate) async fn check_versions(&mut self, fleet: &Fleet, when: &str) {
        let now = loop {
            if let Some(v) = versions(self.requester, &fleet.root).await {
                break v;
            }
            assert!(
                self.started.elapsed() < RUN_LIMIT,
                "the map server stopped answering {when}\n{}",
                fleet.logs()
            );
            tokio::time::sleep(Duration::from_millis(100)).await;
        };
        none_lost(&self.seen, &now).unwrap_or_else(|e| panic!("{when}: {e}\n{}", fleet.logs()));
        self.seen = now;
    }

    /// SIGKILL one role, start it again, wait for its liveliness token.
    pub(crate) async fn kill_and_restart(&mut self, fleet: &mut Fleet, name: &str) {
        fleet.restart_exited();
        self.check_versions(fleet, &format!("before killing {name}"))
            .await;
        let key = fleet
            .roles
            .iter()
            .find(|r| r.name == name)
            .map(|r| r.live_key.clone())
            .expect("a role of the fleet");
        let killed = Instant::now();
        fleet.kill(name);
        assert!(
            wait_live(self.session, &key, false, Duration::from_secs(10)).await,
            "{key} stayed live after SIGKILL"
        );
        fleet.start(name);
        assert!(
            wait_live(self.session, &key, true, Duration::from_secs(30)).await,
            "{key} did not come back\n{}",
            fleet.logs()
        );
        self.downtime.push((name.to_owned(), killed.elapsed()));
        self.check_versions(fleet, &format!("after killing {name}"))
            .await;
    }

    /// Waits for the window report of `task`, restarting what exits meanwhile.
    pub(crate) async fn report(
        &mut self,
        fleet: &mut Fleet,
        reports: &Mutex<Vec<WindowReport>>,
        task: &str,
    ) -> WindowReport {
        loop {
            fleet.restart_exited();
            let done: Vec<WindowReport> = reports.lock().expect("reports").clone();
            if let Some(r) = done.iter().find(|r| r.task == task) {
                return r.clone();
            }
            assert!(
                self.started.elapsed() < RUN_LIMIT,
                "no report for {task} within {RUN_LIMIT:?}; reports: {done:?}\n{}",
                fleet.logs()
            );
            tokio::time::sleep(Duration::from_millis(200)).await;
        }
    }
}
