//! One variant's day: the robot from its start through the day's tasks, a window at a
//! time ([`super::window`]), the executive's state carried from window to window (its
//! time model, the next window's plans made during the task).

use roam_controller::params::{ApfParams, Follow};
use serde::Serialize;

use super::measure::{Track, WindowResult};
use super::planning::{plan_seed, Planned, Planner};
use super::robot::{Robot, Step};
use super::variant::{Settings, Variant};
use super::world::DayWorld;
use super::{DaysError, DaysOptions};
use roam_mission::calibration::{Calibration, CalibrationConfig, TimeModel};
use roam_mission::executive::ExecutiveConfig;
use roam_mission::margin::ArrivalMargin;
use roam_mission::path::mission_waypoints;
use roam_mission::tasks::Task;
use roam_mission::watch::WatchParams;
use roam_world::seed::splitmix64;

/// How often the executive asks again for a window's first plans when none came
/// ([`roam_mission::window::PLAN_RETRY_S`], wall seconds there), mission seconds.
const PLAN_RETRY_S: f64 = 1.0;

/// The steps the day may take to get the robot's first fix.
const FIRST_FIX_STEPS: usize = 100;

/// The sim's stream of a day, apart from its plans' streams.
const SIM_STREAM: u64 = 0x51_4D_5F_53_54_52_45_41;

/// One variant's day.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DayResult {
    pub day: usize,
    pub variant: Variant,
    pub windows: Vec<WindowResult>,
    /// The ranges of the day's first scan: the same in every variant of a day (the
    /// sim's noise depends on the day, not on the variant).
    pub first_ranges: Vec<f64>,
    /// The robot's true path through the whole day (not in the JSON: large).
    #[serde(skip)]
    pub truth: Vec<[f64; 2]>,
}

/// A window's plans made ahead, while the robot did the previous task.
pub(super) struct PlannedAhead {
    pub window: usize,
    pub from: [f64; 2],
    pub shortest: Planned,
    pub plan: Planned,
    pub budget_s: f64,
    /// Curious plans already made for the window (the seeds' rank goes on from here).
    pub ranks: u32,
}

/// The executive's state through one variant's day.
pub(super) struct DayRun<'a> {
    pub world: &'a DayWorld,
    pub settings: Settings,
    pub planner: Planner<'a>,
    pub robot: Robot,
    pub calibration: Calibration,
    /// The executive's own settings (`ExecutiveConfig::default()`: waypoint spacing,
    /// the replan policy's thresholds, the arrival margin), which every variant shares.
    pub executive: ExecutiveConfig,
    pub margin: ArrivalMargin,
    pub plan_cost_s: f64,
    pub day_seed: u64,
    pub planned_ahead: Option<PlannedAhead>,
    /// The whole day's true path.
    pub truth: Vec<[f64; 2]>,
}

/// The seed of day `day` in a batch seeded `seed`.
pub fn day_seed(seed: u64, day: usize) -> u64 {
    splitmix64(seed ^ splitmix64(day as u64))
}

/// Runs day `day` of `variant`.
pub fn run_day(
    world: &DayWorld,
    variant: Variant,
    options: &DaysOptions,
    day: usize,
) -> Result<DayResult, DaysError> {
    let settings = variant.settings(options.w_loc);
    let executive = ExecutiveConfig::default();
    let seed = day_seed(options.seed, day);
    let apf = ApfParams {
        follow: settings.follow,
        ..ApfParams::indoor()
    };
    let mut run = DayRun {
        world,
        settings,
        planner: Planner {
            world,
            generations: options.generations,
            w_loc: settings.w_loc,
            change: settings.change,
        },
        robot: Robot::new(world, &apf, splitmix64(seed ^ SIM_STREAM))?,
        calibration: Calibration::new(TimeModel::table_i(), CalibrationConfig::default())?,
        margin: if settings.arrival_guard {
            executive.margin()
        } else {
            ArrivalMargin::none()
        },
        executive,
        plan_cost_s: options.plan_cost_s,
        day_seed: seed,
        planned_ahead: None,
        truth: Vec::new(),
    };
    run.first_fix()?;
    let mut windows = Vec::with_capacity(world.tasks.len());
    for (w, task) in world.tasks.iter().enumerate() {
        if let Some(result) = run.window(w, task, world.tasks.get(w + 1))? {
            windows.push(result);
        }
    }
    Ok(DayResult {
        day,
        variant,
        windows,
        first_ranges: run.robot.first_ranges().to_vec(),
        truth: run.truth,
    })
}

