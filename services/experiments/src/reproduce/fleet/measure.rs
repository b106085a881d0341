//! What the fleet's week is measured by: each window (late, the share driven, the
//! information driven), the map error every sim minute, every change event, the plans.

use std::collections::BTreeMap;

use roam_controller::controller::{Decision, MissionState};
use roam_mapper::brier::brier;
use roam_mission::information::gathered;
use roam_proto::mission::WindowReport;
use serde::Serialize;

use crate::reproduce::executive::track::Track;
use crate::reproduce::executive::FinishedWindow;

use super::error::FleetError;
use super::events::{ChangeEvent, ChangeLog};
use super::variant::FleetVariant;
use super::world::FleetWorld;

/// One robot's window.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WindowRecord {
    pub robot: usize,
    /// The shift (day) its task is in, from 0.
    pub day: usize,
    pub task: String,
    pub window_s: f64,
    pub late: bool,
    /// From the first mission to the arrival over the window's length.
    pub share: f64,
    /// Paper 000's measure on the static map along the true driven path.
    pub driven_information: f64,
    pub ga_plans: u32,
    /// Plans the planner refused in the window (`None`: a live window, whose report
    /// does not say).
    pub refused_plans: Option<u32>,
    /// The same refusals by kind (`roam_planner::plan::PlanError::kind`; empty live).
    pub refusals: BTreeMap<&'static str, u32>,
}

impl WindowRecord {
    pub fn of(world: &FleetWorld, robot: usize, shift_s: f64, w: FinishedWindow) -> WindowRecord {
        let report = &w.outcome.report;
        let window_s = w.task.start_s - w.began_s;
        let sent = w.log.first_sent_at_s.unwrap_or(w.began_s);
        let driving_s = report.arrival_s.map_or(0.0, |a| a - sent);
        let track: &Track = &w.log.track;
        WindowRecord {
            robot,
            day: (w.task.start_s / shift_s).floor().max(0.0) as usize,
            task: w.task.name.clone(),
            window_s,
            late: report.arrival_s.is_none_or(|a| a > w.task.start_s),
            share: if window_s > 0.0 {
                driving_s / window_s
            } else {
                0.0
            },
            driven_information: track.information(&world.planning, &world.params),
            ga_plans: w.log.ga_plans,
            refused_plans: Some(w.log.refused_plans),
            refusals: w.log.refusals.clone(),
        }
    }
}

impl WindowRecord {
    /// A window a live executive reported (`roam demo --fleet`): `truth` the robot's
    /// true positions through the window. The share is counted from the window's
    /// beginning to the arrival (the live report does not say when the first mission
    /// left; the batch counts from it, which differs by the first plan's time).
    pub fn live(
        world: &FleetWorld,
        robot: usize,
        shift_s: f64,
        report: &WindowReport,
        truth: &[[f64; 2]],
    ) -> WindowRecord {
        let window_s = report.task_start_s - report.began_s;
        let driving_s = report.arrival_s.map_or(0.0, |a| a - report.began_s);
        WindowRecord {
            robot,
            day: (report.task_start_s / shift_s).floor().max(0.0) as usize,
            task: report.task.clone(),
            window_s,
            late: !report.on_time,
            share: if window_s > 0.0 {
                driving_s / window_s
            } else {
                0.0
            },
            driven_information: gathered(&world.planning, &world.params, truth),
            ga_plans: report.asks.iter().filter(|a| a.curious).count() as u32,
            refused_plans: None,
            refusals: BTreeMap::new(),
        }
    }
}

/// The fleet's map against the world, at one time.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MapSample {
    pub t_s: f64,
    /// The Brier score of P(occupied now) over the cells objects can cover, over the
    /// sample of the others, and over both.
    pub zones: f64,
    pub others: f64,
    pub all: f64,
    /// The same score of the static map alone (occupied where the scenario's map is,
    /// free elsewhere: a map that knows no change) over all the scored cells: the
    /// reference the fleet's belief must beat, and what the world's own churn costs a
    /// map that never looks (it moves with how many objects are out, not with the
    /// fleet).
    pub static_map: f64,
}

impl MapSample {
    /// The belief (per coarse cell) scored against the truth (occupied or not, per
    /// coarse cell: [`FleetWorld::semi_static_truth`]) over the world's scored cells,
    /// beside the static map's score.
    pub fn score(
        world: &FleetWorld,
        t_s: f64,
        belief: &[f64],
        truth: &[bool],
    ) -> Result<MapSample, FleetError> {
        let score = |cells: &[usize]| {
            brier(belief, truth, cells.iter().copied())
                .map_err(|e| FleetError::Mapper(e.to_string()))
        };
        let (zones, others) = world.scored.split_at(world.zone_cells);
        Ok(MapSample {
            t_s,
            zones: score(zones)?,
            others: score(others)?,
            all: score(&world.scored)?,
            // The static map's occupancy values are its beliefs (0 free, 100 occupied).
            static_map: brier(
                &world.static_coarse.cells,
                truth,
                world.scored.iter().copied(),
            )
            .map_err(|e| FleetError::Mapper(e.to_string()))?,
        })
    }
}

/// The picture's paths keep one step in this many.
pub const PATH_EVERY_STEPS: u64 = 5;

/// Everything one variant's week recorded.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WeekRecord {
    pub variant: FleetVariant,
    pub robots: usize,
    pub windows: Vec<WindowRecord>,
    pub maps: Vec<MapSample>,
    pub events: Vec<ChangeEvent>,
    /// Each curious plan's computing time, seconds (wall, this machine).
    pub plan_latencies_s: Vec<f64>,
    /// Steps a robot's controller held it for its PEB, per robot.
    pub halted_steps: Vec<u64>,
    /// Scans localization refused (the batch stepper's count; `None` live, where the
    /// localization service logs them) and the first one's message.
    pub localization_errors: Option<u64>,
    pub first_localization_error: Option<String>,
    /// Each robot's true path through the first shift, every [`PATH_EVERY_STEPS`]th
    /// step: for the picture, not the report (at most a shift's steps per robot).
    #[serde(skip)]
    pub paths: Vec<Vec<[f64; 2]>>,
    /// The sim time the week ended at, and the wall seconds it took.
    pub end_s: f64,
    pub wall_s: f64,
}

impl WeekRecord {
    pub fn new(variant: FleetVariant, robots: usize) -> WeekRecord {
        WeekRecord {
            variant,
            robots,
            windows: Vec::new(),
            maps: Vec::new(),
            events: Vec::new(),
            plan_latencies_s: Vec::new(),
            halted_steps: vec![0; robots],
            localization_errors: None,
            first_localization_error: None,
            paths: vec![Vec::new(); robots],
            end_s: 0.0,
            wall_s: 0.0,
        }
    }

    /// Robot `robot`'s controller decided `decision` this step.
    pub fn robot_step(&mut self, robot: usize, decision: Option<&Decision>) {
        if decision.is_some_and(|d| d.status == MissionState::HaltedPeb) {
            if let Some(h) = self.halted_steps.get_mut(robot) {
                *h += 1;
            }
        }
    }

    pub fn finish(&mut self, changes: ChangeLog, end_s: f64, wall_s: f64) {
        self.events = changes.events().to_vec();
        self.end_s = end_s;
        self.wall_s = wall_s;
    }
}
