//! The mission executive in process: one robot's day driven by the executive's own
//! window machine ([`roam_mission::window::DowntimeWindow`]) exactly as the live
//! executive ([`roam_mission::executive`]) drives it, with its actions answered in
//! process instead of over Zenoh:
//!
//! | action | live (`roam mission`) | here |
//! |---|---|---|
//! | `Drive(mission)` | put on `robot/<id>/mission` | [`Io::send`]: the stepper's controller takes it |
//! | `RequestPlan(ask)` | [`plan_request`] to the planner service | [`plan_request`] answered by [`Io::answer`] (the planner's own code), delivered `planning_cost_s` of mission time later |
//! | `Forget(id)` | the request dropped (cancelled) | its answer dropped |
//! | `Arrived` | the calibration learns | the same calibration learns |
//!
//! and its events heard in the same order: every sim step, localization's estimate,
//! the controller's status on the current mission (the controller service's own
//! message, [`controller_status`]), each followed by a tick (the live executive ticks
//! after every event), the plan answers that are due, then a tick. Wall time is
//! mission time over the clock's rate (the demo's 20×), so the wall-clock rules (plan
//! retries, a silent controller) behave as they do in the demo.
//!
//! The caller steps the sim and hands each robot's [`Step`] to its executive
//! ([`InProcessExecutive::on_step`]); a day of one robot (`roam reproduce mission
//! --days`) and a fleet's shift (`roam reproduce fleet`) are both this, one executive
//! per robot.

mod step;
pub mod track;

use std::collections::{BTreeMap, VecDeque};
use std::sync::Arc;

use roam_controller::status::controller_status;
use roam_mission::calibration::{Calibration, CalibrationConfig, CalibrationError, TimeModel};
use roam_mission::config::ExecutiveConfig;
use roam_mission::information::InformationScale;
use roam_mission::request::plan_request;
use roam_mission::tasks::Task;
use roam_mission::window::{
    DowntimeWindow, Handover, Now, SeenObstacles, WindowAction, WindowEnd, WindowEvent,
    WindowOutcome, WindowRules, WindowSetup,
};
use roam_proto::controller::Mission;
use roam_proto::mission::WindowReport;
use roam_proto::planner::{Plan, PlanRequest};

use crate::closed_loop::setup::EpisodeError;
pub use step::Step;
use track::{Leg, Track};

/// The steps an executive waits for its robot's first fix.
pub const FIRST_FIX_STEPS: usize = 100;

/// The mission tag of an executive in process (a live one takes its Zenoh session's).
pub const BATCH_TAG: &str = "batch";

/// What an executive in process asks of the world around it.
pub trait Io {
    /// The controller takes `mission` (an empty one holds the robot).
    fn send(&mut self, mission: &Mission) -> Result<(), EpisodeError>;
    /// The planner's answer to `request`, asked at mission time `now_s`; when it
    /// refuses, a short token for why (`roam_planner::plan::PlanError::kind`), counted
    /// in the window's log.
    fn answer(&mut self, request: &PlanRequest, now_s: f64) -> Result<Plan, &'static str>;
}

