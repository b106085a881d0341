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

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use roam_experiments::reproduce::fleet::events::ChangeLog;
use roam_experiments::reproduce::fleet::measure::{
    MapSample, WeekRecord, WindowRecord, PATH_EVERY_STEPS,
};
use roam_experiments::reproduce::fleet::summary::summarize;
use roam_experiments::reproduce::fleet::week::{plan_seed, MAP_SAMPLE_S};
use roam_experiments::reproduce::fleet::FleetWorld;
use roam_experiments::reproduce::fleet::{picture, FleetReport, FleetSummary, FleetVariant};
use roam_mission::config::ExecutiveConfig;
use roam_mission::executive::{self, Progress};
use roam_planner::coupling::Coupling;
use roam_proto::cells::Cells;
use roam_proto::controller::{ControllerStatus, MissionState};
use roam_proto::map::Layer;
use roam_proto::mapper::OCCUPIED_NOW_LAYER;
use roam_proto::mission::WindowReport;
use roam_proto::planner::PlannerModel;
use roam_proto::sim::SimStatus;
use roam_proto::sim::{
    GroundTruth, LocalObservation, ObjectTruth, ObjectsTruth, RobotEventKind, RobotEvents,
    SimControl,
};
use roam_proto::{decode, keys, Message};
use roam_runtime::{lock, Requester};
use roam_stack::stack::{Stack, StackOptions};
use serde::Serialize;
use tokio::task::JoinSet;
use tokio_util::sync::CancellationToken;
use zenoh::pubsub::Subscriber;

use crate::demo::{with_live_view, write_error, DemoError, LiveView, DEMO_W_LOC};

/// The most robots the live fleet runs: the warehouse shift's ten.
pub const MAX_FLEET_DEMO_ROBOTS: usize = 10;
/// The wall time the fleet demo should end within after the build (issue 27).
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

/// A goal of the live fleet, judged from its figure.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LiveGoal {
    pub goal: &'static str,
    pub figure: Option<f64>,
    pub at_most: f64,
    pub met: Option<bool>,
}

impl LiveGoal {
    /// `met`, `missed`, or `no figure`.
    pub fn verdict(&self) -> &'static str {
        match self.met {
            Some(true) => "met",
            Some(false) => "missed",
            None => "no figure",
        }
    }

    fn at_most(goal: &'static str, figure: Option<f64>, at_most: f64) -> LiveGoal {
        LiveGoal {
            goal,
            figure,
            at_most,
            met: figure.map(|f| f <= at_most),
        }
    }
}

/// `report.json`.
#[derive(Debug, Clone, Serialize)]
pub struct FleetDemoReport {
    pub robots: usize,
    pub shift_s: f64,
    pub sim_rate: f64,
    pub planners: usize,
    pub seed: u64,
    /// Every task of every robot reached no later than its start.
    pub on_time: bool,
    /// The run in the batch's figures (variant `news`).
    pub summary: FleetSummary,
    pub goals: Vec<LiveGoal>,
    /// Every window, as each robot's executive reported it.
    pub windows: Vec<WindowReport>,
    pub wall_s: f64,
    pub pictures: Vec<PathBuf>,
}

/// What the run records from the wire while the executives drive.
struct Recorder {
    names: Vec<String>,
    shift_s: f64,
    step_s: f64,
    /// The newest sim time heard.
    now_s: f64,
    changes: ChangeLog,
    landed: Vec<ObjectTruth>,
    /// Each robot's true positions with their times (the windows' information).
    truth: Vec<Vec<(f64, [f64; 2])>>,
    /// Each robot's path for the picture, every [`PATH_EVERY_STEPS`]th step.
    paths: Vec<Vec<[f64; 2]>>,
    halted_steps: Vec<u64>,
    /// Each robot's last controller state and distance left: said when a window is
    /// given up.
    last_status: Vec<Option<(MissionState, Option<f64>)>>,
    /// Each robot's last event from the sim (a collision, a push by a moving obstacle)
    /// and its step: said with the controller's state when a window is given up.
    last_event: Vec<Option<(u64, String)>>,
    plan_latencies_s: Vec<f64>,
    maps: Vec<MapSample>,
}

