//! A held robot gets out, through Zenoh: the map server, the planner,
//! the sim in lock-step (this test stepping it), localization, the controller
//! (`ApfParams::indoor()`, its PEB guard on at 2 m) and the executive as `roam mission`,
//! on the demo's day world, as `mission_lockstep.rs` runs them.
//!
//! The day is one task at [`TASK_AT`] on free, well covered floor south of the
//! north-east room, with generous time (120 s; 12.8 m from the start as the crow
//! flies) and no PEB cost (`w_loc: None`), so the curious plan is free to visit the
//! archive, the room's interesting and uncovered part (no anchor stands in the
//! north-east: fewer than three are in range there, the fix is lost). The executive's
//! seed is one whose curious path takes the robot over the edge of the coverage, where
//! the controller's guard holds it (`halted_peb`).
//!
//! With `recover: true` the executive must get it out: after `hold_patience_s` back
//! along its own track to its last fix, then the window's fastest path to the task, on
//! time. The control, the same day with `recover: false`, leaves the robot held and the
//! task missed.

use std::collections::BTreeMap;
use std::time::Instant;

use roam_experiments::reproduce::mission::days::day::{day_seed, sim_seed};
use roam_mission::config::ExecutiveConfig;
use roam_mission::tasks::Task;
use roam_mission::watch::Reason;
use roam_proto::controller::{ControllerStatus, Mission, MissionState};
use roam_proto::mission::WindowReport;
use roam_tests::lockstep::{LockstepDay, Seen};

const SCENARIO: &str = "config/scenarios/day.yaml";
/// Free floor south of the north-east room, three or more anchors in range (PEB about
/// 0.1 m).
const TASK_AT: [f64; 2] = [2.0, 0.0];
const TASK_START_S: f64 = 120.0;
/// The executive's seed: `day_seed(0, 1)`, whose curious path crosses into the room
/// (checked in batch with the same window machine: held once and late without
/// recovery, recovered once and on time with it). A change to the window's rules can
/// move the path off the room: find another seed the same way (about one seed in three
/// qualifies).
const SEED_BASE: u64 = 0;
const SEED_DAY: usize = 1;
/// The window is given up this long after the task's start (a held robot's report
/// comes then).
const GIVE_UP_AFTER_S: f64 = 10.0;
/// The sim's step is 0.4 s: the window's end at 130 s and some room.
const MAX_STEPS: u64 = 360;

fn config(recover: bool) -> ExecutiveConfig {
    ExecutiveConfig {
        tasks: vec![Task {
            name: "past-the-archive".into(),
            at: TASK_AT,
            start_s: TASK_START_S,
            duration_s: 5.0,
        }],
        max_generations: Some(3),
        seed: day_seed(SEED_BASE, SEED_DAY),
        // Lock-step: plans cost no mission time, no wall-clock rule a waiting test
        // could trip.
        planning_cost_s: Some(0.0),
        plan_deadline_s: 60.0,
        replan_time_share: 1.0,
        controller_silence_s: 600.0,
        give_up_after_s: GIVE_UP_AFTER_S,
        // No PEB cost: a curious plan may cross the uncovered room.
        w_loc: None,
        recover,
        ..ExecutiveConfig::default()
    }
}

/// What one live day showed.
#[derive(Debug, Default)]
struct Day {
    reports: Vec<WindowReport>,
    steps: u64,
    /// Controller statuses heard, by state.
    states: BTreeMap<String, u32>,
    /// The PEBs the controller's statuses carried: the least and largest bounded one,
    /// and how many were unbounded (`None`) while the robot was held.
    peb_min_m: f64,
    peb_max_m: f64,
    held_unbounded: u32,
    held_bounded: u32,
    /// The first status on which the guard held the robot.
    first_held: Option<ControllerStatus>,
    /// The recovery missions the executive sent, and the controller's last status on
    /// each (state, commands sent, distance left).
    recoveries: Vec<Mission>,
    on_recoveries: BTreeMap<String, ControllerStatus>,
}

