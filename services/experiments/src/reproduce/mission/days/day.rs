//! One variant's day, driven by the executive's own window machine
//! ([`roam_mission::window::DowntimeWindow`]) exactly as the live executive drives it
//! ([`roam_mission::executive`]), with its actions answered in process instead of over
//! Zenoh:
//!
//! | action | live (`roam mission`) | here |
//! |---|---|---|
//! | `Drive(mission)` | put on `robot/<id>/mission` | the stepper's controller takes it |
//! | `RequestPlan(ask)` | [`plan_request`] to the planner service | [`plan_request`] answered by the planner's own code ([`super::planning`]), delivered `planning_cost_s` of mission time later |
//! | `Forget(id)` | the request dropped (cancelled) | its answer dropped |
//! | `Arrived` | the calibration learns | the same calibration learns |
//!
//! and its events heard in the same order: every sim step, localization's estimate,
//! the controller's status on the current mission (the controller service's own
//! message, [`roam_controller::status::controller_status`]), each followed by a tick
//! (the live executive ticks after every event), the plan answers that are due, then a
//! tick. Wall time is mission time over the clock's rate (the demo's 20×),
//! so the wall-clock rules (plan retries, a silent controller) behave as they do in the
//! demo.

use std::collections::VecDeque;

use roam_controller::params::ApfParams;
use roam_controller::status::controller_status;
use roam_mission::calibration::{path_measure, Calibration, CalibrationConfig, TimeModel};
use roam_mission::config::ExecutiveConfig;
use roam_mission::information::InformationScale;
use roam_mission::request::plan_request;
use roam_mission::tasks::Task;
use roam_mission::watch::Reason;
use roam_mission::window::{
    DowntimeWindow, Handover, Now, WindowAction, WindowEnd, WindowEvent, WindowOutcome,
    WindowRules, WindowSetup,
};
use roam_proto::mission::WindowReport;
use roam_proto::planner::Plan;
use roam_world::seed::splitmix64;
use serde::Serialize;

use super::measure::{planned_path, Leg, TimeModelUse, Track, WindowResult};
use super::planning::Planner;
use super::robot::Robot;
use super::variant::Variant;
use super::world::DayWorld;
use super::{DaysError, DaysOptions};

/// The steps the day may take to get the robot's first fix.
const FIRST_FIX_STEPS: usize = 100;

/// The sim's stream of a day, apart from its plans' streams.
const SIM_STREAM: u64 = 0x51_4D_5F_53_54_52_45_41;

/// The mission tag of the batch's executive (a live one takes its Zenoh session's).
pub const BATCH_TAG: &str = "batch";

/// One variant's day.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DayResult {
    pub day: usize,
    pub variant: Variant,
    pub windows: Vec<WindowResult>,
    /// The ranges of the day's first scan: the same in every variant of a day (the
    /// sim's noise depends on the day, not on the variant).
    pub first_ranges: Vec<f64>,
    /// The executive's own window reports, as the live executive publishes them:
    /// what the equivalence test holds the live executive to (not in the JSON: the
    /// windows above carry their figures).
    #[serde(skip)]
    pub reports: Vec<WindowReport>,
    /// The robot's true path through the whole day (not in the JSON: large).
    #[serde(skip)]
    pub truth: Vec<[f64; 2]>,
}

/// The seed of day `day` in a batch seeded `seed`.
pub fn day_seed(seed: u64, day: usize) -> u64 {
    splitmix64(seed ^ splitmix64(day as u64))
}

/// The executive's configuration of a day: the day's robot and tasks, the batch's
/// generations and plan cost, the day's seed, the variant's rules.
pub fn day_config(
    world: &DayWorld,
    variant: Variant,
    options: &DaysOptions,
    seed: u64,
) -> ExecutiveConfig {
    let base = ExecutiveConfig {
        robot: world.robot.clone(),
        tasks: world.tasks.clone(),
        max_generations: Some(options.generations),
        seed,
        planning_cost_s: Some(options.plan_wall_s * options.rate),
        ..ExecutiveConfig::default()
    };
    variant.config(base, options.w_loc)
}

/// The sim's seed on a day seeded `day_seed` (the same for every variant).
pub fn sim_seed(day_seed: u64) -> u64 {
    splitmix64(day_seed ^ SIM_STREAM)
}

