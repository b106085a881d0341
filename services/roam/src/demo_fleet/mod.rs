//! `roam demo --fleet`: the warehouse fleet live. The whole stack boots in one process
//! on the built-in warehouse (`config/scenarios/warehouse.yaml`), the planners plan on
//! the fleet's news (`coupling: news`, the mapper's `news` layer), and every robot of
//! the shift (`config/shifts/warehouse.yaml`) gets its own mission executive, all
//! through Zenoh as separate executives would, for the first `shift_s` seconds of the
//! shift; the planners also plan around what the fleet has seen occupied (`occupied_now`:
//! pallets left on the dock lanes; `roam_planner::seen`), and the controller calls a
//! robot stuck after 10 s without progress (`ApfParams::fleet`). Each executive is configured as `roam reproduce fleet`'s `news` variant
//! configures it, with the same plan seeds; the run is measured as the batch measures a
//! week ([`roam_experiments::reproduce::fleet`]: late windows, how soon the fleet sees
//! each change, the map now against the world every sim minute, plan latency) from
//! what the services publish: the sim's truth (`robot/*/truth`, `sim/objects`), the
//! robots' observations, the controller's status and the mapper's `occupied_now`
//! layer.

mod record;
mod report;

use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use roam_experiments::reproduce::fleet::events::ChangeLog;
use roam_experiments::reproduce::fleet::measure::{WeekRecord, WindowRecord};
use roam_experiments::reproduce::fleet::summary::summarize;
use roam_experiments::reproduce::fleet::week::robot_config;
use roam_experiments::reproduce::fleet::FleetWorld;
use roam_experiments::reproduce::fleet::{picture, FleetOptions, FleetReport, FleetVariant};
use roam_mission::config::ExecutiveConfig;
use roam_mission::executive::{self, Progress};
use roam_planner::coupling::Coupling;
use roam_proto::keys;
use roam_proto::mission::WindowReport;
use roam_proto::planner::PlannerModel;
use roam_proto::sim::{SimControl, SimStatus};
use roam_runtime::{lock, Requester};
use roam_stack::stack::{Stack, StackOptions};
use tokio::task::JoinSet;
use tokio_util::sync::CancellationToken;

use crate::demo::{with_live_view, write_error, DemoError, LiveView, DEMO_W_LOC};
use record::{listen, sample_maps, Recorder, Shared};
use report::write_reports;
pub use report::{FleetDemoReport, LiveGoal};

/// The most robots the live fleet runs: the warehouse shift's ten.
pub const MAX_FLEET_DEMO_ROBOTS: usize = 10;
/// The wall time the fleet demo should end within once built, seconds.
pub const FLEET_DEMO_WALL_GOAL_S: f64 = 180.0;
/// The plan latency p99 the fleet should keep, ms.
pub const FLEET_DEMO_P99_GOAL_MS: f64 = 1000.0;

/// How the fleet demo runs.
#[derive(Debug, Clone)]
pub struct FleetDemoOptions {
    pub out_dir: PathBuf,
    /// The sim's real-time factor.
    pub rate: f64,
    /// The plans' seed (each robot's is derived from it as the batch derives it).
    pub seed: u64,
    /// The first robots of the shift to run (1 to 10).
    pub robots: usize,
    /// How much of the shift to run, sim seconds: the tasks that start within it.
    pub shift_s: f64,
    /// Planner instances.
    pub planners: usize,
    /// The planners plan around what the fleet has seen occupied (`roam_planner::seen`):
    /// on by default. Measured (services/experiments/README.md, "The fleet live"): with
    /// the fleet's stuck window, 0, 0 and 0 late windows on seeds 0 to 2 against 1, 0
    /// and 5 on the static map alone, where robots drove into pallets on the dock lanes
    /// after every replan.
    pub avoid_seen: bool,
    pub root: Option<String>,
    pub listen: Option<String>,
    pub view: LiveView,
    pub ros2: Option<roam_ros2::node::Ros2Config>,
}

