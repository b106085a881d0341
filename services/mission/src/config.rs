//! How the executive plans and watches: [`ExecutiveConfig`], the one configuration the
//! live executive (`roam mission --config`) and the batch of days
//! (`roam_experiments::reproduce::mission::days`) both run. Every variant a batch
//! compares is a value of it, so a report's "variant" is a configuration a user can
//! run, never a second program.

use std::path::PathBuf;

use roam_proto::keys;
use roam_proto::planner::PlannerModel;
use serde::{Deserialize, Serialize};

use crate::calibration::TimeModel;
use crate::margin::ArrivalMargin;
use crate::tasks::{self, Task, TaskError};
use crate::watch::WatchParams;

/// [`ExecutiveConfig::replan_generations`] by default: at population 200 on the day
/// world a seeded replan then takes a p99 of 40 ms (`roam bench planner --replans`;
/// 60 generations took 52 ms, over the 50 ms goal), for a median 0.99 of the
/// information 1000 generations from scratch find (services/planner/README.md,
/// "Replans").
pub const DEFAULT_REPLAN_GENERATIONS: u32 = 40;

/// How the executive plans and watches.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ExecutiveConfig {
    /// The robot this executive drives.
    pub robot: String,
    pub tasks: Vec<Task>,
    /// The planner for downtime paths: paper 000's GA under a curiosity model
    /// (`model1` by default; `model0`, `model2`), `greedy`, or `anytime` (the greedy
    /// planner's route at once, then the GA under Model I seeded with it, the fitter by
    /// Model I's F1); `shortest` drives the fastest path in every window (the
    /// baseline). Model I, not `anytime`, by default: on the executive's day (50 days,
    /// `roam reproduce mission --days 50 --variants executive,anytime`) the portfolio
    /// gathered 8% less information a day, on time alike (services/mission/README.md,
    /// "The anytime portfolio in the day"). With `anytime`, a replan seeded with the
    /// route left runs the GA alone under Model I (the route left is its warm start,
    /// and the greedy planner's 25–110 ms would break the replans' 50 ms).
    pub model: PlannerModel,
    /// The planner's deadline, wall seconds (paper 000's t_plan), at most: a replan's
    /// is cut to what the window can afford ([`ExecutiveConfig::replan_time_share`]).
    pub plan_deadline_s: f64,
    /// Generations the GA may run at most (it stops at the deadline anyway).
    pub max_generations: Option<u32>,
    /// Generations of a replan made while the robot drives (slack, behind, pushed off
    /// its path, stuck): it is seeded with the route the robot drives
    /// ([`roam_proto::planner::PlanRequest::seed_route`]), so it starts from a good
    /// path and needs fewer; at most `max_generations`, `None`: `max_generations`. What a replan costs at the
    /// default is measured by `roam bench planner --replans`.
    pub replan_generations: Option<u32>,
    /// The planner's localizability cost W_loc (paper 002's PEB in paper 000's fitness;
    /// see the planner's `w_loc`). `None`: the planner's default, off.
    pub w_loc: Option<f64>,
    /// The PEB the localizability cost forgives, metres (the planner's `peb_free_m`).
    /// `None`: the planner's default, 0.
    pub peb_free_m: Option<f64>,
    pub seed: u64,
    /// Waypoints are at most this far apart along the planned path, metres.
    pub waypoint_spacing_m: f64,
    /// An estimate farther than this from the planned path means the robot was pushed
    /// off it: replan from where it is, metres.
    pub off_path_m: f64,
    /// The robot's top speed for the ETA-slip check, m/s.
    pub speed_m_per_s: f64,
    /// Replans per window at most.
    pub max_replans: u32,
    /// A window is given up this long after its task's start, seconds.
    pub give_up_after_s: f64,
    /// No status from the controller on the current mission for this long (wall
    /// seconds) means the controller lost it (it restarted, or the robot's link was
    /// down when the mission was sent): replan from where the robot is and send again.
    pub controller_silence_s: f64,
    /// Arriving this much earlier than the task's start is slack: the executive replans
    /// a curious path with the time left (the mirror of the ETA slip rule), seconds.
    /// Infinity turns the rule off.
    pub slack_s: f64,
    /// Mission seconds between two slack replans at least.
    pub slack_interval_s: f64,
    /// A slack or behind replan is made only when at least this much of the window is
    /// left after it, seconds: a short replan near a window's end is the one a time
    /// model gets most wrong, and where the batch's late arrivals came from.
    pub min_replan_window_s: f64,
    /// The behind rule ([`crate::watch`]): replan a curious path when the robot's own
    /// pace says it would arrive late though its top speed would not.
    pub behind: bool,
    /// Plan the next window while the robot drives toward (and works at) this task, so
    /// that planning costs the next window nothing.
    pub plan_ahead: bool,
    /// A window without a plan made ahead sets off at once on the fastest path (the
    /// window computes it) while its curious plan is made from where the robot will be
    /// when it comes, instead of waiting for the plan ([`crate::window`]).
    pub set_off_at_once: bool,
    /// The largest share of the time left that a plan may cost on the mission clock:
    /// its deadline is cut to `replan_time_share × time left / clock rate` (at the
    /// demo's 20×, a minute left gives a replan 0.3 s of wall time).
    pub replan_time_share: f64,
    /// The arrival margin's floor share of the time to the task, and floor seconds
    /// ([`crate::margin`]); `0` and `0` with `late_probability` 1 leave no margin.
    pub arrival_margin_share: f64,
    pub arrival_margin_min_s: f64,
    /// The probability of arriving late that each plan's margin is sized for, from the
    /// robot's own prediction errors ([`crate::margin`]); in (0, 1].
    pub late_probability: f64,
    /// Recover a robot that the controller's PEB guard holds: after `hold_patience_s`
    /// of mission time held, drive it back along its own path to where it had a fix,
    /// then replan with the time left.
    pub recover: bool,
    pub hold_patience_s: f64,
    /// An estimate whose PEB is at most this is a fix a recovery may go back to: the
    /// controller's guard (`max_peb_m`, 2 m by default), metres.
    pub fix_peb_m: f64,
    /// What a curious plan costs on the mission clock, seconds, fixed (a lock-step sim,
    /// whose clock stands while the planner works: 0); absent: measured, the wall time
    /// recent plans took at the clock's rate.
    pub planning_cost_s: Option<f64>,
    /// The same for a replan seeded with the route the robot drives, fixed; absent:
    /// `planning_cost_s` when that is set, else measured from the seeded replans alone.
    pub replan_cost_s: Option<f64>,
    /// Plan with paper 000 Eq. 2's v_lin and v_ang fitted to what this robot drove
    /// (Table I as the prior; see [`crate::calibration`]); `false`: Table I throughout.
    pub calibrate: bool,
    /// Where the robot's fit is kept across restarts; absent: in memory only.
    pub calibration_file: Option<PathBuf>,
    /// Where the route the robot drives is kept, so that a restarted executive drives
    /// on with it (when it is for the same task and still fits) instead of starting the
    /// window over ([`crate::resume`]); absent: a restart begins the window afresh.
    pub resume_file: Option<PathBuf>,
    /// The time model before anything was driven (the calibration's prior): Table I's
    /// v_lin 2.0 s/m and v_ang 1.0 s/rad by default; a robot's datasheet figures where
    /// they are known. Bounded as the calibration's fits are.
    pub time_model_prior: TimeModel,
    /// The layer of what the fleet believes occupied now (the mapper's `occupied_now`),
    /// followed to replan when a believed obstacle blocks the route ahead
    /// (`window/blocked.rs`): set it where the planners plan around it (their
    /// `obstacles_layer`). `None`: routes are not checked (the stuck rule still acts).
    pub obstacles_layer: Option<String>,
    /// How close a route may pass a believed obstacle, metres: the planners'
    /// `obstacle_inflation_m`, 0.3 by default (0..=[`MAX_OBSTACLE_INFLATION_M`]).
    pub obstacle_inflation_m: f64,
}