/// Runs day `day` of `variant`.
pub fn run_day(
    world: &DayWorld,
    variant: Variant,
    options: &DaysOptions,
    day: usize,
) -> Result<DayResult, DaysError> {
    let seed = day_seed(options.seed, day);
    let config = day_config(world, variant, options, seed);
    let (windows, first_ranges, reports, truth) = drive(
        world,
        &config,
        variant.change_coupling(),
        sim_seed(seed),
        options,
    )?;
    Ok(DayResult {
        day,
        variant,
        windows,
        first_ranges,
        reports,
        truth,
    })
}

/// What [`drive`] returns: the windows' measures, the first scan's ranges, the
/// executive's window reports and the robot's true path.
pub type Driven = (
    Vec<WindowResult>,
    Vec<f64>,
    Vec<WindowReport>,
    Vec<[f64; 2]>,
);

/// The executive configured by `config` through its day, the planner coupling the
/// change layer when `change`, the sim seeded `sim_seed`, with the controller the demo
/// runs ([`ApfParams::indoor`]).
pub fn drive(
    world: &DayWorld,
    config: &ExecutiveConfig,
    change: bool,
    sim_seed: u64,
    options: &DaysOptions,
) -> Result<Driven, DaysError> {
    let planner = Planner { world, change };
    let robot = Robot::new(world, &ApfParams::indoor(), sim_seed)?;
    let mut day_run = DayRun::new(world, config, planner, robot, options)?;
    let windows = day_run.drive_day()?;
    let first_ranges = day_run.robot.first_ranges().to_vec();
    Ok((windows, first_ranges, day_run.reports, day_run.truth))
}

/// The executive through one variant's day, and the robot it drives.
#[derive(Debug)]
pub struct DayRun<'a> {
    pub world: &'a DayWorld,
    pub config: &'a ExecutiveConfig,
    pub planner: Planner<'a>,
    pub robot: Robot,
    pub calibration: Calibration,
    /// What the last window handed the next, and where it left the robot (its last good
    /// estimate, as the live executive keeps it).
    handover: Handover,
    position: Option<[f64; 2]>,
    /// The clock's rate: wall time is mission time over it.
    rate: f64,
    /// What a curious plan costs at most, wall seconds (its deadline may cut it).
    plan_wall_s: f64,
    pub reports: Vec<WindowReport>,
    /// The whole day's true path.
    pub truth: Vec<[f64; 2]>,
}

/// What one window's drive records beside the machine.
#[derive(Debug, Default)]
struct WindowLog {
    track: Track,
    /// One per mission that drives a route (recoveries are not routes).
    legs: Vec<Leg>,
    /// The current mission: its id, its waypoints, whether it is a route.
    mission: Option<(String, usize, bool)>,
    /// Answers on their way: when they are due, for which ask, the answer.
    answers: Vec<(f64, u64, Option<Plan>)>,
    first_sent_at_s: Option<f64>,
    first_curious: Option<bool>,
    ga_plans: u32,
}