impl Default for FleetDemoOptions {
    fn default() -> Self {
        FleetDemoOptions {
            out_dir: PathBuf::from("roam-demo-fleet"),
            rate: 10.0,
            seed: 0,
            robots: MAX_FLEET_DEMO_ROBOTS,
            shift_s: 900.0,
            planners: 2,
            avoid_seen: true,
            root: None,
            listen: None,
            view: LiveView::default(),
            ros2: None,
        }
    }
}

impl FleetDemoOptions {
    /// Refuses what cannot run, naming the flag and its limit.
    pub fn check(&self, shift_length_s: f64) -> Result<(), DemoError> {
        let bad = |field: &'static str, value: String, limit: String| {
            Err(DemoError::Invalid {
                field,
                value,
                limit,
            })
        };
        if self.robots == 0 || self.robots > MAX_FLEET_DEMO_ROBOTS {
            return bad(
                "robots",
                self.robots.to_string(),
                format!("1 to {MAX_FLEET_DEMO_ROBOTS}"),
            );
        }
        if !(self.shift_s.is_finite() && self.shift_s > 0.0 && self.shift_s <= shift_length_s) {
            return bad(
                "shift_s",
                self.shift_s.to_string(),
                format!("more than 0 and at most the shift's {shift_length_s} s"),
            );
        }
        if !(self.rate.is_finite() && self.rate > 0.0 && self.rate <= 100.0) {
            return bad(
                "rate",
                self.rate.to_string(),
                "more than 0, at most 100".into(),
            );
        }
        if self.planners == 0 || self.planners > 8 {
            return bad("planners", self.planners.to_string(), "1 to 8".into());
        }
        Ok(())
    }
}

