//! What the controller's subscribers and watchdog share: the fields it steers by, the
//! robots under control, and the tables of robots seen and missions waiting.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use roam_proto::controller::{ControllerStatus, Mission};
use roam_proto::sim::RobotCommand;
use roam_proto::{keys, Message};
use roam_runtime::warn_limit::WarnLimiter;
use roam_runtime::Delivery;

use crate::controller::Controller;
use crate::information::InformationField;
use crate::obstacle_field::ObstacleField;
use crate::params::ApfParams;

/// Robots one controller instance drives at most.
pub const MAX_ROBOTS: usize = 1000;
/// Missions held for robots not yet heard of (see `ControllerShared::hold`).
pub const MAX_HELD_MISSIONS: usize = 64;

/// One robot under control.
pub(super) struct ControlledRobot {
    pub(super) controller: Controller,
    pub(super) mission: String,
    pub(super) waypoints: usize,
    pub(super) last_estimate: Instant,
    pub(super) stale: bool,
    pub(super) last: Option<ControllerStatus>,
}

/// What the controller's subscribers share: the session, the fields the controllers
/// steer by, and the robots under control.
pub(super) struct ControllerShared {
    pub(super) root: String,
    pub(super) session: zenoh::Session,
    pub(super) params: ApfParams,
    pub(super) obstacles: Arc<ObstacleField>,
    pub(super) information: Arc<InformationField>,
    pub(super) stale_after: Duration,
    pub(super) release_after: Duration,
    /// The robots this instance may drive; empty: any.
    pub(super) allowed: Vec<String>,
    pub(super) robots: Mutex<HashMap<String, ControlledRobot>>,
    /// The robots the scenario has: a mission for one is taken at once.
    pub(super) scenario_robots: Vec<String>,
    /// When each robot's last estimate came (robots without a mission too), at most
    /// [`MAX_ROBOTS`]: with the scenario's robots, what "a robot the world has" means
    /// to the controller.
    pub(super) seen: Mutex<HashMap<String, Instant>>,
    /// The step of each robot's last estimate answered, kept with `seen`.
    pub(super) answered: Mutex<HashMap<String, u64>>,
    /// Missions decided on an estimate this controller has not answered yet
    /// ([`Mission::after_step`]), one per robot (the latest), for robots the world has:
    /// each starts once that estimate is answered.
    pub(super) queued: Mutex<HashMap<String, Mission>>,
    /// Missions for robots not yet heard of, waiting for their first estimate: at most
    /// [`MAX_HELD_MISSIONS`], the oldest dropped first, each for `release_after`.
    pub(super) held: Mutex<HashMap<String, (Instant, Mission)>>,
    /// Refused missions and estimates, logged a few per key and window.
    pub(super) warnings: WarnLimiter,
}

impl ControllerShared {
    pub(super) fn robots(&self) -> MutexGuard<'_, HashMap<String, ControlledRobot>> {
        roam_runtime::lock(&self.robots)
    }

    pub(super) fn seen(&self) -> MutexGuard<'_, HashMap<String, Instant>> {
        roam_runtime::lock(&self.seen)
    }

    /// Notes an estimate of `robot`; when [`MAX_ROBOTS`] robots are noted, the one
    /// heard from longest ago makes room.
    pub(super) fn note_seen(&self, robot: &str) {
        let mut seen = self.seen();
        if !seen.contains_key(robot) && seen.len() >= MAX_ROBOTS {
            if let Some(oldest) = seen.iter().min_by_key(|(_, t)| **t).map(|(r, _)| r.clone()) {
                seen.remove(&oldest);
            }
        }
        seen.insert(robot.to_owned(), Instant::now());
    }

    /// Whether `mission` waits for an estimate `robot`'s controller has not answered.
    pub(super) fn waits(&self, robot: &str, mission: &Mission) -> bool {
        let Some(after) = mission.after_step else {
            return false;
        };
        roam_runtime::lock(&self.answered)
            .get(robot)
            .is_none_or(|answered| *answered < after)
    }

    /// The mission queued for `robot` if it may start before (`before: true`) or after
    /// answering the estimate of `step`.
    pub(super) fn take_queued(&self, robot: &str, step: u64, before: bool) -> Option<Mission> {
        let mut queued = roam_runtime::lock(&self.queued);
        let after = queued.get(robot)?.after_step.unwrap_or(0);
        let due = if before { after < step } else { after <= step };
        if due {
            queued.remove(robot)
        } else {
            None
        }
    }

    /// Holds a mission until the robot's first estimate.
    pub(super) fn hold(&self, robot: &str, mission: Mission) {
        let mut held = roam_runtime::lock(&self.held);
        if !held.contains_key(robot) && held.len() >= MAX_HELD_MISSIONS {
            if let Some(oldest) = held
                .iter()
                .min_by_key(|(_, (t, _))| *t)
                .map(|(r, _)| r.clone())
            {
                held.remove(&oldest);
            }
        }
        held.insert(robot.to_owned(), (Instant::now(), mission));
    }

    /// The mission held for `robot`, if one is and it has not expired.
    pub(super) fn take_held(&self, robot: &str) -> Option<Mission> {
        let mut held = roam_runtime::lock(&self.held);
        let (at, mission) = held.remove(robot)?;
        (at.elapsed() < self.release_after).then_some(mission)
    }

    /// Whether the world has `robot`: the scenario names it, or localization reported
    /// it within `release_after`.
    pub(super) fn is_present(&self, robot: &str) -> bool {
        self.scenario_robots.iter().any(|r| r == robot)
            || self
                .seen()
                .get(robot)
                .is_some_and(|t| t.elapsed() < self.release_after)
    }

    /// Commands, goals and statuses are state a robot must not miss: delivered.
    pub(super) fn put<T: Message>(&self, key: &str, message: &T) {
        roam_runtime::publish_wait(&self.session, key, message, Delivery::Reliable);
    }

    pub(super) fn command(&self, robot: &str, u: [f64; 2], step: Option<u64>) {
        self.put(
            &keys::robot_command(&self.root, robot),
            &RobotCommand { u, step },
        );
    }
}