/// The day of [`config`]`(recover)` live, the sim stepped at most [`MAX_STEPS`] times.
async fn live_day(recover: bool) -> Day {
    let config = config(recover);
    let mut stack = LockstepDay::start(SCENARIO, sim_seed(config.seed), config).await;
    let mut day = Day {
        peb_min_m: f64::INFINITY,
        peb_max_m: f64::NEG_INFINITY,
        ..Day::default()
    };
    let note = |day: &mut Day, seen: Seen| {
        day.recoveries
            .extend(seen.missions.into_iter().filter(|m| m.recovery));
        for s in seen.statuses {
            *day.states.entry(format!("{:?}", s.state)).or_default() += 1;
            if let Some(p) = s.peb_m {
                day.peb_min_m = day.peb_min_m.min(p);
                day.peb_max_m = day.peb_max_m.max(p);
            }
            if s.state == MissionState::HaltedPeb {
                match s.peb_m {
                    Some(_) => day.held_bounded += 1,
                    None => day.held_unbounded += 1,
                }
                day.first_held.get_or_insert_with(|| s.clone());
            }
            let on_recovery = s
                .mission
                .as_ref()
                .filter(|id| day.recoveries.iter().any(|m| &m.id == *id))
                .cloned();
            if let Some(id) = on_recovery {
                day.on_recoveries.insert(id, s);
            }
        }
        day.reports.extend(seen.reports);
    };
    while day.reports.is_empty() && stack.steps < MAX_STEPS {
        let seen = stack.step().await;
        note(&mut day, seen);
    }
    // What came with the last step.
    let seen = stack.settle().await;
    note(&mut day, seen);
    day.steps = stack.steps;
    stack.close().await;
    eprintln!(
        "recover {recover}: {} steps; controller states {:?}; bounded PEB {:.3}–{:.3} m; \
         held with PEB unbounded {} times, bounded {} times; first held {:?}",
        day.steps,
        day.states,
        day.peb_min_m,
        day.peb_max_m,
        day.held_unbounded,
        day.held_bounded,
        day.first_held,
    );
    for m in &day.recoveries {
        eprintln!(
            "recover {recover}: recovery {} with {} waypoints {:?}; the controller's last \
             status on it: {:?}",
            m.id,
            m.waypoints.len(),
            m.waypoints,
            day.on_recoveries.get(&m.id)
        );
    }
    for r in &day.reports {
        eprintln!(
            "recover {recover}: window {} to {}: began {:.1} s, task at {:.1} s, arrived {:?}, \
             on time {}, holds {}, held {:.1} s, recoveries {}, replans {:?}",
            r.window,
            r.task,
            r.began_s,
            r.task_start_s,
            r.arrival_s,
            r.on_time,
            r.holds,
            r.held_s,
            r.recoveries,
            r.replan_reasons
        );
    }
    day
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_robot_the_peb_guard_holds_is_recovered_and_on_time() {
    let started = Instant::now();
    let day = live_day(true).await;
    let reports = &day.reports;
    assert_eq!(
        reports.len(),
        1,
        "no window report after {} steps: {day:?}",
        day.steps
    );
    assert!(
        day.first_held.is_some(),
        "the guard never held the robot: {day:?}"
    );
    assert!(
        reports.iter().any(|r| r.holds >= 1 && r.recoveries >= 1),
        "no window was held and recovered: {reports:?}\nrecoveries sent {:?}\nthe controller on them {:?}",
        day.recoveries,
        day.on_recoveries
    );
    let recovered = Reason::Recovered.name();
    assert!(
        reports
            .iter()
            .any(|r| r.replan_reasons.iter().any(|s| s == recovered)),
        "no {recovered:?} among the reasons: {reports:?}"
    );
    for r in reports {
        assert!(
            r.arrival_s.is_some() && r.on_time,
            "window {} to {}: arrived {:?} for a task at {} s (on time {}), held {} times for \
             {:.1} s, {} recoveries\nrecoveries sent {:?}\nthe controller's last status on \
             each {:?}",
            r.window,
            r.task,
            r.arrival_s,
            r.task_start_s,
            r.on_time,
            r.holds,
            r.held_s,
            r.recoveries,
            day.recoveries,
            day.on_recoveries
        );
    }
    eprintln!("recovered day: {:.1} s", started.elapsed().as_secs_f64());
}

/// The control: without recovery the same day leaves the robot held and the task
/// missed.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn without_recovery_the_held_robot_misses_its_task() {
    let started = Instant::now();
    let day = live_day(false).await;
    let reports = &day.reports;
    assert_eq!(
        reports.len(),
        1,
        "no window report after {} steps: {day:?}",
        day.steps
    );
    let r = &reports[0];
    assert!(r.holds >= 1, "not held: {r:?}");
    assert_eq!(r.recoveries, 0, "{r:?}");
    assert!(!r.on_time, "on time though held without recovery: {r:?}");
    eprintln!("control day: {:.1} s", started.elapsed().as_secs_f64());
}