pub use roam_planner::seen::MAX_OBSTACLE_INFLATION_M;

impl ExecutiveConfig {
    /// The replan policy's parameters for plans made with `model`.
    pub fn watch_params(&self, model: TimeModel) -> WatchParams {
        let expected = 1.0 / model.v_lin;
        WatchParams {
            off_path_m: self.off_path_m,
            speed_m_per_s: self.speed_m_per_s.min(expected),
            expected_speed_m_per_s: expected,
            max_replans: self.max_replans,
            give_up_after_s: self.give_up_after_s,
            controller_silence_s: self.controller_silence_s,
            slack_s: self.slack_s,
            slack_interval_s: self.slack_interval_s,
            min_replan_window_s: self.min_replan_window_s,
            behind: self.behind,
        }
    }

    /// The arrival margin this config asks for ([`crate::margin`]).
    pub fn margin(&self) -> ArrivalMargin {
        ArrivalMargin::new(
            self.arrival_margin_share,
            self.arrival_margin_min_s,
            self.late_probability,
        )
    }

    /// Plans are curious (the model is not the shortest path).
    pub fn curious(&self) -> bool {
        self.model != PlannerModel::Shortest
    }

    /// The paper's planner alone, as an executive without roam's rules would use it:
    /// paper 000's GA under Model I, Table I's time model throughout, one plan at each
    /// window's start, no slack, no behind rule, no arrival margin, no recovery, no PEB
    /// cost. What the batch calls `plain`.
    pub fn plain(self) -> ExecutiveConfig {
        ExecutiveConfig {
            model: PlannerModel::Model1,
            calibrate: false,
            slack_s: f64::INFINITY,
            behind: false,
            plan_ahead: false,
            set_off_at_once: false,
            arrival_margin_share: 0.0,
            arrival_margin_min_s: 0.0,
            late_probability: 1.0,
            recover: false,
            w_loc: None,
            ..self
        }
    }

