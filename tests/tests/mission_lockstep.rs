//! One window machine: the executive's day live (real services through Zenoh, the sim
//! in lock-step, this test stepping it) and in batch (`roam reproduce mission --days`'s
//! driver, the same machine answered in process) with the same seeds make the same
//! plan requests, give the same replan reasons and arrive at the same times (within a
//! sim step).
//!
//! Lock-step makes the live run repeatable: the test steps the sim once, then waits
//! until the executive has heard the step's estimate and the controller's status on it
//! (its `robot/<id>/executive` status), has no plan in flight, and the controller's
//! command for the step has left, before the next step. Plans cost no mission time
//! (`planning_cost_s: 0`: the clock stands while the planner works), and the GA runs a
//! few generations, far inside its deadline, so the planner's answers are the batch's.

use std::time::{Duration, Instant};

use roam_controller::service::ControllerConfig;
use roam_experiments::reproduce::mission::days::day::{day_seed, drive, sim_seed};
use roam_experiments::reproduce::mission::days::{DayWorld, DaysOptions};
use roam_mission::config::ExecutiveConfig;
use roam_mission::service::MissionConfig;
use roam_proto::controller::{ControllerStatus, MissionState};
use roam_proto::mission::{ExecutiveStatus, WindowReport};
use roam_proto::sim::{RobotCommand, SimControl, SimStatus};
use roam_proto::{decode, keys, Message};
use roam_tests::{repo_path, within, Harness};
use zenoh::handlers::FifoChannelHandler;
use zenoh::pubsub::Subscriber;
use zenoh::sample::Sample;

type Sub = Subscriber<FifoChannelHandler<Sample>>;

const SCENARIO: &str = "config/scenarios/day.yaml";
const DAY: usize = 1;
const BATCH_SEED: u64 = 5;
/// The day's windows end by 340 s: 850 steps of 0.4 s, and some room.
const MAX_STEPS: u64 = 1000;

/// The executive both runs: the shipped one, with what lock-step needs (plans cost no
/// mission time, a few generations well inside the deadline, no wall-clock rule that a
/// waiting test could trip) and no planner-side coupling (the test's planner has none).
fn config(seed: u64) -> ExecutiveConfig {
    ExecutiveConfig {
        tasks: roam_mission::tasks::day(),
        max_generations: Some(3),
        seed,
        planning_cost_s: Some(0.0),
        plan_deadline_s: 60.0,
        replan_time_share: 1.0,
        controller_silence_s: 600.0,
        // The demo's PEB cost: the planner's localizability layer comes from
        // localization's PEB field, as the batch's planning world does.
        w_loc: Some(2000.0),
        ..ExecutiveConfig::default()
    }
}

