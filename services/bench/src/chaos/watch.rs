//! What the chaos day watches through Zenoh, as a client: the sim clock, every robot's
//! estimates, controller statuses and window reports, the watched robot's executive
//! statuses, liveliness tokens, and each role's first good answer
//! after a fault.

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use roam_proto::controller::{ControllerStatus, MissionState};
use roam_proto::map::LayerList;
use roam_proto::mapper::MapperStatus;
use roam_proto::mission::WindowReport;
use roam_proto::planner::{GaOverrides, Plan, PlanRequest, PlannerModel, ShortestPathUse};
use roam_proto::sim::SimClock;
use roam_proto::{decode, keys};
use roam_runtime::Requester;
use zenoh::pubsub::Subscriber;

use crate::{setup, BenchError};

/// What shows that a role works again.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Answer {
    /// The map server answers the layer list.
    Layers,
    /// The planner instance answers a plan: the fastest path between two free places of
    /// the site.
    Plan {
        instance: String,
        start: [f64; 2],
        goal: [f64; 2],
    },
    /// The mapper answers its status.
    MapperStatus,
    /// The role publishes on its key: `clock` (the sim), `estimate` (localization, any
    /// robot's), `controller` (any robot's status), `executive` (the watched robot's).
    Publishes(&'static str),
    /// Its liveliness token is all there is to ask (the ROS 2 node's roam side).
    Token,
}

#[derive(Debug, Default)]
struct Seen {
    clock: Option<f64>,
    /// The last publication of each pulse (the clock, any robot's estimate and
    /// controller status, the watched robot's executive status).
    last: BTreeMap<&'static str, Instant>,
    /// Every robot's window reports.
    reports: Vec<WindowReport>,
    /// Every robot's controller state, as last heard.
    states: BTreeMap<String, MissionState>,
}

/// The bench's view of the stack.
pub(super) struct Watch {
    pub(super) session: zenoh::Session,
    pub(super) requester: Requester,
    root: String,
    seen: Arc<Mutex<Seen>>,
    _subscribers: Vec<Subscriber<()>>,
}

fn lock(seen: &Mutex<Seen>) -> std::sync::MutexGuard<'_, Seen> {
    seen.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

impl Watch {
    pub(super) async fn start(
        session: zenoh::Session,
        root: &str,
        robot: &str,
    ) -> Result<Watch, BenchError> {
        let seen: Arc<Mutex<Seen>> = Arc::default();
        let mut subscribers = Vec::new();
        for (pulse, key) in [
            ("clock", keys::sim_clock(root)),
            // Localization and the controller serve every robot: any robot's estimate or
            // status is theirs. The executive is the watched robot's.
            ("estimate", keys::robot_estimate_any(root)),
            ("controller", keys::robot_controller_any(root)),
            ("executive", keys::robot_executive(root, robot)),
            ("report", keys::robot_mission_report(root, "*")),
        ] {
            let seen = seen.clone();
            let subscriber = session
                .declare_subscriber(&key)
                .callback(move |sample| {
                    let bytes = sample.payload().to_bytes();
                    let mut seen = lock(&seen);
                    match pulse {
                        "clock" => {
                            if let Ok(c) = decode::<SimClock>(&bytes) {
                                seen.clock = Some(c.time_s);
                            }
                        }
                        "controller" => {
                            if let Ok(s) = decode::<ControllerStatus>(&bytes) {
                                seen.states.insert(s.robot, s.state);
                            }
                        }
                        "report" => {
                            if let Ok(r) = decode::<WindowReport>(&bytes) {
                                seen.reports.push(r);
                            }
                            return;
                        }
                        _ => {}
                    }
                    seen.last.insert(pulse, Instant::now());
                })
                .await
                .map_err(setup)?;
            subscribers.push(subscriber);
        }
        Ok(Watch {
            requester: Requester::new(session.clone(), Duration::from_secs(5)),
            session,
            root: root.to_owned(),
            seen,
            _subscribers: subscribers,
        })
    }