    /// The fastest path in every window: the baseline a user would drive without roam.
    pub fn fastest_path_only(self) -> ExecutiveConfig {
        ExecutiveConfig {
            model: PlannerModel::Shortest,
            ..self.plain()
        }
    }

    /// The generations of a replan seeded with the route the robot drives: the fewer of
    /// `replan_generations` and `max_generations` (`None` when neither is set).
    pub fn replan_generations(&self) -> Option<u32> {
        match (self.replan_generations, self.max_generations) {
            (Some(replan), Some(most)) => Some(replan.min(most)),
            (replan, most) => replan.or(most),
        }
    }

    /// Checks every field, naming the first that is out of range.
    pub fn check(&self) -> Result<(), ConfigError> {
        tasks::check(&self.tasks)?;
        keys::check_name("robot", &self.robot).map_err(|e| ConfigError::Field(e.to_string()))?;
        for (name, value) in [
            ("plan_deadline_s", self.plan_deadline_s),
            ("waypoint_spacing_m", self.waypoint_spacing_m),
            ("off_path_m", self.off_path_m),
            ("speed_m_per_s", self.speed_m_per_s),
            ("give_up_after_s", self.give_up_after_s),
            ("controller_silence_s", self.controller_silence_s),
            ("slack_interval_s", self.slack_interval_s),
            ("hold_patience_s", self.hold_patience_s),
            ("fix_peb_m", self.fix_peb_m),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(ConfigError::Field(format!(
                    "{name} is {value}; give a positive number"
                )));
            }
        }
        if !(0.0..0.5).contains(&self.arrival_margin_share) {
            return Err(ConfigError::Field(format!(
                "arrival_margin_share is {}; give a share in 0..0.5 of the time to the task",
                self.arrival_margin_share
            )));
        }
        for (name, value) in [
            ("arrival_margin_min_s", self.arrival_margin_min_s),
            ("min_replan_window_s", self.min_replan_window_s),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(ConfigError::Field(format!(
                    "{name} is {value}; give 0 or more seconds"
                )));
            }
        }
        if !(self.late_probability > 0.0 && self.late_probability <= 1.0) {
            return Err(ConfigError::Field(format!(
                "late_probability is {}; give a probability in (0, 1], e.g. 0.001",
                self.late_probability
            )));
        }
        if !(self.replan_time_share > 0.0 && self.replan_time_share <= 1.0) {
            return Err(ConfigError::Field(format!(
                "replan_time_share is {}; give a share in (0, 1] of the time left",
                self.replan_time_share
            )));
        }
        if let Some(layer) = &self.obstacles_layer {
            keys::check_name("obstacles_layer", layer)
                .map_err(|e| ConfigError::Field(e.to_string()))?;
        }
        if !(0.0..=MAX_OBSTACLE_INFLATION_M).contains(&self.obstacle_inflation_m) {
            return Err(ConfigError::Field(format!(
                "obstacle_inflation_m is {}; give 0..={MAX_OBSTACLE_INFLATION_M} metres",
                self.obstacle_inflation_m
            )));
        }
        if self.replan_generations == Some(0) {
            return Err(ConfigError::Field(
                "replan_generations is 0; give at least 1 (or leave it out: max_generations)"
                    .into(),
            ));
        }
        if let Some(cost) = self.replan_cost_s {
            if !(cost.is_finite() && cost >= 0.0) {
                return Err(ConfigError::Field(format!(
                    "replan_cost_s is {cost}; give 0 or more seconds, or leave it out to measure it"
                )));
            }
        }
        if let Some(cost) = self.planning_cost_s {
            if !(cost.is_finite() && cost >= 0.0) {
                return Err(ConfigError::Field(format!(
                    "planning_cost_s is {cost}; give 0 or more seconds, or leave it out to measure it"
                )));
            }
        }
        if self.slack_s.is_nan() || self.slack_s <= 0.0 {
            return Err(ConfigError::Field(format!(
                "slack_s is {}; give a positive number of seconds (.inf turns the slack rule off)",
                self.slack_s
            )));
        }
        Ok(())
    }
}

