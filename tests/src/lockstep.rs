//! The executive's day with the sim in lock-step: the map server, a planner, the sim
//! (paused, stepped by the test), localization, the controller (`ApfParams::indoor`)
//! and the executive as `roam mission`, each a real service on loopback, used through
//! Zenoh only. After each step the driver waits until the executive has heard the
//! step's estimate and the controller's status on it and has no plan in flight (its
//! `robot/<id>/executive` status), and until the controller's command for the step
//! has left, so the next step takes it: a live day that repeats itself, and that the
//! batch of days must reproduce (`tests/tests/mission_lockstep.rs`).

use std::time::{Duration, Instant};

use roam_controller::params::ApfParams;
use roam_controller::service::ControllerConfig;
use roam_map_server::MapServerConfig;
use roam_mission::config::ExecutiveConfig;
use roam_mission::service::MissionConfig;
use roam_proto::controller::{ControllerStatus, Mission, MissionState};
use roam_proto::mission::{ExecutiveStatus, WindowReport};
use roam_proto::sim::{RobotCommand, SimControl, SimStatus};
use roam_proto::{decode, keys, Message};
use roam_runtime::service_config::ServiceConfig;
use roam_runtime::Requester;
use zenoh::handlers::FifoChannelHandler;
use zenoh::pubsub::Subscriber;
use zenoh::sample::Sample;

use crate::{repo_path, within, Harness, RunningService};

type Sub = Subscriber<FifoChannelHandler<Sample>>;

/// How long a step waits for the executive before it goes on (a refused scan gives no
/// estimate to hear).
const STEP_PATIENCE: Duration = Duration::from_secs(3);

/// What one step (or the settling after the last) brought.
#[derive(Debug, Default)]
pub struct Seen {
    pub statuses: Vec<ControllerStatus>,
    pub missions: Vec<Mission>,
    pub reports: Vec<WindowReport>,
}

/// The stack of one lock-step day.
pub struct LockstepDay {
    harness: Harness,
    _services: Vec<RunningService>,
    client: Requester,
    reports: Sub,
    executive: Sub,
    statuses: Sub,
    commands: Sub,
    missions: Sub,
    heard: ExecutiveStatus,
    last_status: Option<ControllerStatus>,
    /// Steps taken.
    pub steps: u64,
}

impl std::fmt::Debug for LockstepDay {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LockstepDay")
            .field("root", &self.harness.root)
            .field("steps", &self.steps)
            .field("heard", &self.heard)
            .finish_non_exhaustive()
    }
}

async fn subscribe(client: &Requester, key: String) -> Sub {
    within("subscribe", client.session().declare_subscriber(key))
        .await
        .expect("subscriber")
}

/// Every message waiting on `sub`, decoded.
fn drain<T: Message>(sub: &Sub) -> Vec<T> {
    let mut out = Vec::new();
    while let Ok(Some(sample)) = sub.try_recv() {
        if let Ok(m) = decode(&sample.payload().to_bytes()) {
            out.push(m);
        }
    }
    out
}

impl LockstepDay {
    /// Boots the stack on `scenario` (relative to the repository), the sim seeded
    /// `sim_seed`, the executive on `config` (its robot `robot`), and waits until the
    /// executive listens.
    pub async fn start(scenario: &str, sim_seed: u64, config: ExecutiveConfig) -> LockstepDay {
        let harness = Harness::start().await;
        let mut services = vec![
            harness
                .start_role(MapServerConfig {
                    map: Some(repo_path(scenario)),
                    ..harness.map_server_config()
                })
                .await,
            harness
                .start_role(harness.planner_config("planner-0"))
                .await,
        ];
        let mut sim = harness.sim_config(Some(scenario));
        sim.seed = sim_seed;
        services.push(harness.start_role(sim).await);
        services.push(
            harness
                .start_role(harness.localization_config(Some(scenario)))
                .await,
        );
        services.push(
            harness
                .start_role(ControllerConfig {
                    scenario: Some(repo_path(scenario)),
                    // Lock-step waits on the test, not on the clock: no stale halts.
                    stale_after_s: 600.0,
                    apf: ApfParams::indoor(),
                    ..harness.controller_config()
                })
                .await,
        );
        let client = harness.client().await;
        let root = harness.root.clone();
        let robot = config.robot.clone();
        let reports = subscribe(&client, keys::robot_mission_report(&root, &robot)).await;
        let executive = subscribe(&client, keys::robot_executive(&root, &robot)).await;
        let statuses = subscribe(&client, keys::robot_controller(&root, &robot)).await;
        let commands = subscribe(&client, keys::robot_command(&root, &robot)).await;
        let missions = subscribe(&client, keys::robot_mission(&root, &robot)).await;
        services.push(
            harness
                .start_role(MissionConfig {
                    service: ServiceConfig::at(root.clone()),
                    executive: config,
                    scenario: Some(repo_path(scenario)),
                    ..MissionConfig::default()
                })
                .await,
        );
        // The executive listens before it waits 2 s for a clock the paused sim has not
        // published yet.
        tokio::time::sleep(Duration::from_secs(3)).await;
        LockstepDay {
            heard: ExecutiveStatus {
                robot,
                window: 0,
                estimate_step: None,
                status_step: None,
                plans_in_flight: 0,
            },
            harness,
            _services: services,
            client,
            reports,
            executive,
            statuses,
            commands,
            missions,
            last_status: None,
            steps: 0,
        }
    }

