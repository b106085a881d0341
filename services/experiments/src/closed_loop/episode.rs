//! One batch run of the controller in the sim world, without any network: the loop the
//! experiments repeat and that the services reproduce step for step. It is the one
//! closed loop roam has, [`Stepper`], driven to the end ([`run_episode`]).
//!
//! The structure is kept literally like the services' (sim → ranges → localization →
//! controller → commands → sim):
//!
//! 1. `Sim::with_params(scenario, seed)`, a `Tracker` with the scenario's sensing model
//!    and default `FimOptions`, one `Controller` per robot with its mission.
//! 2. `sim.step(&[])`: the first step, without commands.
//! 3. For each robot's report: its messages (`robot_messages`), the estimate from its
//!    range scan (`Tracker::on_scan`, exactly what the localization service publishes),
//!    then the controller's update from the estimate and its PEB
//!    ([`PositionSource::Estimate`]) or from the true position and the PEB there
//!    ([`PositionSource::Truth`], paper 002 ES2's "nominal conditions").
//! 4. The commands of the robots whose mission is Active; `sim.step(&commands)`; back to 3.
//!
//! The run stops when every robot's mission is completed, stuck, at its step limit, or
//! held for its PEB for a whole stuck window (a lost fix that does not come back: a
//! robot at rest stays where its fix was lost), or after `max_steps` + 1 sim steps.
//!
//! The sim runs with the scenario's parameters except the local grid observation, which
//! is turned off: it draws no random numbers and does not move anything (roam-sim draws
//! two transition and one range value per robot per step whatever it observes), so the
//! trajectories are bit for bit those of the sim service with the observation on.

use std::collections::BTreeMap;
use std::path::Path;

use roam_controller::controller::{Decision, MissionState};
use roam_controller::params::ApfParams;
use roam_sim::SimParams;
use roam_world::scenario::Scenario;
use serde::Serialize;

pub use crate::closed_loop::setup::{EpisodeError, PositionSource, Setup};
use crate::closed_loop::stepper::Stepper;

/// The waypoints one robot is to visit, in order.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RobotMission {
    pub robot: String,
    pub waypoints: Vec<[f64; 2]>,
}

/// What one robot did in an episode. The per-step vectors hold one entry per update
/// made while its mission was on (at most `max_steps` + 1).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RobotTrack {
    pub robot: String,
    pub waypoints: Vec<[f64; 2]>,
    /// The mission's status when the episode ended.
    pub status: MissionState,
    /// Every waypoint reached.
    pub success: bool,
    /// Updates of the mission until it ended (the sim step at which it completed, when
    /// it did).
    pub steps: u64,
    /// The length of the true path while the mission was on, metres.
    pub distance_m: f64,
    /// The true position at each update, world metres.
    pub truth: Vec<[f64; 2]>,
    /// The estimate at each update (the prior when degraded), world metres.
    pub estimate: Vec<[f64; 2]>,
    /// ‖p̂ − p‖ at each update, metres.
    pub error_m: Vec<f64>,
    /// Consecutive updates the PEB guard was holding the robot when its mission ended
    /// (0: it was not held). The experiments tell a failure the guard caused (a robot
    /// held until it is given up) from one the robot drove into ([`crate::reproduce::apf::failure`]).
    pub held_updates: u64,
}

impl RobotTrack {
    /// Records one update (the true position, the estimate and the controller's
    /// decision on it) and says whether the robot's part in the episode is over: its
    /// mission ended, it has none, or the PEB guard has held it for
    /// `stuck_window_steps` updates (given up, as a robot that cannot localize is).
    pub(crate) fn record(
        &mut self,
        truth: [f64; 2],
        estimate: [f64; 2],
        decision: &Decision,
        stuck_window_steps: u64,
    ) -> bool {
        if let Some(last) = self.truth.last() {
            self.distance_m += (truth[0] - last[0]).hypot(truth[1] - last[1]);
        }
        self.truth.push(truth);
        self.estimate.push(estimate);
        self.error_m
            .push((estimate[0] - truth[0]).hypot(estimate[1] - truth[1]));
        self.status = decision.status;
        self.steps = decision.steps;
        self.held_updates = decision.halted_updates;
        self.success = decision.status == MissionState::Completed;
        decision.status.is_final()
            || decision.status == MissionState::Idle
            || (decision.status == MissionState::HaltedPeb
                && decision.halted_updates >= stuck_window_steps)
    }
}

/// The result of one episode.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Episode {
    pub seed: u64,
    pub source: PositionSource,
    /// Sim steps taken.
    pub sim_steps: u64,
    /// Scans localization refused (an error, not a missing fix), counted so that none
    /// hides behind a step without an estimate.
    pub localization_errors: u64,
    /// One entry per mission, in the missions' order.
    pub robots: Vec<RobotTrack>,
}

impl Episode {
    /// Every robot reached every waypoint.
    pub fn success(&self) -> bool {
        self.robots.iter().all(|r| r.success)
    }
}

