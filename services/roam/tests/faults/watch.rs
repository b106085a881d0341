//! What the test watches through Zenoh while it kills: liveliness tokens, the map
//! server's layer versions (none may go back), each role's downtime, the window reports.

use std::collections::BTreeMap;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use roam_proto::keys;
use roam_proto::map::LayerList;
use roam_proto::mission::WindowReport;
use roam_runtime::Requester;

use crate::fleet::Fleet;

/// The whole run, kills and the mission, must end within this.
pub(crate) const RUN_LIMIT: Duration = Duration::from_secs(240);

pub(crate) async fn is_live(session: &zenoh::Session, key: &str) -> bool {
    match session
        .liveliness()
        .get(key)
        .timeout(Duration::from_millis(500))
        .await
    {
        Ok(replies) => replies.recv_async().await.is_ok(),
        Err(_) => false,
    }
}

pub(crate) async fn wait_live(
    session: &zenoh::Session,
    key: &str,
    live: bool,
    limit: Duration,
) -> bool {
    let started = Instant::now();
    while started.elapsed() < limit {
        if is_live(session, key).await == live {
            return true;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    false
}

pub(crate) async fn versions(requester: &Requester, root: &str) -> Option<BTreeMap<String, u64>> {
    let list: LayerList = requester
        .request::<LayerList, LayerList>(&keys::map_index(root), None)
        .await
        .ok()?;
    Some(
        list.layers
            .into_iter()
            .map(|l| (l.name, l.version))
            .collect(),
    )
}

/// Every layer seen before is there with at least its version.
pub(crate) fn none_lost(
    before: &BTreeMap<String, u64>,
    after: &BTreeMap<String, u64>,
) -> Result<(), String> {
    for (name, v) in before {
        match after.get(name) {
            Some(w) if w >= v => {}
            Some(w) => return Err(format!("layer {name} went back from version {v} to {w}")),
            None => return Err(format!("layer {name} (version {v}) is gone")),
        }
    }
    Ok(())
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
        let i = fleet
            .roles
            .iter()
            .position(|r| format!("{}-{}", r.service, r.instance) == name)
            .expect("a role of the fleet");
        let key = fleet.live_key(i);
        let killed = Instant::now();
        fleet.kill(i);
        assert!(
            wait_live(self.session, &key, false, Duration::from_secs(10)).await,
            "{key} stayed live after SIGKILL"
        );
        fleet.roles[i].restarts += 1;
        fleet.start(i);
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