/// Runs the fleet demo and writes `report.json`, `report.md` and the pictures.
pub async fn run(
    options: &FleetDemoOptions,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<FleetDemoReport, DemoError> {
    let started = Instant::now();
    let world = Arc::new(FleetWorld::warehouse().map_err(|e| DemoError::Fleet(e.to_string()))?);
    options.check(world.shift.length_s)?;
    std::fs::create_dir_all(&options.out_dir).map_err(|e| write_error(&options.out_dir, e))?;
    let scenario = options.out_dir.join("world.yaml");
    std::fs::write(&scenario, roam_mission::shift::WAREHOUSE_SCENARIO)
        .map_err(|e| write_error(&scenario, e))?;
    progress(&format!(
        "booting the stack on the warehouse ({} planners on the fleet's news)",
        options.planners
    ));
    let stack = Stack::start(
        StackOptions {
            root: options.root.clone(),
            map: Some(scenario.clone()),
            planners: options.planners,
            sim_rate: Some(options.rate),
            apf: Some(roam_controller::params::ApfParams::fleet()),
            coupling: Coupling::News,
            avoid_seen: options.avoid_seen,
            ros2: options.ros2.clone(),
            listen: options.listen.clone(),
            ..StackOptions::default()
        },
        Duration::from_secs(60),
    )
    .await?;
    with_live_view(stack, &options.view, progress, async |stack| {
        drive(stack, options, &world, progress, started).await
    })
    .await
}

/// The executive's configuration for robot `index` of the shift: the batch's `news`
/// variant's ([`robot_config`], W_loc [`DEMO_W_LOC`], the greedy planner), for the tasks
/// that start within `shift_s`.
fn executive_config(
    world: &FleetWorld,
    options: &FleetDemoOptions,
    index: usize,
) -> ExecutiveConfig {
    let robot = &world.shift.robots[index];
    let tasks = robot
        .tasks
        .iter()
        .filter(|t| t.start_s <= options.shift_s)
        .cloned()
        .collect();
    let batch = FleetOptions {
        seed: options.seed,
        w_loc: DEMO_W_LOC,
        model: PlannerModel::Greedy,
        avoid_seen: options.avoid_seen,
        ..FleetOptions::default()
    };
    robot_config(FleetVariant::News, &robot.robot, index, tasks, &batch)
}

async fn drive(
    stack: &Stack,
    options: &FleetDemoOptions,
    world: &Arc<FleetWorld>,
    progress: &(dyn Fn(&str) + Sync),
    started: Instant,
) -> Result<FleetDemoReport, DemoError> {
    let session = stack.router.session.clone();
    let root = stack.root.clone();
    let requester = Requester::new(session.clone(), Duration::from_secs(10));
    let robots = options.robots;
    // The scenario's robots beyond the demo's leave the sim before anyone moves.
    for r in &world.shift.robots[robots..] {
        requester
            .request::<SimControl, SimStatus>(
                &keys::sim_control(&root),
                Some(&SimControl::RemoveRobot {
                    name: r.robot.clone(),
                }),
            )
            .await?;
    }
    let names: Vec<String> = world.shift.robots[..robots]
        .iter()
        .map(|r| r.robot.clone())
        .collect();
    let recorder: Shared = Arc::new(Mutex::new(Recorder {
        names: names.clone(),
        shift_s: options.shift_s,
        step_s: world.step_s,
        now_s: 0.0,
        changes: ChangeLog::default(),
        landed: Vec::new(),
        truth: vec![Vec::new(); robots],
        paths: vec![Vec::new(); robots],
        halted_steps: vec![0; robots],
        last_status: vec![None; robots],
        last_event: vec![None; robots],
        plan_latencies_s: Vec::new(),
        maps: Vec::new(),
    }));
    let _subscribers = listen(&session, &root, &recorder).await?;
    let cancel = CancellationToken::new();
    let sampler = tokio::spawn(sample_maps(
        requester.clone(),
        root.clone(),
        world.clone(),
        recorder.clone(),
        cancel.clone(),
    ));
    let (lines, mut said) = tokio::sync::mpsc::unbounded_channel::<String>();
    let mut executives = JoinSet::new();
    for index in 0..robots {
        let config = executive_config(world, options, index);
        // A robot whose first task starts after the shortened shift stays where it is.
        if config.tasks.is_empty() {
            continue;
        }
        let (session, root, cancel) = (session.clone(), root.clone(), cancel.clone());
        let (lines, recorder) = (lines.clone(), recorder.clone());
        executives.spawn(async move {
            let robot = config.robot.clone();
            let say = move |p: Progress| match p {
                Progress::Answered { model, took_s, .. } if model != PlannerModel::Shortest => {
                    lock(&recorder).plan_latencies_s.push(took_s);
                }
                Progress::Arrived {
                    window,
                    task,
                    at_s,
                    start_s,
                } => {
                    let _ = lines.send(format!(
                        "{robot} window {}: at {task} at {at_s:.1} s, task starts at {start_s:.1} s{}",
                        window + 1,
                        if at_s > start_s { " (late)" } else { "" }
                    ));
                }
                Progress::GaveUp { window, task } => {
                    let (last, event) = {
                        let r = lock(&recorder);
                        (r.last_status[index], r.last_event[index].clone())
                    };
                    let _ = lines.send(format!(
                        "{robot} window {}: gave up on reaching {task} (the controller: {}; the sim's last event: {})",
                        window + 1,
                        last.map_or("nothing heard".to_owned(), |(state, left)| format!(
                            "{state:?}, {} m left",
                            left.map_or("?".to_owned(), |d| format!("{d:.1}"))
                        )),
                        event.map_or("none".to_owned(), |(step, what)| format!("{what} at step {step}"))
                    ));
                }
                _ => {}
            };
            let outcomes = executive::run(&session, &root, &config, &cancel, &say, &|_| {}).await;
            (index, outcomes)
        });
    }
    drop(lines);
    let mut reports: Vec<(usize, WindowReport)> = Vec::new();
    let mut failed = None;
    loop {
        tokio::select! {
            Some(line) = said.recv() => progress(&line),
            joined = executives.join_next() => {
                let Some(joined) = joined else { break };
                match joined {
                    Ok((index, Ok(outcomes))) => {
                        reports.extend(outcomes.into_iter().map(|o| (index, o.report)));
                    }
                    // One executive failing fails the run: the others stop now
                    // rather than drive on for a report that will not be written.
                    Ok((index, Err(e))) => {
                        failed.get_or_insert(format!("{}: {e}", names[index]));
                        cancel.cancel();
                    }
                    Err(e) => {
                        failed.get_or_insert(format!("an executive stopped: {e}"));
                        cancel.cancel();
                    }
                }
            }
        }
    }
    while let Ok(line) = said.try_recv() {
        progress(&line);
    }
    cancel.cancel();
    let _ = sampler.await;
    if let Some(why) = failed {
        return Err(DemoError::Fleet(why));
    }
    reports.sort_by_key(|a| (a.0, a.1.window));
    let wall_s = started.elapsed().as_secs_f64();
    let week = {
        let r = lock(&recorder);
        let mut week = WeekRecord::new(FleetVariant::News, robots);
        week.windows = reports
            .iter()
            .map(|(i, w)| WindowRecord::live(world, *i, options.shift_s, w, &r.window_truth(*i, w)))
            .collect();
        week.maps = r.maps.clone();
        week.plan_latencies_s = r.plan_latencies_s.clone();
        week.halted_steps = r.halted_steps.clone();
        week.paths = r.paths.clone();
        week.events = r.changes.events().to_vec();
        week.end_s = r.now_s;
        week.wall_s = wall_s;
        week
    };
    let summary = summarize(&week, options.shift_s, 1);
    let windows: Vec<WindowReport> = reports.into_iter().map(|(_, w)| w).collect();
    let late = windows.iter().filter(|w| !w.on_time).count();
    let goals = vec![
        LiveGoal::at_most("late windows", Some(late as f64), 0.0),
        LiveGoal::at_most(
            "plan latency p99, ms",
            summary.plan_p99_ms,
            FLEET_DEMO_P99_GOAL_MS,
        ),
        LiveGoal::at_most("wall seconds", Some(wall_s), FLEET_DEMO_WALL_GOAL_S),
    ];
    let pictures = picture::write(
        &options.out_dir,
        world,
        std::slice::from_ref(&week),
        options.seed,
    )
    .map_err(|e| write_error(&options.out_dir, e))?;
    let table = FleetReport {
        days: 1,
        seed: options.seed,
        model: PlannerModel::Greedy,
        generations: 0,
        robots,
        shift_s: options.shift_s,
        variants: vec![summary.clone()],
        goals: Vec::new(),
        weeks: Vec::new(),
    }
    .table();
    let report = FleetDemoReport {
        robots,
        shift_s: options.shift_s,
        sim_rate: options.rate,
        planners: options.planners,
        seed: options.seed,
        on_time: late == 0,
        summary,
        goals,
        windows,
        wall_s,
        pictures,
    };
    write_reports(&options.out_dir, &report, &table)?;
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_options_are_refused_naming_the_field() {
        let ok = FleetDemoOptions::default();
        assert!(ok.check(3600.0).is_ok());
        for (options, field) in [
            (
                FleetDemoOptions {
                    robots: 0,
                    ..ok.clone()
                },
                "robots",
            ),
            (
                FleetDemoOptions {
                    robots: 11,
                    ..ok.clone()
                },
                "robots",
            ),
            (
                FleetDemoOptions {
                    shift_s: 4000.0,
                    ..ok.clone()
                },
                "shift_s",
            ),
            (
                FleetDemoOptions {
                    shift_s: f64::NAN,
                    ..ok.clone()
                },
                "shift_s",
            ),
            (
                FleetDemoOptions {
                    rate: 0.0,
                    ..ok.clone()
                },
                "rate",
            ),
            (
                FleetDemoOptions {
                    planners: 0,
                    ..ok.clone()
                },
                "planners",
            ),
        ] {
            match options.check(3600.0) {
                Err(DemoError::Invalid { field: f, .. }) => assert_eq!(f, field),
                other => panic!("{field}: {other:?}"),
            }
        }
    }
}
