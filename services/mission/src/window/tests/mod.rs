//! Each rule of the window, event by event: a 4 m square world of 0.2 m cells, a task
//! 3 m east of the robot at 100 s, the next one 3 m north of the robot at 200 s.

use super::*;
use crate::calibration::{path_measure, TimeModel};
use crate::information::InformationScale;
use crate::margin::ArrivalMargin;
use crate::tasks::Task;
use crate::watch::WatchParams;
use roam_planner::params::GaParams;
use roam_planner::world::World;
use roam_proto::controller::{ControllerStatus, Mission, MissionState};
use roam_proto::map::{GridMeta, Origin};
use roam_proto::mission::WindowReport;
use roam_proto::planner::{FitnessTerms, MapVersion, Plan, PlannerModel, ShortestPath, StopReason};
use roam_world::grid::Grid;

const FROM: [f64; 2] = [0.1, 0.1];
const GOAL: [f64; 2] = [3.1, 0.1];
const NEXT: [f64; 2] = [0.1, 3.1];
const CURIOUS_ETA_S: f64 = 40.0;
const SHORTEST_ETA_S: f64 = 6.0;

struct Fixture {
    world: World,
    params: GaParams,
}

fn fixture() -> Fixture {
    let meta = GridMeta {
        width: 20,
        height: 20,
        resolution: 0.2,
        origin: Origin::default(),
    };
    // Information that differs cell by cell, so that paths differ in what they see.
    let mut information = Grid::filled(meta, 0u8);
    for (i, cell) in information.cells.iter_mut().enumerate() {
        *cell = (i % 7 * 10) as u8;
    }
    Fixture {
        world: World::new(&Grid::filled(meta, 0i8), &information, 0.25).expect("world"),
        params: GaParams::default(),
    }
}

fn task(name: &str, at: [f64; 2], start_s: f64) -> Task {
    Task {
        name: name.into(),
        at,
        start_s,
        duration_s: 5.0,
    }
}

fn margin() -> ArrivalMargin {
    ArrivalMargin::new(0.05, 2.0, 1e-3)
}

fn watch_params() -> WatchParams {
    WatchParams {
        off_path_m: 0.5,
        speed_m_per_s: 0.5,
        expected_speed_m_per_s: 0.5,
        max_replans: 3,
        give_up_after_s: 60.0,
        controller_silence_s: 3.0,
        slack_s: 10.0,
        slack_interval_s: 5.0,
        min_replan_window_s: 0.0,
        behind: true,
    }
}

fn rules() -> WindowRules {
    WindowRules {
        set_off_at_once: false,
        curious: true,
        plan_ahead: false,
        recover: true,
        hold_patience_s: 4.0,
        fix_peb_m: 2.0,
        replan_time_share: 1.0,
        plan_deadline_s: 1.0,
    }
}

impl Fixture {
    fn scale(&self) -> InformationScale<'_> {
        InformationScale {
            world: &self.world,
            params: &self.params,
        }
    }

    fn setup(&self, window: usize, from: [f64; 2], next: bool) -> WindowSetup<'_> {
        let (task, next) = match window {
            0 => (
                task("goal1", GOAL, 100.0),
                next.then(|| task("goal2", NEXT, 200.0)),
            ),
            _ => (task("goal2", NEXT, 200.0), None),
        };
        WindowSetup {
            window,
            task,
            next,
            robot: "robot".into(),
            mission_tag: "tag".into(),
            from,
            time_model: TimeModel::table_i(),
            watch: watch_params(),
            rules: rules(),
            give_up_after_s: 60.0,
            waypoint_spacing_m: 1.0,
            scale: self.scale(),
        }
    }

    /// The first window, begun at 0 s.
    fn begin(&self, next: bool) -> (DowntimeWindow<'_>, Vec<WindowAction>) {
        DowntimeWindow::begin(
            self.setup(0, FROM, next),
            Handover::first(margin()),
            at(0.0, 0.0),
        )
    }

    /// The first window with its curious plan sent at 1 s (wall 0 s).
    fn driving(&self, next: bool) -> (DowntimeWindow<'_>, Mission) {
        let (mut w, _) = self.begin(next);
        let actions = answer(&mut w, curious_reply(true), at(1.0, 0.0));
        (w, sent(&actions))
    }
}

/// Mission time `mission_s`, wall time `wall_s`, a plan (and a seeded replan) costing
/// 1 s.
fn at(mission_s: f64, wall_s: f64) -> Now {
    Now {
        mission_s,
        wall_s,
        planning_cost_s: 1.0,
        replan_cost_s: 1.0,
        clock_rate: 1.0,
    }
}

/// A reply; [`answer`] gives it the id of the request in flight.
fn reply(plan: Plan) -> WindowEvent {
    WindowEvent::PlanReply {
        id: 0,
        plan: Box::new(plan),
    }
}

/// A failure; [`answer`] gives it the id of the request in flight.
fn failed() -> WindowEvent {
    WindowEvent::PlanFailed { id: 0 }
}

/// `event` as the answer to the request in flight (the drive's, else the next
/// window's).
fn answer(w: &mut DowntimeWindow<'_>, event: WindowEvent, now: Now) -> Vec<WindowAction> {
    let id = w
        .drive_ask
        .as_ref()
        .map(|(id, _)| *id)
        .or(w.ahead_ask.map(|(id, _)| id))
        .expect("a request in flight");
    let event = match event {
        WindowEvent::PlanReply { plan, .. } => WindowEvent::PlanReply { id, plan },
        WindowEvent::PlanFailed { .. } => WindowEvent::PlanFailed { id },
        other => other,
    };
    w.handle(event, now)
}