impl<'a> DayRun<'a> {
    pub fn new(
        world: &'a DayWorld,
        config: &'a ExecutiveConfig,
        planner: Planner<'a>,
        robot: Robot,
        options: &DaysOptions,
    ) -> Result<DayRun<'a>, DaysError> {
        Ok(DayRun {
            world,
            config,
            planner,
            robot,
            calibration: Calibration::new(config.time_model_prior, CalibrationConfig::default())?,
            handover: Handover::first(config.margin()),
            position: None,
            rate: options.rate,
            plan_wall_s: options.plan_wall_s,
            reports: Vec::new(),
            truth: Vec::new(),
        })
    }

    /// The first fix, then every window of the day.
    pub fn drive_day(&mut self) -> Result<Vec<WindowResult>, DaysError> {
        self.first_fix()?;
        let tasks = &self.config.tasks;
        let mut windows = Vec::with_capacity(tasks.len());
        for (w, task) in tasks.iter().enumerate() {
            if let Some(result) = self.window(w, task, tasks.get(w + 1))? {
                windows.push(result);
            }
        }
        Ok(windows)
    }

    /// Steps until the robot has a fix (the executive waits for its first estimate).
    fn first_fix(&mut self) -> Result<(), DaysError> {
        for _ in 0..FIRST_FIX_STEPS {
            let step = self.robot.step()?;
            self.truth.push(step.truth);
            if self.robot.position().is_some() {
                return Ok(());
            }
        }
        Err(DaysError::World(format!(
            "no fix of the robot in its first {FIRST_FIX_STEPS} steps"
        )))
    }

    /// The model plans are made with: the fit, or Table I when not calibrating.
    fn time_model(&self) -> TimeModel {
        if self.config.calibrate {
            self.calibration.model()
        } else {
            TimeModel::table_i()
        }
    }

    fn now(&self) -> Now {
        let mission_s = self.robot.now_s();
        Now {
            mission_s,
            wall_s: mission_s / self.rate,
            planning_cost_s: self.config.planning_cost_s.unwrap_or(0.0),
            clock_rate: self.rate,
        }
    }

    /// Window `w` toward `task`; `None` when the task was over before it began.
    fn window(
        &mut self,
        w: usize,
        task: &Task,
        next: Option<&Task>,
    ) -> Result<Option<WindowResult>, DaysError> {
        let began = self.robot.now_s();
        let from = self
            .position
            .or(self.robot.position())
            .unwrap_or([f64::NAN, f64::NAN]);
        let model = self.time_model();
        let world = self.world;
        let setup = WindowSetup {
            window: w,
            task: task.clone(),
            next: next.cloned(),
            robot: self.config.robot.clone(),
            mission_tag: BATCH_TAG.to_owned(),
            from,
            time_model: model,
            watch: self.config.watch_params(model),
            rules: WindowRules::of(self.config),
            give_up_after_s: self.config.give_up_after_s,
            waypoint_spacing_m: self.config.waypoint_spacing_m,
            scale: InformationScale {
                world: &world.planning,
                params: &world.params,
            },
        };
        let handover = std::mem::replace(&mut self.handover, Handover::first(self.config.margin()));
        let (mut machine, actions) = DowntimeWindow::begin(setup, handover, self.now());
        let mut log = WindowLog::default();
        if let Some(&at) = self.truth.last() {
            log.track.truth.push(at);
        }
        let mut ended = self.perform(&mut machine, &mut log, actions)?;
        while ended.is_none() {
            ended = self.step_window(&mut machine, &mut log)?;
        }
        let Some(end) = ended else {
            return Ok(None);
        };
        self.handover = end.handover;
        self.position = Some(end.position);
        Ok(end.outcome.map(|outcome| {
            self.reports.push(outcome.report.clone());
            self.result(w, task, began, outcome, log)
        }))
    }

    /// One sim step of the window: its estimate, the controller's status, the answers
    /// due, a tick; the window's end if it came.
    fn step_window(
        &mut self,
        machine: &mut DowntimeWindow<'_>,
        log: &mut WindowLog,
    ) -> Result<Option<WindowEnd>, DaysError> {
        let step = self.robot.step()?;
        self.truth.push(step.truth);
        log.track.record(&step, self.world);
        let mut events = Vec::new();
        if let Some(e) = &step.estimate {
            events.push(WindowEvent::Estimate {
                position: e.position,
                peb_m: e.peb_m,
                degraded: e.degraded,
            });
        }
        if let (Some(d), Some((id, waypoints, route))) = (step.decision, &log.mission) {
            if *route {
                if let Some(leg) = log.legs.last_mut() {
                    leg.progress(d.distance_left_m);
                }
            }
            let status = controller_status(
                &self.config.robot,
                id,
                *waypoints,
                &d,
                step.estimate.as_ref(),
            );
            events.push(WindowEvent::Status(status));
        }
        // Each event is followed by a tick, as the live executive ticks after each.
        for event in events {
            for event in [event, WindowEvent::Tick] {
                let actions = machine.handle(event, self.now());
                if let Some(end) = self.perform(machine, log, actions)? {
                    return Ok(Some(end));
                }
            }
        }
        let actions = machine.handle(WindowEvent::Tick, self.now());
        self.perform(machine, log, actions)
    }

    /// Performs `actions` in order, then hands the machine every answer that is due
    /// (and performs what it asks in turn); the window's end if it came.
    fn perform(
        &mut self,
        machine: &mut DowntimeWindow<'_>,
        log: &mut WindowLog,
        actions: Vec<WindowAction>,
    ) -> Result<Option<WindowEnd>, DaysError> {
        let mut pending = VecDeque::from(actions);
        loop {
            while let Some(action) = pending.pop_front() {
                let now = self.robot.now_s();
                match action {
                    WindowAction::Drive(mission) => {
                        self.robot.send(&mission)?;
                        log.first_sent_at_s.get_or_insert(now);
                        if !mission.recovery {
                            log.legs.push(Leg::new(Vec::new()));
                        }
                        log.mission =
                            Some((mission.id, mission.waypoints.len(), !mission.recovery));
                    }
                    WindowAction::RequestPlan(ask) => {
                        log.ga_plans += u32::from(ask.curious);
                        let request = plan_request(self.config, &ask, self.time_model());
                        let answer = self
                            .planner
                            .answer(&request, self.robot.change_map(), now)
                            .ok();
                        let cost_s = if ask.curious {
                            self.plan_wall_s.min(ask.deadline_s) * self.rate
                        } else {
                            0.0
                        };
                        log.answers.push((now + cost_s, ask.id, answer));
                    }
                    WindowAction::Forget(id) => log.answers.retain(|a| a.1 != id),
                    WindowAction::Planned { curious, .. } => {
                        log.first_curious.get_or_insert(curious);
                    }
                    WindowAction::Arrived { drive, .. } => {
                        if self.config.calibrate {
                            let (d, theta) = path_measure(&drive.path);
                            self.calibration.add_planned(d, theta, drive.took_s);
                        }
                    }
                    WindowAction::Done(end) => return Ok(Some(*end)),
                    WindowAction::Replanned { .. }
                    | WindowAction::Recovering { .. }
                    | WindowAction::GaveUp
                    | WindowAction::Skipped => {}
                }
            }
            let now = self.robot.now_s();
            // The earliest answer that is due, in the order asked.
            let Some(i) = log.answers.iter().position(|a| a.0 <= now) else {
                return Ok(None);
            };
            let (_, id, answer) = log.answers.remove(i);
            let event = match answer {
                Some(plan) => WindowEvent::PlanReply {
                    id,
                    plan: Box::new(plan),
                },
                None => WindowEvent::PlanFailed { id },
            };
            pending.extend(machine.handle(event, self.now()));
        }
    }

    /// The window's measures: the machine's report, with what the batch sees that the
    /// executive cannot (the true path, the PEB there, the change seen).
    fn result(
        &self,
        w: usize,
        task: &Task,
        began: f64,
        outcome: WindowOutcome,
        mut log: WindowLog,
    ) -> WindowResult {
        let report = &outcome.report;
        let arrival = report.arrival_s;
        let window_s = task.start_s - began;
        let sent = log.first_sent_at_s.unwrap_or(began);
        let driving_s = arrival.map_or(0.0, |at| at - sent);
        for (leg, plan) in log.legs.iter_mut().zip(&outcome.plans) {
            leg.plan = plan.clone();
        }
        let planned = planned_path(&log.legs, arrival.is_some());
        let planned_information =
            roam_mission::information::gathered(&self.world.planning, &self.world.params, &planned);
        let driven_information = log.track.information(self.world);
        let time_model = report.time_model.filter(|_| arrival.is_some()).map(|m| {
            let took_s = m.driving_s;
            TimeModelUse {
                v_lin: m.v_lin,
                v_ang: m.v_ang,
                predicted_s: m.predicted_s,
                took_s,
                error: if took_s > 0.0 {
                    (m.predicted_s - took_s) / took_s
                } else {
                    0.0
                },
            }
        });
        WindowResult {
            window: w,
            task: task.name.clone(),
            began_s: began,
            task_start_s: task.start_s,
            window_s,
            arrival_s: arrival,
            late: arrival.is_none_or(|a| a > task.start_s),
            driving_s,
            share: if window_s > 0.0 {
                driving_s / window_s
            } else {
                0.0
            },
            waited_for_plan_s: sent - began,
            held_s: report.held_s,
            holds: report.holds,
            recoveries: report.recoveries,
            late_probability: report.late_probability,
            early_s: arrival
                .map(|a| task.start_s - a)
                .filter(|early| *early >= 0.0),
            budget_s: report.budget_s,
            curious: log.first_curious.unwrap_or(false),
            first_plan_cells: outcome.plans.first().map_or(0, Vec::len),
            ga_plans: log.ga_plans,
            driven_information,
            planned_information,
            shortest_information: report.shortest_information,
            driven_over_planned: (planned_information > 0.0)
                .then(|| driven_information / planned_information),
            changing_cells_seen: log.track.changing_cells_seen(self.world),
            peb_mean_m: log.track.peb_mean_m(),
            halted_steps: log.track.halted_steps,
            estimate_rms_m: log.track.estimate_rms_m(),
            replans: report
                .replan_reasons
                .iter()
                .map(|s| Reason::of_sentence(s).map_or("no_plan", Reason::name))
                .collect(),
            time_model,
        }
    }
}