impl DayRun<'_> {
    /// Steps until the robot has a fix (the executive waits for its first estimate).
    fn first_fix(&mut self) -> Result<(), DaysError> {
        for _ in 0..FIRST_FIX_STEPS {
            self.advance(None)?;
            if self.robot.position().is_some() {
                return Ok(());
            }
        }
        Err(DaysError::World(format!(
            "no fix of the robot in its first {FIRST_FIX_STEPS} steps"
        )))
    }

    /// Where the executive believes the robot is: its last estimate that was not
    /// degraded ([`DayRun::first_fix`] made sure there is one).
    pub fn here(&self) -> [f64; 2] {
        self.robot.position().unwrap_or([f64::NAN, f64::NAN])
    }

    /// The model plans are made with: the fit, or Table I when not calibrating.
    pub fn time_model(&self) -> TimeModel {
        if self.settings.calibrate {
            self.calibration.model()
        } else {
            TimeModel::table_i()
        }
    }

    /// The watch's parameters, as the executive makes them from its config and model.
    pub fn watch_params(&self) -> WatchParams {
        WatchParams {
            slack_s: if self.settings.slack {
                self.executive.slack_s
            } else {
                f64::INFINITY
            },
            behind: self.settings.arrival_guard,
            ..self.executive.watch_params(self.time_model())
        }
    }

    /// A plan as the controller's mission: every turn (`follow: path`), or today's
    /// thinning to mutually visible points (`follow: waypoints`).
    pub fn waypoints(&self, plan: &Planned) -> Vec<[f64; 2]> {
        match self.settings.follow {
            Follow::Path => mission_waypoints(&plan.points, self.executive.waypoint_spacing_m),
            Follow::Waypoints => {
                super::thin::thin(&plan.points, self.executive.waypoint_spacing_m, |a, b| {
                    super::thin::line_of_sight(&self.world.planning, a, b)
                })
            }
        }
    }

    /// One step, kept in the day's path and in `track` (the window's drive).
    pub fn advance(&mut self, track: Option<&mut Track>) -> Result<Step, DaysError> {
        let step = self.robot.step()?;
        self.truth.push(step.truth);
        if let Some(t) = track {
            t.record(&step, self.world);
        }
        Ok(step)
    }

    /// Steps until the mission clock reaches `t_s`.
    pub fn run_until(&mut self, t_s: f64, mut track: Option<&mut Track>) -> Result<(), DaysError> {
        while self.robot.now_s() < t_s {
            self.advance(track.as_deref_mut())?;
        }
        Ok(())
    }

    /// The curious plan for the budget, or the shortest when curiosity does not fit
    /// (the executive's rule, [`roam_mission::window`]), with the budget. A curious plan costs
    /// `plan_cost_s` of mission time, through which the robot goes on as it was (its
    /// mission, a hold, or standing at its task). `leave_at_s`: the robot cannot set
    /// off before (a window planned during the previous task). `rank` counts the
    /// window's curious plans (their seeds).
    #[allow(clippy::too_many_arguments)]
    pub fn plan_window(
        &mut self,
        from: [f64; 2],
        task: &Task,
        window: usize,
        rank: &mut u32,
        shortest: &Planned,
        curious: bool,
        leave_at_s: Option<f64>,
        track: Option<&mut Track>,
    ) -> Result<(Planned, f64), DaysError> {
        let now = self.robot.now_s();
        let earliest = now + self.plan_cost_s;
        let time_left = task.start_s - leave_at_s.map_or(earliest, |at| at.max(earliest));
        let budget = self.margin.budget(time_left);
        if !(curious && self.settings.curious) || budget <= shortest.t_eta_s {
            return Ok((shortest.clone(), budget));
        }
        let map = self.planner.map(self.robot.change_map(), now);
        let seed = plan_seed(self.day_seed, window, *rank);
        *rank += 1;
        let planned =
            self.planner
                .curious(map.as_ref(), from, task.at, budget, self.time_model(), seed);
        self.run_until(now + self.plan_cost_s, track)?;
        match planned {
            Ok(Some(plan)) => Ok((plan, budget)),
            // Refused or not fitting: the executive takes the shortest path.
            Ok(None) | Err(_) => Ok((shortest.clone(), budget)),
        }
    }

    /// A window's shortest and curious plans (the executive's first plan): asked
    /// again every [`PLAN_RETRY_S`] while the planner refuses (the estimate in an
    /// inflated cell), `None` once the window is given up.
    #[allow(clippy::too_many_arguments)]
    pub fn first_plans(
        &mut self,
        from: Option<[f64; 2]>,
        task: &Task,
        window: usize,
        rank: &mut u32,
        leave_at_s: Option<f64>,
        mut track: Option<&mut Track>,
    ) -> Result<Option<(Planned, Planned, f64)>, DaysError> {
        loop {
            let start = from.unwrap_or_else(|| self.here());
            if let Ok(shortest) = self
                .planner
                .shortest(None, start, task.at, self.time_model())
            {
                let (plan, budget) = self.plan_window(
                    start,
                    task,
                    window,
                    rank,
                    &shortest,
                    true,
                    leave_at_s,
                    track.as_deref_mut(),
                )?;
                return Ok(Some((shortest, plan, budget)));
            }
            if self.robot.now_s() > task.start_s + self.executive.give_up_after_s {
                return Ok(None);
            }
            let until = self.robot.now_s() + PLAN_RETRY_S;
            self.run_until(until, track.as_deref_mut())?;
        }
    }
}
