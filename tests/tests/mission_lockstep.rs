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

use roam_experiments::reproduce::mission::days::day::{day_seed, drive, sim_seed};
use roam_experiments::reproduce::mission::days::{DayWorld, DaysOptions};
use roam_mission::config::ExecutiveConfig;
use roam_proto::mission::WindowReport;
use roam_tests::lockstep::LockstepDay;

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

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn the_live_executive_and_the_batch_make_the_same_day() {
    let seed = day_seed(BATCH_SEED, DAY);
    let config = config(seed);

    // The batch.
    let world = DayWorld::new(&roam_mission::site::Site::builtin_day()).expect("the day world");
    let options = DaysOptions {
        plan_wall_s: 0.0,
        replan_wall_s: 0.0,
        ..DaysOptions::default()
    };
    let batch = drive(&world, &config, false, sim_seed(seed), &options)
        .expect("batch")
        .reports;
    assert_eq!(batch.len(), 4, "{batch:?}");

    // Live.
    let mut day = LockstepDay::start(SCENARIO, sim_seed(seed), config).await;
    let mut live: Vec<WindowReport> = Vec::new();
    while live.len() < 4 && day.steps < MAX_STEPS {
        live.extend(day.step().await.reports);
    }
    assert_eq!(
        live.len(),
        4,
        "the live day ended after {} steps: {live:?}",
        day.steps
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
    day.close().await;
}