/// Why an executive in process stopped.
#[derive(Debug, thiserror::Error)]
pub enum ExecutiveError {
    #[error("driving: {0}")]
    Drive(#[from] EpisodeError),
    #[error("the time model: {0}")]
    Calibration(#[from] CalibrationError),
    #[error("no fix of robot {robot:?} in its first {FIRST_FIX_STEPS} steps")]
    NoFix { robot: String },
}

/// What one window's drive records beside the machine.
#[derive(Debug, Default)]
pub struct WindowLog {
    pub track: Track,
    /// One per mission that drives a route (recoveries are not routes).
    pub legs: Vec<Leg>,
    /// The current mission: its id, its waypoints, whether it is a route.
    mission: Option<(String, usize, bool)>,
    /// Answers on their way: when they are due, for which ask, the answer.
    answers: Vec<(f64, u64, Option<Plan>)>,
    pub first_sent_at_s: Option<f64>,
    pub first_curious: Option<bool>,
    pub ga_plans: u32,
    /// Plans the planner refused (an error, not a plan the budget cut): the window
    /// machine then goes on as the live executive does on a refusal, and the reports
    /// count them.
    pub refused_plans: u32,
    /// The same refusals by kind (`roam_planner::plan::PlanError::kind`, or the batch's
    /// own: `no_patrol`, `news`).
    pub refusals: BTreeMap<&'static str, u32>,
}

/// A window that ended with an outcome.
#[derive(Debug)]
pub struct FinishedWindow {
    pub index: usize,
    pub task: Task,
    pub began_s: f64,
    pub outcome: WindowOutcome,
    pub log: WindowLog,
}

/// The window being driven.
#[derive(Debug)]
struct Current<'a> {
    index: usize,
    began_s: f64,
    machine: DowntimeWindow<'a>,
    log: WindowLog,
}

/// One robot's executive, in process (module doc).
#[derive(Debug)]
pub struct InProcessExecutive<'a> {
    config: &'a ExecutiveConfig,
    scale: InformationScale<'a>,
    calibration: Calibration,
    /// What the last window handed the next, and where it left the robot (its last good
    /// estimate, as the live executive keeps it).
    handover: Option<Handover>,
    position: Option<[f64; 2]>,
    /// The robot's last estimate that was not degraded.
    fix: Option<[f64; 2]>,
    /// The clock's rate: wall time is mission time over it.
    rate: f64,
    /// What a curious plan costs at most, wall seconds (its deadline may cut it).
    plan_wall_s: f64,
    /// The same for a replan seeded with the route left.
    replan_wall_s: f64,
    now_s: f64,
    last_truth: Option<[f64; 2]>,
    steps_without_fix: usize,
    next_task: usize,
    current: Option<Current<'a>>,
    /// The executive's own window reports, as the live executive publishes them.
    pub reports: Vec<WindowReport>,
    finished: Vec<FinishedWindow>,
}