/// Cell centres from `a` to `b` along x or y, 0.2 m apart, both ends included.
fn line(a: [f64; 2], b: [f64; 2]) -> Vec<[f64; 2]> {
    let n = ((b[0] - a[0]).abs().max((b[1] - a[1]).abs()) / 0.2).round() as usize;
    (0..=n)
        .map(|k| {
            let t = k as f64 / n.max(1) as f64;
            [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
        })
        .collect()
}

fn joined(legs: &[Vec<[f64; 2]>]) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = Vec::new();
    for leg in legs {
        let skip = usize::from(!out.is_empty());
        out.extend(leg.iter().skip(skip));
    }
    out
}

/// The curious route: north 1 m, east 3 m, south to the task.
fn curious_points() -> Vec<[f64; 2]> {
    joined(&[
        line(FROM, [0.1, 1.1]),
        line([0.1, 1.1], [3.1, 1.1]),
        line([3.1, 1.1], GOAL),
    ])
}

fn shortest_points(from: [f64; 2]) -> Vec<[f64; 2]> {
    line(from, [GOAL[0], from[1]])
}

fn plan(model: PlannerModel, points: Vec<[f64; 2]>, t_eta_s: f64) -> Plan {
    Plan {
        request_id: "r".into(),
        model,
        cells: points
            .iter()
            .map(|p| [(p[0] / 0.2) as u32, (p[1] / 0.2) as u32])
            .collect(),
        points,
        t_eta_s,
        reaches_goal: true,
        within_budget: true,
        fitness: FitnessTerms::default(),
        u_ges: 0.0,
        density: 0.0,
        distinct_information: 0.0,
        generations: 10,
        planning_ms: 1.0,
        stop_reason: StopReason::MaxGenerations,
        planning_resolution_m: None,
        cpu_grant_s: None,
        seed: 0,
        map_version: MapVersion {
            inflated: 1,
            information: 1,
            change: None,
            obstacles: None,
        },
        instance: "planner".into(),
        shortest: None,
        found_by: None,
        seed_route_used: None,
    }
}

fn attached(points: Vec<[f64; 2]>) -> Option<ShortestPath> {
    Some(ShortestPath {
        cells: Vec::new(),
        points,
        t_eta_s: SHORTEST_ETA_S,
        distinct_information: 0.0,
    })
}

/// A curious plan with the shortest path attached, within its budget or not.
fn curious_reply(within_budget: bool) -> WindowEvent {
    reply(Plan {
        within_budget,
        shortest: attached(shortest_points(FROM)),
        ..plan(PlannerModel::Model1, curious_points(), CURIOUS_ETA_S)
    })
}

/// The shortest path from `from`, as the planner answers `model: shortest` (or the
/// fallback).
fn shortest_reply(from: [f64; 2]) -> WindowEvent {
    let points = shortest_points(from);
    reply(Plan {
        within_budget: false,
        stop_reason: StopReason::Complete,
        shortest: attached(points.clone()),
        ..plan(PlannerModel::Shortest, points, SHORTEST_ETA_S)
    })
}

/// An estimate made at `time_s`.
fn estimate(position: [f64; 2], peb_m: f64, time_s: f64) -> WindowEvent {
    WindowEvent::Estimate {
        position,
        peb_m: Some(peb_m),
        degraded: false,
        time_s,
    }
}

fn status(mission: &str, state: MissionState, distance_left_m: f64) -> WindowEvent {
    WindowEvent::Status(ControllerStatus {
        robot: "robot".into(),
        mission: Some(mission.into()),
        state,
        waypoint: Some(0),
        waypoints: 1,
        distance_left_m: Some(distance_left_m),
        steps: 1,
        estimate_step: Some(1),
        peb_m: None,
        omega_deg: 0.0,
        z_isa: 0.0,
        u: [0.0, 0.0],
    })
}

/// The one request among `actions`.
fn asked(actions: &[WindowAction]) -> PlanAsk {
    let asks: Vec<PlanAsk> = actions
        .iter()
        .filter_map(|a| match a {
            WindowAction::RequestPlan(ask) => Some(ask.clone()),
            _ => None,
        })
        .collect();
    assert_eq!(asks.len(), 1, "{actions:?}");
    asks[0].clone()
}

/// The one mission sent to drive among `actions`.
fn sent(actions: &[WindowAction]) -> Mission {
    let missions: Vec<&Mission> = actions
        .iter()
        .filter_map(|a| match a {
            WindowAction::Drive(m) => Some(m),
            _ => None,
        })
        .collect();
    assert_eq!(missions.len(), 1, "{actions:?}");
    missions[0].clone()
}

/// How the window ended, from the last of `actions`.
fn ended(actions: &[WindowAction]) -> WindowEnd {
    match actions.last() {
        Some(WindowAction::Done(end)) => (**end).clone(),
        _ => panic!("not done: {actions:?}"),
    }
}

fn report(actions: &[WindowAction]) -> WindowReport {
    ended(actions).outcome.expect("an outcome").report
}

/// The controller's status `state` on `mission`.
fn answer_status(
    w: &mut DowntimeWindow<'_>,
    mission: &Mission,
    state: MissionState,
    now: Now,
) -> Vec<WindowAction> {
    w.handle(status(&mission.id, state, 0.0), now)
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

mod late_held_ahead;
mod lifecycle;
mod map_changed;
mod next_window;
mod replans;
mod resume;
mod set_off;