impl Recorder {
    fn robot(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    fn truth(&mut self, t: &GroundTruth) {
        let Some(i) = self.robot(&t.robot) else {
            return;
        };
        self.now_s = self.now_s.max(t.time_s);
        // A shift's steps at most: the sim runs a little past the last task.
        let most = (self.shift_s / self.step_s).ceil() as usize + 1024;
        if self.truth[i].len() < most {
            self.truth[i].push((t.time_s, t.at));
        }
        if t.time_s <= self.shift_s && t.step.is_multiple_of(PATH_EVERY_STEPS) {
            self.paths[i].push(t.at);
        }
    }

    fn window_truth(&self, robot: usize, report: &WindowReport) -> Vec<[f64; 2]> {
        let end = report.arrival_s.unwrap_or(report.task_start_s);
        self.truth[robot]
            .iter()
            .filter(|(t, _)| *t >= report.began_s && *t <= end)
            .map(|(_, at)| *at)
            .collect()
    }
}

type Shared = Arc<Mutex<Recorder>>;

fn decoded<T: Message>(sample: &zenoh::sample::Sample) -> Option<T> {
    decode::<T>(&sample.payload().to_bytes()).ok()
}

/// A sim event in a few words.
fn event_name(e: &RobotEventKind) -> String {
    match e {
        RobotEventKind::SpeedClipped { .. } => "speed clipped".to_owned(),
        RobotEventKind::Collision { obstacle, .. } => format!("collision with {obstacle}"),
        RobotEventKind::Displaced { by, .. } => format!("pushed by {by}"),
        RobotEventKind::Trapped { by } => format!("trapped by {by}"),
    }
}

/// The subscribers that feed the recorder; dropped, they stop.
async fn listen(
    session: &zenoh::Session,
    root: &str,
    recorder: &Shared,
) -> Result<Vec<Subscriber<()>>, DemoError> {
    let zenoh_error = |e: zenoh::Error| DemoError::Zenoh(e.to_string());
    let mut subscribers = Vec::new();
    let r = recorder.clone();
    subscribers.push(
        session
            .declare_subscriber(format!("{root}/robot/*/truth"))
            .callback(move |s| {
                if let Some(t) = decoded::<GroundTruth>(&s) {
                    lock(&r).truth(&t);
                }
            })
            .await
            .map_err(zenoh_error)?,
    );
    let r = recorder.clone();
    subscribers.push(
        session
            .declare_subscriber(keys::robot_observation_any(root))
            .callback(move |s| {
                if let Some(o) = decoded::<LocalObservation>(&s) {
                    lock(&r).changes.observe(&o, o.time_s);
                }
            })
            .await
            .map_err(zenoh_error)?,
    );
    let r = recorder.clone();
    subscribers.push(
        session
            .declare_subscriber(keys::sim_objects(root))
            .callback(move |s| {
                if let Some(o) = decoded::<ObjectsTruth>(&s) {
                    let mut r = lock(&r);
                    r.changes.update(&o.objects, o.time_s);
                    r.landed = o.objects;
                }
            })
            .await
            .map_err(zenoh_error)?,
    );
    let r = recorder.clone();
    subscribers.push(
        session
            .declare_subscriber(format!("{root}/robot/*/events"))
            .callback(move |s| {
                if let Some(e) = decoded::<RobotEvents>(&s) {
                    let mut r = lock(&r);
                    if let (Some(i), Some(last)) = (r.robot(&e.robot), e.events.last()) {
                        r.last_event[i] = Some((e.step, event_name(last)));
                    }
                }
            })
            .await
            .map_err(zenoh_error)?,
    );
    let r = recorder.clone();
    subscribers.push(
        session
            .declare_subscriber(format!("{root}/robot/*/controller"))
            .callback(move |s| {
                if let Some(c) = decoded::<ControllerStatus>(&s) {
                    let mut r = lock(&r);
                    if let Some(i) = r.robot(&c.robot) {
                        if c.state == MissionState::HaltedPeb {
                            r.halted_steps[i] += 1;
                        }
                        r.last_status[i] = Some((c.state, c.distance_left_m));
                    }
                }
            })
            .await
            .map_err(zenoh_error)?,
    );
    Ok(subscribers)
}

/// Every sim minute, the mapper's `occupied_now` layer scored against the sim's
/// objects, as the batch scores its mapper's belief ([`MapSample::score`]).
async fn sample_maps(
    requester: Requester,
    root: String,
    world: Arc<FleetWorld>,
    recorder: Shared,
    cancel: CancellationToken,
) {
    let mut next_s = MAP_SAMPLE_S;
    let key = keys::map_layer(&root, OCCUPIED_NOW_LAYER);
    loop {
        tokio::select! {
            _ = cancel.cancelled() => return,
            _ = tokio::time::sleep(Duration::from_millis(50)) => {}
        }
        let now_s = lock(&recorder).now_s;
        if now_s < next_s {
            continue;
        }
        next_s += MAP_SAMPLE_S;
        let Ok(layer) = requester.request::<Layer, Layer>(&key, None).await else {
            continue;
        };
        let belief = belief_on_coarse(&world, &layer);
        let truth = world.semi_static_truth(&lock(&recorder).landed);
        if let Ok(sample) = MapSample::score(&world, now_s, &belief, &truth) {
            lock(&recorder).maps.push(sample);
        }
    }
}

/// The layer's P(occupied now) at each coarse cell's centre (0..=100 → 0..1); a cell
/// the layer does not cover is 1/2.
fn belief_on_coarse(world: &FleetWorld, layer: &Layer) -> Vec<f64> {
    let coarse = world.coarse;
    let Cells::I8(cells) = &layer.cells else {
        return vec![0.5; coarse.cell_count() as usize];
    };
    let (w, h) = (coarse.width as usize, coarse.height as usize);
    let mut belief = Vec::with_capacity(w * h);
    for cy in 0..h {
        for cx in 0..w {
            let x = coarse.origin.x + (cx as f64 + 0.5) * coarse.resolution;
            let y = coarse.origin.y + (cy as f64 + 0.5) * coarse.resolution;
            let p = roam_world::grid::world_to_cell(&layer.meta, x, y)
                .and_then(|(lx, ly)| cells.get(ly * layer.meta.width as usize + lx))
                .map_or(0.5, |&v| f64::from(v.clamp(0, 100)) / 100.0);
            belief.push(p);
        }
    }
    belief
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
/// variant, its seed and PEB cost, the tasks that start within `shift_s`.
fn executive_config(
    world: &FleetWorld,
    options: &FleetDemoOptions,
    index: usize,
) -> ExecutiveConfig {
    let robot = &world.shift.robots[index];
    let base = ExecutiveConfig {
        robot: robot.robot.clone(),
        tasks: robot
            .tasks
            .iter()
            .filter(|t| t.start_s <= options.shift_s)
            .cloned()
            .collect(),
        seed: plan_seed(options.seed, index),
        peb_free_m: Some(0.0),
        ..ExecutiveConfig::default()
    };
    FleetVariant::News.config(base, DEMO_W_LOC, PlannerModel::Greedy)
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
                    Ok((index, Err(e))) => {
                        failed.get_or_insert(format!("{}: {e}", names[index]));
                    }
                    Err(e) => {
                        failed.get_or_insert(format!("an executive stopped: {e}"));
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

fn write_reports(dir: &Path, report: &FleetDemoReport, table: &str) -> Result<(), DemoError> {
    let json_path = dir.join("report.json");
    let json = serde_json::to_string_pretty(report).map_err(|e| write_error(&json_path, e))?;
    std::fs::write(&json_path, json).map_err(|e| write_error(&json_path, e))?;
    let md_path = dir.join("report.md");
    std::fs::write(&md_path, markdown(report, table)).map_err(|e| write_error(&md_path, e))?;
    Ok(())
}

fn markdown(r: &FleetDemoReport, table: &str) -> String {
    let mut out = format!(
        "# roam demo --fleet\n\n{} robots in the warehouse (`world.yaml`), each with its own mission executive, the first {:.0} s of their shift, the sim at {}x, {} planners on the fleet's news (seed {}), {:.1} s of wall time.\n\n",
        r.robots, r.shift_s, r.sim_rate, r.planners, r.seed, r.wall_s
    );
    out.push_str("Measured as `roam reproduce fleet` measures a week (its `news` variant):\n\n");
    out.push_str(table);
    out.push_str("\n| goal | figure | at most | verdict |\n|---|---|---|---|\n");
    for g in &r.goals {
        out.push_str(&format!(
            "| {} | {} | {} | {} |\n",
            g.goal,
            g.figure.map_or("-".to_owned(), |f| format!("{f:.1}")),
            g.at_most,
            g.verdict()
        ));
    }
    out.push_str("\n| robot | window | task | task starts s | arrived s | on time | replans | holds |\n|---|---|---|---|---|---|---|---|\n");
    for w in &r.windows {
        out.push_str(&format!(
            "| {} | {} | {} | {:.1} | {} | {} | {} | {} |\n",
            w.robot,
            w.window + 1,
            w.task,
            w.task_start_s,
            w.arrival_s.map_or("-".to_owned(), |a| format!("{a:.1}")),
            if w.on_time { "yes" } else { "no" },
            w.replans,
            w.holds,
        ));
    }
    out.push_str("\n![the warehouse with each robot's driven path](warehouse-news.svg)\n\n![detection latency over the run](detection.svg)\n");
    out
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

    #[test]
    fn the_belief_is_read_at_each_coarse_cells_centre() {
        let Ok(world) = FleetWorld::warehouse() else {
            panic!("the built-in warehouse loads");
        };
        let meta = world.coarse;
        let n = meta.cell_count() as usize;
        let mut cells = vec![0i8; n];
        cells[n - 1] = 100;
        let layer = Layer {
            name: OCCUPIED_NOW_LAYER.into(),
            version: 1,
            meta,
            derived_from: None,
            cells: Cells::I8(cells),
        };
        let belief = belief_on_coarse(&world, &layer);
        assert_eq!(belief.len(), n);
        assert_eq!(belief[n - 1], 1.0);
        assert_eq!(belief[0], 0.0);
    }
}