    fn take(&mut self, seen: &mut Seen) {
        for s in drain::<ExecutiveStatus>(&self.executive) {
            self.heard = s;
        }
        seen.missions.extend(drain::<Mission>(&self.missions));
        for s in drain::<ControllerStatus>(&self.statuses) {
            self.last_status = Some(s.clone());
            seen.statuses.push(s);
        }
    }

    /// One sim step, and everything it brought once the executive and the controller
    /// are done with it (module doc).
    pub async fn step(&mut self) -> Seen {
        self.steps += 1;
        let root = &self.harness.root;
        let stepped: SimStatus = within(
            "step",
            self.client
                .request(&keys::sim_control(root), Some(&SimControl::Step { n: 1 })),
        )
        .await
        .unwrap_or_else(|e| {
            panic!(
                "step {}: {e}; last status {:?}",
                self.steps, self.last_status
            )
        });
        let mut seen = Seen::default();
        let driving = self
            .last_status
            .as_ref()
            .is_some_and(|s| s.mission.is_some());
        let waited = Instant::now();
        loop {
            self.take(&mut seen);
            let h = &self.heard;
            let estimate_heard = h.estimate_step.is_some_and(|e| e >= stepped.step);
            let status_heard = !driving || h.status_step.is_some_and(|e| e >= stepped.step);
            if estimate_heard && status_heard && h.plans_in_flight == 0 {
                break;
            }
            if waited.elapsed() > STEP_PATIENCE {
                eprintln!("step {}: waited out, heard {h:?}", self.steps);
                break;
            }
            tokio::time::sleep(Duration::from_millis(1)).await;
        }
        // A mission sent on this step is installed at the controller (its
        // acknowledgement names it) before the next step's estimate can reach it.
        if let Some(sent) = seen.missions.last().map(|m| m.id.clone()) {
            let until = Instant::now() + Duration::from_secs(10);
            while Instant::now() < until
                && self.last_status.as_ref().and_then(|s| s.mission.as_deref()) != Some(&sent)
            {
                tokio::time::sleep(Duration::from_millis(1)).await;
                self.take(&mut seen);
            }
        }
        // This step's controller status reaches this driver too (the executive may have
        // heard it first): without it, whether a command is due cannot be told.
        let active_before = self
            .last_status
            .as_ref()
            .is_some_and(|s| s.state == MissionState::Active);
        if active_before {
            let until = Instant::now() + STEP_PATIENCE;
            let heard = |seen: &Seen| {
                seen.statuses
                    .iter()
                    .any(|s| s.estimate_step >= Some(stepped.step))
            };
            while Instant::now() < until && !heard(&seen) {
                tokio::time::sleep(Duration::from_millis(1)).await;
                self.take(&mut seen);
            }
        }
        // The command for this step has left the controller; the next step takes it.
        let active = self.last_status.as_ref().is_some_and(|s| {
            s.state == MissionState::Active && s.estimate_step == Some(stepped.step)
        });
        if active {
            let until = Instant::now() + Duration::from_secs(10);
            'command: while Instant::now() < until {
                for c in drain::<RobotCommand>(&self.commands) {
                    if c.step == Some(stepped.step) {
                        break 'command;
                    }
                }
                tokio::time::sleep(Duration::from_millis(1)).await;
            }
            self.until_the_sim_holds_the_command(stepped.step).await;
        }
        seen.reports.extend(drain::<WindowReport>(&self.reports));
        seen
    }

    /// Waits until the sim holds the command answering `step`: this driver heard it
    /// leave the controller, but the sim hears it on another link, and a step request
    /// that overtook it would drive the robot on the previous command.
    async fn until_the_sim_holds_the_command(&self, step: u64) {
        let root = &self.harness.root;
        let robot = &self.heard.robot;
        let until = Instant::now() + Duration::from_secs(10);
        while Instant::now() < until {
            let status: Result<SimStatus, _> = self
                .client
                .request(&keys::sim_control(root), Some(&SimControl::Status))
                .await;
            if let Ok(status) = status {
                if status
                    .pending
                    .iter()
                    .any(|p| &p.robot == robot && p.step == Some(step))
                {
                    return;
                }
            }
            tokio::time::sleep(Duration::from_millis(1)).await;
        }
        eprintln!("step {step}: the sim never held its command");
    }

    /// What came after the last step (a moment's wait).
    pub async fn settle(&mut self) -> Seen {
        tokio::time::sleep(Duration::from_millis(200)).await;
        let mut seen = Seen::default();
        self.take(&mut seen);
        seen.reports.extend(drain::<WindowReport>(&self.reports));
        seen
    }

    pub async fn close(self) {
        self.harness.close().await;
    }
}
