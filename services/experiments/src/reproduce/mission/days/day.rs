//! One variant's day: the executive in process ([`InProcessExecutive`], the
//! executive's own window machine driven as the live executive drives it) with the
//! day's robot ([`Robot`]: the sim, localization, the APF controller and the mapper's
//! change map one step at a time) and the planner's own code ([`Planner`]).

use roam_controller::params::ApfParams;
use roam_mission::config::ExecutiveConfig;
use roam_mission::information::InformationScale;
use roam_mission::watch::Reason;
use roam_mission::window::NO_PLAN_REASON;
use roam_proto::controller::Mission;
use roam_proto::mission::WindowReport;
use roam_proto::planner::{Plan, PlanRequest};
use roam_world::seed::splitmix64;
use serde::Serialize;

use super::error::DaysError;
use super::measure::{TimeModelUse, WindowResult};
use super::options::DaysOptions;
use super::planning::Planner;
use super::robot::Robot;
use super::variant::Variant;
use super::world::DayWorld;
use crate::closed_loop::setup::EpisodeError;
use crate::reproduce::executive::track::planned_path;
use crate::reproduce::executive::{FinishedWindow, InProcessExecutive, Io};

/// The sim's stream of a day, apart from its plans' streams.
const SIM_STREAM: u64 = 0x51_4D_5F_53_54_52_45_41;

pub use crate::reproduce::executive::BATCH_TAG;

/// One variant's day.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DayResult {
    pub day: usize,
    pub variant: Variant,
    pub windows: Vec<WindowResult>,
    /// Scans localization refused through the day (an error, not a missing fix: the
    /// step goes on without an estimate), counted so that none hides.
    pub localization_errors: u64,
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
    /// Every plan request the executive made, in order (not in the JSON): what `roam
    /// bench planner --replans` times.
    #[serde(skip)]
    pub asked: Vec<PlanRequest>,
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
        replan_cost_s: Some(options.replan_wall_s * options.rate),
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
    let driven = drive(
        world,
        &config,
        variant.change_coupling(),
        sim_seed(seed),
        options,
    )?;
    Ok(DayResult {
        day,
        variant,
        windows: driven.windows,
        localization_errors: driven.localization_errors,
        first_ranges: driven.first_ranges,
        reports: driven.reports,
        truth: driven.truth,
        asked: driven.asked,
    })
}

/// What [`drive`] returns.
#[derive(Debug)]
pub struct Driven {
    /// The windows' measures.
    pub windows: Vec<WindowResult>,
    /// The ranges of the day's first scan.
    pub first_ranges: Vec<f64>,
    /// The executive's window reports.
    pub reports: Vec<WindowReport>,
    /// The robot's true path.
    pub truth: Vec<[f64; 2]>,
    /// Scans localization refused.
    pub localization_errors: u64,
    /// The executive's plan requests, in order.
    pub asked: Vec<PlanRequest>,
}

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
    Ok(Driven {
        windows,
        first_ranges: day_run.robot.first_ranges().to_vec(),
        reports: std::mem::take(&mut day_run.executive.reports),
        localization_errors: day_run.robot.localization_errors(),
        truth: day_run.truth,
        asked: day_run.asked,
    })
}

/// The executive through one variant's day, and the robot it drives.
#[derive(Debug)]
pub struct DayRun<'a> {
    pub world: &'a DayWorld,
    pub executive: InProcessExecutive<'a>,
    pub planner: Planner<'a>,
    pub robot: Robot,
    /// The whole day's true path.
    pub truth: Vec<[f64; 2]>,
    /// The executive's plan requests, in order.
    pub asked: Vec<PlanRequest>,
}

/// The day's robot and planner, as the executive in process asks them.
struct DayIo<'r, 'a> {
    robot: &'r mut Robot,
    planner: &'r Planner<'a>,
    asked: &'r mut Vec<PlanRequest>,
}

impl Io for DayIo<'_, '_> {
    fn send(&mut self, mission: &Mission) -> Result<(), EpisodeError> {
        self.robot.send(mission)
    }

    fn answer(&mut self, request: &PlanRequest, now_s: f64) -> Result<Plan, &'static str> {
        self.asked.push(request.clone());
        self.planner
            .answer(request, self.robot.change_map(), now_s)
            .map_err(|e| e.kind())
    }
}

impl<'a> DayRun<'a> {
    pub fn new(
        world: &'a DayWorld,
        config: &'a ExecutiveConfig,
        planner: Planner<'a>,
        robot: Robot,
        options: &DaysOptions,
    ) -> Result<DayRun<'a>, DaysError> {
        let scale = InformationScale {
            world: &world.planning,
            params: &world.params,
        };
        Ok(DayRun {
            world,
            executive: InProcessExecutive::new(
                config,
                scale,
                options.rate,
                (options.plan_wall_s, options.replan_wall_s),
            )?,
            planner,
            robot,
            truth: Vec::new(),
            asked: Vec::new(),
        })
    }

    /// The first fix, then every window of the day.
    pub fn drive_day(&mut self) -> Result<Vec<WindowResult>, DaysError> {
        let mut windows = Vec::new();
        while !self.executive.done() {
            let step = self.robot.step()?;
            self.truth.push(step.truth);
            let mut io = DayIo {
                robot: &mut self.robot,
                planner: &self.planner,
                asked: &mut self.asked,
            };
            self.executive.on_step(&step, &mut io)?;
            for finished in self.executive.take_finished() {
                windows.push(self.result(finished));
            }
        }
        Ok(windows)
    }

    /// The window's measures: the machine's report, with what the batch sees that the
    /// executive cannot (the true path, the PEB there, the change seen).
    fn result(&self, finished: FinishedWindow) -> WindowResult {
        let FinishedWindow {
            index: w,
            task,
            began_s: began,
            outcome,
            mut log,
        } = finished;
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
        let driven_information = log
            .track
            .information(&self.world.planning, &self.world.params);
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
            refused_plans: log.refused_plans,
            driven_information,
            planned_information,
            shortest_information: report.shortest_information,
            driven_over_planned: (planned_information > 0.0)
                .then(|| driven_information / planned_information),
            changing_cells_seen: log
                .track
                .information(&self.world.changing, &self.world.params),
            peb_mean_m: log.track.peb_mean_m(),
            halted_steps: log.track.halted_steps,
            estimate_rms_m: log.track.estimate_rms_m(),
            replans: report
                .replan_reasons
                .iter()
                .map(|s| Reason::of_name(s).map_or(NO_PLAN_REASON, Reason::name))
                .collect(),
            time_model,
        }
    }
}