/// Runs `missions` (at most one per robot) from the scenario's start to the end (module
/// doc) with the scenario's sim parameters: a [`Stepper`] driven to the end.
pub fn run_episode(
    setup: &Setup,
    params: &ApfParams,
    source: PositionSource,
    missions: &[RobotMission],
    seed: u64,
) -> Result<Episode, EpisodeError> {
    run_episode_with(setup, setup.sim_params, params, source, missions, seed)
}

/// [`run_episode`] with the sim's parameters `sim_params` (e.g. with its observation
/// on, [`Stepper::observing`]: the tracks do not change).
pub fn run_episode_with(
    setup: &Setup,
    sim_params: SimParams,
    params: &ApfParams,
    source: PositionSource,
    missions: &[RobotMission],
    seed: u64,
) -> Result<Episode, EpisodeError> {
    let mut stepper = Stepper::new(setup, sim_params, params, source, seed)?;
    // Each robot's track, whether it is done, and its mission's rank.
    let mut tracks: BTreeMap<String, (RobotTrack, bool, usize)> = BTreeMap::new();
    for (index, m) in missions.iter().enumerate() {
        stepper.set_mission(&m.robot, m.waypoints.clone())?;
        let done = m.waypoints.is_empty();
        if done {
            stepper.retire(&m.robot);
        }
        let track = RobotTrack {
            robot: m.robot.clone(),
            waypoints: m.waypoints.clone(),
            status: MissionState::Idle,
            success: done,
            steps: 0,
            distance_m: 0.0,
            truth: Vec::new(),
            estimate: Vec::new(),
            error_m: Vec::new(),
            held_updates: 0,
        };
        if tracks
            .insert(m.robot.clone(), (track, done, index))
            .is_some()
        {
            return Err(EpisodeError::DuplicateMission(m.robot.clone()));
        }
    }
    let max_sim_steps = params.max_steps.saturating_add(1);
    loop {
        let out = stepper.step()?;
        for r in &out.robots {
            // A refused scan updates no controller, as the localization service
            // publishes nothing for it.
            let (Some(e), Some(d)) = (&r.estimate, r.decision) else {
                continue;
            };
            let Some((track, done, _)) = tracks.get_mut(&r.robot) else {
                continue;
            };
            *done = track.record(
                r.messages.truth.at,
                e.position,
                &d,
                params.stuck_window_steps,
            );
            if *done {
                stepper.retire(&r.robot);
            }
        }
        if tracks.values().all(|(_, done, _)| *done) || stepper.sim().steps() >= max_sim_steps {
            break;
        }
    }
    let mut robots: Vec<(usize, RobotTrack)> =
        tracks.into_values().map(|(t, _, i)| (i, t)).collect();
    robots.sort_by_key(|(i, _)| *i);
    Ok(Episode {
        seed,
        source,
        sim_steps: stepper.sim().steps(),
        localization_errors: stepper.localization_errors,
        robots: robots.into_iter().map(|(_, t)| t).collect(),
    })
}

/// A robot's mission from a scenario's waypoints: all of them in order, without a first
/// one the robot already stands on (within `g_thres_m`), followed by `and_back` (paper
/// 002 ES2 returns to A).
pub fn mission_from_waypoints(
    setup: &Setup,
    robot: &str,
    g_thres_m: f64,
    and_back: bool,
) -> Result<RobotMission, EpisodeError> {
    let start = setup
        .start_of(robot)
        .ok_or_else(|| EpisodeError::UnknownRobot(robot.to_owned()))?;
    let all: Vec<[f64; 2]> = setup.scenario.file.waypoints.iter().map(|w| w.at).collect();
    let skip = all
        .first()
        .is_some_and(|w| (w[0] - start[0]).hypot(w[1] - start[1]) <= g_thres_m);
    let mut waypoints: Vec<[f64; 2]> = all.iter().skip(usize::from(skip)).copied().collect();
    if and_back {
        if let Some(first) = all.first() {
            waypoints.push(*first);
        }
    }
    Ok(RobotMission {
        robot: robot.to_owned(),
        waypoints,
    })
}

/// Loads a scenario file as the services do (`roam_world::scenario::load_or_builtin`).
pub fn load_scenario(path: &Path) -> Result<Scenario, EpisodeError> {
    Ok(roam_world::scenario::load_or_builtin(Some(path))?.1)
}

/// One ES1 mission in batch (paper 002 §4): the scenario at `path`'s first robot from its
/// start (A) through the scenario's waypoints (B), on estimates, with `params` and
/// `seed`. The integration tests compare the running services with this.
pub fn es1_mission(path: &Path, params: &ApfParams, seed: u64) -> Result<Episode, EpisodeError> {
    let scenario = load_scenario(path)?;
    let setup = Setup::new(&scenario)?;
    let robot = scenario
        .file
        .robots
        .first()
        .ok_or_else(|| EpisodeError::NoRobot(path.display().to_string()))?;
    let mission = mission_from_waypoints(&setup, &robot.name, params.g_thres_m, false)?;
    run_episode(&setup, params, PositionSource::Estimate, &[mission], seed)
}