impl Default for ExecutiveConfig {
    fn default() -> Self {
        ExecutiveConfig {
            robot: "robot".to_owned(),
            tasks: tasks::builtin(),
            model: PlannerModel::Model1,
            plan_deadline_s: 1.0,
            max_generations: Some(1000),
            replan_generations: Some(DEFAULT_REPLAN_GENERATIONS),
            w_loc: None,
            peb_free_m: None,
            seed: 0,
            waypoint_spacing_m: 1.0,
            off_path_m: 1.5,
            speed_m_per_s: 0.5,
            max_replans: 10,
            give_up_after_s: 60.0,
            controller_silence_s: 3.0,
            slack_s: 3.0,
            slack_interval_s: 5.0,
            min_replan_window_s: 10.0,
            behind: true,
            plan_ahead: true,
            set_off_at_once: true,
            replan_time_share: 0.1,
            arrival_margin_share: 0.05,
            arrival_margin_min_s: 2.0,
            late_probability: 1e-3,
            recover: true,
            hold_patience_s: 4.0,
            fix_peb_m: 2.0,
            planning_cost_s: None,
            replan_cost_s: None,
            calibrate: true,
            calibration_file: None,
            resume_file: None,
            time_model_prior: TimeModel::table_i(),
            obstacles_layer: None,
            obstacle_inflation_m: 0.3,
        }
    }
}

/// Why a configuration is refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ConfigError {
    #[error(transparent)]
    Tasks(#[from] TaskError),
    #[error("invalid config: {0}")]
    Field(String),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_is_valid_and_each_bad_field_is_named() {
        assert_eq!(ExecutiveConfig::default().check(), Ok(()));
        assert_eq!(ExecutiveConfig::default().plain().check(), Ok(()));
        let bad = |c: ExecutiveConfig| c.check().expect_err("refused").to_string();
        let c = ExecutiveConfig::default;
        assert!(bad(ExecutiveConfig {
            late_probability: 0.0,
            ..c()
        })
        .contains("late_probability"));
        assert!(bad(ExecutiveConfig {
            replan_time_share: 2.0,
            ..c()
        })
        .contains("replan_time_share"));
        assert!(bad(ExecutiveConfig {
            hold_patience_s: f64::NAN,
            ..c()
        })
        .contains("hold_patience_s"));
        assert!(bad(ExecutiveConfig {
            min_replan_window_s: -1.0,
            ..c()
        })
        .contains("min_replan_window_s"));
        assert!(bad(ExecutiveConfig {
            obstacle_inflation_m: 9.0,
            ..c()
        })
        .contains("obstacle_inflation_m"));
        assert!(bad(ExecutiveConfig {
            obstacles_layer: Some("occupied/now".into()),
            ..c()
        })
        .contains("obstacles_layer"));
    }
}