async fn subscribe(client: &roam_runtime::Requester, key: String) -> Sub {
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

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn the_live_executive_and_the_batch_make_the_same_day() {
    let seed = day_seed(BATCH_SEED, DAY);
    let config = config(seed);

    // The batch.
    let world = DayWorld::new().expect("the day world");
    let options = DaysOptions {
        plan_wall_s: 0.0,
        ..DaysOptions::default()
    };
    let (_, _, batch, _) = drive(&world, &config, false, sim_seed(seed), &options).expect("batch");
    assert_eq!(batch.len(), 4, "{batch:?}");

    // Live.
    let harness = Harness::start().await;
    let _map_server = harness
        .start_role(roam_map_server::MapServerConfig {
            map: Some(repo_path(SCENARIO)),
            ..harness.map_server_config()
        })
        .await;
    let _planner = harness
        .start_role(harness.planner_config("planner-0"))
        .await;
    let mut sim = harness.sim_config(Some(SCENARIO));
    sim.seed = sim_seed(seed);
    let _sim = harness.start_role(sim).await;
    let _localization = harness
        .start_role(harness.localization_config(Some(SCENARIO)))
        .await;
    let _controller = harness
        .start_role(ControllerConfig {
            scenario: Some(repo_path(SCENARIO)),
            // Lock-step waits on this test, not on the clock: no stale halts.
            stale_after_s: 600.0,
            apf: roam_controller::params::ApfParams::indoor(),
            ..harness.controller_config()
        })
        .await;
    let client = harness.client().await;
    let root = harness.root.clone();
    let reports = subscribe(&client, keys::robot_mission_report(&root, "robot")).await;
    let executive = subscribe(&client, keys::robot_executive(&root, "robot")).await;
    let statuses = subscribe(&client, keys::robot_controller(&root, "robot")).await;
    let commands = subscribe(&client, keys::robot_command(&root, "robot")).await;
    let _mission = harness
        .start_role(MissionConfig {
            root: root.clone(),
            executive: config.clone(),
            scenario: Some(repo_path(SCENARIO)),
            ..MissionConfig::default()
        })
        .await;
    // The executive listens before it waits 2 s for a clock the paused sim has not
    // published yet.
    tokio::time::sleep(Duration::from_secs(3)).await;

    let mut live: Vec<WindowReport> = Vec::new();
    let mut heard = ExecutiveStatus {
        robot: "robot".into(),
        window: 0,
        estimate_step: None,
        status_step: None,
        plans_in_flight: 0,
    };
    let mut last_status: Option<ControllerStatus> = None;
    let mut step = 0;
    while live.len() < 4 && step < MAX_STEPS {
        step += 1;
        let stepped: SimStatus = within(
            "step",
            client.request(&keys::sim_control(&root), Some(&SimControl::Step { n: 1 })),
        )
        .await
        .unwrap_or_else(|e| panic!("step {step}: {e}; last status {last_status:?}"));
        let driving = last_status.as_ref().is_some_and(|s| s.mission.is_some());
        let waited = Instant::now();
        loop {
            for s in drain::<ExecutiveStatus>(&executive) {
                heard = s;
            }
            for s in drain::<ControllerStatus>(&statuses) {
                last_status = Some(s);
            }
            let estimate_heard = heard.estimate_step.is_some_and(|e| e >= stepped.step);
            let status_heard = !driving || heard.status_step.is_some_and(|e| e >= stepped.step);
            if estimate_heard && status_heard && heard.plans_in_flight == 0 {
                break;
            }
            // A refused scan gives no estimate: after a while the step goes on.
            if waited.elapsed() > Duration::from_secs(3) {
                eprintln!("step {step}: waited out, heard {heard:?}, driving {driving}");
                break;
            }
            tokio::time::sleep(Duration::from_millis(1)).await;
        }
        // The command for this step has left the controller; the next step takes it.
        if last_status.as_ref().is_some_and(|s| {
            s.state == MissionState::Active && s.estimate_step == Some(stepped.step)
        }) {
            let until = Instant::now() + Duration::from_secs(10);
            'command: while Instant::now() < until {
                for c in drain::<RobotCommand>(&commands) {
                    if c.step == Some(stepped.step) {
                        break 'command;
                    }
                }
                tokio::time::sleep(Duration::from_millis(1)).await;
            }
        }
        live.extend(drain::<WindowReport>(&reports));
    }
    assert_eq!(
        live.len(),
        4,
        "the live day ended after {step} steps: {live:?}"
    );

    for (l, b) in live.iter().zip(&batch) {
        let w = l.window;
        assert_eq!((l.task.as_str(), w), (b.task.as_str(), b.window));
        assert_eq!(
            l.replan_reasons, b.replan_reasons,
            "window {w}: replan reasons"
        );
        let asks = |r: &WindowReport| -> Vec<(bool, bool)> {
            r.asks.iter().map(|a| (a.curious, a.ahead)).collect()
        };
        assert_eq!(asks(l), asks(b), "window {w}: the plan requests");
        for (x, y) in l.asks.iter().zip(&b.asks) {
            let from = (x.from[0] - y.from[0]).hypot(x.from[1] - y.from[1]);
            assert!(
                from < 1e-6,
                "window {w}: asked from {:?} and {:?}\nlive {:?}\nbatch {:?}",
                x.from,
                y.from,
                l.asks,
                b.asks
            );
            assert!(
                (x.at_s - y.at_s).abs() < 0.41,
                "window {w}: asked at {x:?} and {y:?}"
            );
            assert!(
                (x.t_exec_s - y.t_exec_s).abs() < 0.41,
                "window {w}: budgets {x:?} and {y:?}"
            );
        }
        assert_eq!(l.on_time, b.on_time, "window {w}");
        match (l.arrival_s, b.arrival_s) {
            (Some(a), Some(c)) => assert!((a - c).abs() < 0.41, "window {w}: arrived {a} and {c}"),
            (a, c) => assert_eq!(a, c, "window {w}"),
        }
    }
    harness.close().await;
}