impl<'a> InProcessExecutive<'a> {
    /// The executive configured by `config`, planning on `scale`'s map, at a clock
    /// `rate` times real time with curious plans costing `plan_wall_s` wall seconds and
    /// seeded replans `replan_wall_s` (`walls`; each cut to its deadline).
    pub fn new(
        config: &'a ExecutiveConfig,
        scale: InformationScale<'a>,
        rate: f64,
        (plan_wall_s, replan_wall_s): (f64, f64),
    ) -> Result<InProcessExecutive<'a>, ExecutiveError> {
        Ok(InProcessExecutive {
            config,
            scale,
            calibration: Calibration::new(config.time_model_prior, CalibrationConfig::default())?,
            handover: Some(Handover::first(config.margin())),
            position: None,
            fix: None,
            rate,
            plan_wall_s,
            replan_wall_s,
            now_s: 0.0,
            last_truth: None,
            steps_without_fix: 0,
            next_task: 0,
            current: None,
            reports: Vec::new(),
            finished: Vec::new(),
        })
    }

    /// Every task's window is over.
    pub fn done(&self) -> bool {
        self.current.is_none() && self.next_task >= self.config.tasks.len()
    }

    /// The windows that ended since the last call, in order.
    pub fn take_finished(&mut self) -> Vec<FinishedWindow> {
        std::mem::take(&mut self.finished)
    }

    /// The robot's current route, if a window drives one (the last mission sent).
    pub fn current_plan(&self) -> Option<&[[f64; 2]]> {
        let current = self.current.as_ref()?;
        current.log.legs.last().map(|l| l.plan.as_slice())
    }

    /// The time model plans are made with: the fit, or Table I when not calibrating.
    pub fn time_model(&self) -> TimeModel {
        if self.config.calibrate {
            self.calibration.model()
        } else {
            TimeModel::table_i()
        }
    }

    fn now(&self) -> Now {
        Now {
            mission_s: self.now_s,
            wall_s: self.now_s / self.rate,
            planning_cost_s: self.config.planning_cost_s.unwrap_or(0.0),
            replan_cost_s: self
                .config
                .replan_cost_s
                .or(self.config.planning_cost_s)
                .unwrap_or(0.0),
            clock_rate: self.rate,
        }
    }

    /// One sim step of the robot: before its first fix, the fix is awaited; then the
    /// current window hears the step (its estimate, the controller's status, the
    /// answers due, ticks), and a window that ends hands over to the next at once.
    pub fn on_step(&mut self, step: &Step, io: &mut dyn Io) -> Result<(), ExecutiveError> {
        self.now_s = step.time_s;
        self.last_truth = Some(step.truth);
        if let Some(e) = step.estimate.as_ref().filter(|e| !e.degraded) {
            self.fix = Some(e.position);
        }
        if self.done() {
            return Ok(());
        }
        let Some(mut current) = self.current.take() else {
            if self.fix.is_none() {
                self.steps_without_fix += 1;
                if self.steps_without_fix >= FIRST_FIX_STEPS {
                    return Err(ExecutiveError::NoFix {
                        robot: self.config.robot.clone(),
                    });
                }
                return Ok(());
            }
            return self.begin_next(io);
        };
        current.log.track.record(step, self.scale.world);
        let mut events = Vec::new();
        if let Some(e) = &step.estimate {
            events.push(WindowEvent::Estimate {
                position: e.position,
                peb_m: e.peb_m,
                degraded: e.degraded,
                time_s: e.time_s,
            });
        }
        if let (Some(d), Some((id, waypoints, route))) = (step.decision, &current.log.mission) {
            if *route {
                if let Some(leg) = current.log.legs.last_mut() {
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
        let Some(mut current) = self.hear(current, events, io)? else {
            return Ok(());
        };
        let actions = current.machine.handle(WindowEvent::Tick, self.now());
        match self.perform(&mut current, actions, io)? {
            Some(end) => self.end_window(current, end, io),
            None => {
                self.current = Some(current);
                Ok(())
            }
        }
    }

    /// A new set of the obstacles the fleet believes in, heard at the step's time (after
    /// the step's own events, as `on_step` ran them): the current window checks its
    /// route against it (`roam_mission::window`, `blocked.rs`), or the next window
    /// begins with it. Heard only when the config follows an `obstacles_layer`, as the
    /// live executive does.
    pub fn on_obstacles(
        &mut self,
        set: Arc<SeenObstacles>,
        io: &mut dyn Io,
    ) -> Result<(), ExecutiveError> {
        if self.config.obstacles_layer.is_none() || self.done() {
            return Ok(());
        }
        let Some(current) = self.current.take() else {
            if let Some(handover) = self.handover.as_mut() {
                handover.obstacles = Some(set);
            }
            return Ok(());
        };
        self.current = self.hear(current, vec![WindowEvent::MapChanged(set)], io)?;
        Ok(())
    }

    /// The current window hears `events`, each followed by a tick, as the live executive
    /// ticks after each; `None` when the window ended (handed over to the next).
    fn hear(
        &mut self,
        mut current: Current<'a>,
        events: Vec<WindowEvent>,
        io: &mut dyn Io,
    ) -> Result<Option<Current<'a>>, ExecutiveError> {
        for event in events {
            for event in [event, WindowEvent::Tick] {
                let actions = current.machine.handle(event, self.now());
                if let Some(end) = self.perform(&mut current, actions, io)? {
                    self.end_window(current, end, io)?;
                    return Ok(None);
                }
            }
        }
        Ok(Some(current))
    }

    /// Begins the next task's window, now (and the ones after it, while a window ends
    /// as it begins: a task already over).
    fn begin_next(&mut self, io: &mut dyn Io) -> Result<(), ExecutiveError> {
        while self.current.is_none() && self.next_task < self.config.tasks.len() {
            let index = self.next_task;
            self.next_task += 1;
            let tasks = &self.config.tasks;
            let (task, next) = (tasks[index].clone(), tasks.get(index + 1).cloned());
            let from = self.position.or(self.fix).unwrap_or([f64::NAN, f64::NAN]);
            let model = self.time_model();
            let setup = WindowSetup {
                window: index,
                task,
                next,
                robot: self.config.robot.clone(),
                mission_tag: BATCH_TAG.to_owned(),
                from,
                time_model: model,
                watch: self.config.watch_params(model),
                rules: WindowRules::of(self.config),
                give_up_after_s: self.config.give_up_after_s,
                waypoint_spacing_m: self.config.waypoint_spacing_m,
                scale: self.scale,
            };
            let handover = self
                .handover
                .take()
                .unwrap_or_else(|| Handover::first(self.config.margin()));
            let (machine, actions) = DowntimeWindow::begin(setup, handover, self.now());
            let mut current = Current {
                index,
                began_s: self.now_s,
                machine,
                log: WindowLog::default(),
            };
            if let Some(at) = self.last_truth {
                current.log.track.truth.push(at);
            }
            match self.perform(&mut current, actions, io)? {
                Some(end) => self.finish(current, end),
                None => self.current = Some(current),
            }
        }
        Ok(())
    }

    /// A window ended: its outcome kept, the next begun.
    fn end_window(
        &mut self,
        current: Current<'a>,
        end: WindowEnd,
        io: &mut dyn Io,
    ) -> Result<(), ExecutiveError> {
        self.finish(current, end);
        self.begin_next(io)
    }

    fn finish(&mut self, current: Current<'a>, end: WindowEnd) {
        self.handover = Some(end.handover);
        self.position = Some(end.position);
        if let Some(outcome) = end.outcome {
            self.reports.push(outcome.report.clone());
            self.finished.push(FinishedWindow {
                index: current.index,
                task: self.config.tasks[current.index].clone(),
                began_s: current.began_s,
                outcome,
                log: current.log,
            });
        }
    }

    /// Performs `actions` in order, then hands the machine every answer that is due
    /// (and performs what it asks in turn); the window's end if it came.
    fn perform(
        &mut self,
        current: &mut Current<'a>,
        actions: Vec<WindowAction>,
        io: &mut dyn Io,
    ) -> Result<Option<WindowEnd>, ExecutiveError> {
        let mut pending = VecDeque::from(actions);
        let log = &mut current.log;
        loop {
            while let Some(action) = pending.pop_front() {
                let now = self.now_s;
                match action {
                    WindowAction::Drive(mission) => {
                        io.send(&mission)?;
                        log.first_sent_at_s.get_or_insert(now);
                        if !mission.recovery {
                            log.legs.push(Leg::new(mission.waypoints.clone()));
                        }
                        log.mission =
                            Some((mission.id, mission.waypoints.len(), !mission.recovery));
                    }
                    WindowAction::RequestPlan(ask) => {
                        log.ga_plans += u32::from(ask.curious);
                        let request = plan_request(self.config, &ask, self.time_model());
                        let answer = match io.answer(&request, now) {
                            Ok(plan) => Some(plan),
                            Err(why) => {
                                log.refused_plans += 1;
                                *log.refusals.entry(why).or_default() += 1;
                                None
                            }
                        };
                        let wall_s = if ask.seed_route.is_empty() {
                            self.plan_wall_s
                        } else {
                            self.replan_wall_s
                        };
                        let cost_s = if ask.curious {
                            wall_s.min(ask.deadline_s) * self.rate
                        } else {
                            0.0
                        };
                        log.answers.push((now + cost_s, ask.id, answer));
                    }
                    WindowAction::Forget(id) => log.answers.retain(|a| a.1 != id),
                    WindowAction::Planned { curious, .. } => {
                        log.first_curious.get_or_insert(curious);
                    }
                    WindowAction::Arrived { drives, .. } => {
                        if self.config.calibrate {
                            for drive in drives {
                                drive.teach(&mut self.calibration);
                            }
                        }
                    }
                    WindowAction::Done(end) => return Ok(Some(*end)),
                    WindowAction::Replanned { .. }
                    | WindowAction::Recovering { .. }
                    | WindowAction::GaveUp
                    | WindowAction::Skipped => {}
                }
            }
            let now = self.now_s;
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
            pending.extend(current.machine.handle(event, self.now()));
        }
    }
}