    /// The sim's clock as last heard.
    pub(super) fn sim_s(&self) -> Option<f64> {
        lock(&self.seen).clock
    }

    pub(super) fn reports(&self) -> Vec<WindowReport> {
        lock(&self.seen).reports.clone()
    }

    /// Every robot's controller state, as last heard.
    pub(super) fn controller_states(&self) -> BTreeMap<String, MissionState> {
        lock(&self.seen).states.clone()
    }

    pub(super) fn live_key(&self, service: &str, instance: &str) -> String {
        keys::liveliness(&self.root, service, instance)
    }

    pub(super) async fn is_live(&self, key: &str) -> bool {
        is_live(&self.session, key).await
    }

    /// Waits until the token `key` is there (`live`) or gone; how long it took, `None`
    /// past `limit`.
    pub(super) async fn wait_live(
        &self,
        key: &str,
        live: bool,
        limit: Duration,
    ) -> Option<Duration> {
        wait_live(&self.session, key, live, limit).await
    }

    /// The map server's layers and versions, `None` when it does not answer.
    pub(super) async fn versions(&self) -> Option<BTreeMap<String, u64>> {
        versions(&self.requester, &self.root).await
    }

    /// Whether the role has given a good answer after `since`: asked now, or heard.
    pub(super) async fn answers(&self, answer: &Answer, since: Instant) -> bool {
        let short = Requester::new(self.session.clone(), Duration::from_secs(2));
        match answer {
            Answer::Layers => self.versions().await.is_some(),
            Answer::MapperStatus => short
                .request::<MapperStatus, MapperStatus>(&keys::mapper_status(&self.root), None)
                .await
                .is_ok(),
            Answer::Plan {
                instance,
                start,
                goal,
            } => {
                let request = probe_plan(*start, *goal);
                short
                    .request::<PlanRequest, Plan>(
                        &keys::planner_plan_at(&self.root, instance),
                        Some(&request),
                    )
                    .await
                    .is_ok()
            }
            Answer::Publishes(pulse) => {
                lock(&self.seen).last.get(pulse).is_some_and(|t| *t > since)
            }
            Answer::Token => true,
        }
    }
}

/// The map server's layers and their versions, `None` when it does not answer.
pub async fn versions(requester: &Requester, root: &str) -> Option<BTreeMap<String, u64>> {
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

/// The layers of `before` that are gone from `after` or at a lower version there: a
/// map server that lost what it had acked.
pub fn gone_back(before: &BTreeMap<String, u64>, after: &BTreeMap<String, u64>) -> Vec<String> {
    before
        .iter()
        .filter(|(name, v)| after.get(*name).is_none_or(|w| w < v))
        .map(|(name, _)| name.clone())
        .collect()
}

/// Whether a liveliness token `key` is held now, as `session` sees it.
pub async fn is_live(session: &zenoh::Session, key: &str) -> bool {
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

/// Waits until the token `key` is there (`live`) or gone; how long it took, `None` past
/// `limit`.
pub async fn wait_live(
    session: &zenoh::Session,
    key: &str,
    live: bool,
    limit: Duration,
) -> Option<Duration> {
    let started = Instant::now();
    while started.elapsed() < limit {
        if is_live(session, key).await == live {
            return Some(started.elapsed());
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    None
}

/// A small plan any planner answers at once: the fastest path from `start` to `goal`,
/// with all the time it needs.
fn probe_plan(start: [f64; 2], goal: [f64; 2]) -> PlanRequest {
    PlanRequest {
        request_id: None,
        cancel_token: None,
        start,
        goal,
        t_exec_s: 3600.0,
        deadline_s: 1.0,
        model: PlannerModel::Shortest,
        params: GaOverrides::default(),
        seed: 0,
        map_version: None,
        shortest: ShortestPathUse::Omit,
        seed_route: Vec::new(),
    }
}
