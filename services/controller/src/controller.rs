//! The per-robot controller: a mission of waypoints, one command per position update
//! (paper 002 Eq. 3), and the mission's status. The Zenoh service and the batch episodes
//! run this same state machine.
//!
//! ```text
//!            set_mission(non-empty)
//!   Idle ─────────────────────────────► Active ◄──────► HaltedPeb   (PEB bad / good again)
//!    ▲                                    │
//!    │ set_mission(empty)                 ├── last waypoint reached ──► Completed
//!    │                                    ├── no progress over window ─► Stuck
//!    └──────── (from any status) ◄────────┴── max_steps updates ──────► StepLimit
//! ```
//!
//! Completed, Stuck and StepLimit are final: the robot gets zero commands until a new
//! mission arrives. HaltedPeb is not: the robot is held while its PEB is above
//! `max_peb_m` (or unbounded) and resumes when it is good again.
//!
//! What f_a pulls toward is the parameter `follow` ([`Follow`]): the current waypoint
//! (paper 002), or the carrot of pure pursuit on the mission's path ([`crate::carrot`]),
//! the polyline from where the robot was at the mission's first driven update through
//! every waypoint. Either way f_Tr and f_is act and z_isa(ω) adapts (Eqs. 2–3), and
//! progress for the stuck rule is the distance left: to the current waypoint (the
//! record restarts at each waypoint), or along the path.

use std::sync::Arc;

/// Where a mission stands: the wire's own state, so the controller, its status message
/// and the executive say it in one vocabulary.
pub use roam_proto::controller::MissionState;
use serde::Serialize;

use crate::carrot::PathTracker;
use crate::forces::{command, Forces};
use crate::information::InformationField;
use crate::obstacle_field::ObstacleField;
use crate::params::{ApfParams, Follow};

/// What the controller decided on one update.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Decision {
    /// The command u of paper 002 Eq. 3; zero unless `status` is Active.
    pub u: [f64; 2],
    pub status: MissionState,
    /// Index of the current waypoint (under `follow: path`, the first one ahead of the
    /// robot's projection onto the path); `None` when idle or completed.
    pub waypoint: Option<usize>,
    /// From the position to the current waypoint plus the remaining legs (under
    /// `follow: path`, to the projection plus the rest of the path), metres; 0 when
    /// completed or idle.
    pub distance_left_m: f64,
    /// Updates since the mission began (this one included).
    pub steps: u64,
    /// ω between f_a and f_is, degrees (0 when no force was evaluated).
    pub omega_deg: f64,
    /// z_isa(ω) used (0 when no force was evaluated).
    pub z_isa: f64,
    /// Consecutive updates held for the PEB, this one included (0 unless HaltedPeb).
    pub halted_updates: u64,
}

/// The controller of one robot.
#[derive(Debug, Clone)]
pub struct Controller {
    params: ApfParams,
    obstacles: Arc<ObstacleField>,
    information: Arc<InformationField>,
    waypoints: Vec<[f64; 2]>,
    /// Index of the current waypoint (== len when completed).
    current: usize,
    status: MissionState,
    steps: u64,
    /// Updates that were not held for the PEB (the stuck window counts these).
    active_steps: u64,
    halted_updates: u64,
    /// The best distance to the current waypoint at the last sign of progress, and
    /// `active_steps` then.
    checkpoint: Option<(f64, u64)>,
    /// Metres of the legs after the current waypoint.
    legs_after: Vec<f64>,
    /// Under `follow: path`: the path being followed, from the mission's first driven
    /// update on (`None` before it).
    path: Option<PathTracker>,
    /// Under `follow: path`: the mission's index of each path point after the first
    /// (the robot's start), for [`Decision::waypoint`].
    path_waypoints: Vec<usize>,
    /// The mission is a recovery: the PEB guard does not hold it.
    recovery: bool,
}

impl Controller {
    /// An idle controller. `params` should have passed [`ApfParams::check`].
    pub fn new(
        params: ApfParams,
        obstacles: Arc<ObstacleField>,
        information: Arc<InformationField>,
    ) -> Controller {
        Controller {
            params,
            obstacles,
            information,
            waypoints: Vec::new(),
            current: 0,
            status: MissionState::Idle,
            steps: 0,
            active_steps: 0,
            halted_updates: 0,
            checkpoint: None,
            legs_after: Vec::new(),
            path: None,
            path_waypoints: Vec::new(),
            recovery: false,
        }
    }

    /// Replaces the mission, at any time: the robot heads for the first waypoint (under
    /// `follow: path`, along the path from where it is at the next driven update), with
    /// the step count and the progress record reset. An empty mission makes it idle.
    pub fn set_mission(&mut self, waypoints: Vec<[f64; 2]>) {
        // legs_after[i]: the length of the route from waypoint i to the last one.
        let mut legs_after = vec![0.0; waypoints.len()];
        for i in (0..waypoints.len().saturating_sub(1)).rev() {
            let (a, b) = (waypoints[i], waypoints[i + 1]);
            legs_after[i] = legs_after[i + 1] + (b[0] - a[0]).hypot(b[1] - a[1]);
        }
        self.status = if waypoints.is_empty() {
            MissionState::Idle
        } else {
            MissionState::Active
        };
        self.waypoints = waypoints;
        self.legs_after = legs_after;
        self.current = 0;
        self.steps = 0;
        self.active_steps = 0;
        self.halted_updates = 0;
        self.checkpoint = None;
        self.path = None;
        self.path_waypoints.clear();
        self.recovery = false;
    }

    /// A recovery mission ([`roam_proto::controller::Mission::recovery`]): as
    /// [`Controller::set_mission`], but the PEB guard does not hold the robot on it, so
    /// that a robot held where it has no fix can drive back to where it had one.
    pub fn set_recovery(&mut self, waypoints: Vec<[f64; 2]>) {
        self.set_mission(waypoints);
        self.recovery = true;
    }

    /// Ends the mission as if emptied: zero commands, status Idle.
    pub fn end_mission(&mut self) {
        self.set_mission(Vec::new());
    }

    /// The mission's status after the last update.
    pub fn status(&self) -> MissionState {
        self.status
    }

    /// Whether the robot still has a mission to drive (Active or HaltedPeb).
    pub fn is_active(&self) -> bool {
        matches!(self.status, MissionState::Active | MissionState::HaltedPeb)
    }

    pub fn params(&self) -> &ApfParams {
        &self.params
    }

    /// The mission's waypoints.
    pub fn waypoints(&self) -> &[[f64; 2]] {
        &self.waypoints
    }

    /// Updates since the mission began.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    fn distance_left(&self, p: [f64; 2]) -> f64 {
        match (self.waypoints.get(self.current), &self.path) {
            (None, _) => 0.0,
            (Some(_), Some(path)) => path.distance_left_m(p),
            (Some(w), None) => (w[0] - p[0]).hypot(w[1] - p[1]) + self.legs_after[self.current],
        }
    }

    fn decision(&self, p: [f64; 2], forces: Option<&Forces>) -> Decision {
        let active = self.status == MissionState::Active;
        Decision {
            u: match forces {
                Some(f) if active => f.u,
                _ => [0.0, 0.0],
            },
            status: self.status,
            waypoint: (self.current < self.waypoints.len()).then_some(self.current),
            distance_left_m: self.distance_left(p),
            steps: self.steps,
            omega_deg: forces.map_or(0.0, |f| f.omega_deg),
            z_isa: forces.map_or(0.0, |f| f.z_isa),
            halted_updates: self.halted_updates,
        }
    }

    /// One update from the robot's position (its estimate, or the truth in paper 002's
    /// "nominal conditions") and the PEB the localization service gives with it (`None`:
    /// unbounded, the fix is lost; it counts as +∞, so `max_peb_m = ∞` turns the guard
    /// off entirely).
    ///
    /// In order: a final or idle mission gives a zero command and changes nothing; the
    /// step count rises; after `max_steps` updates the mission ends (StepLimit); a PEB
    /// above `max_peb_m` or unbounded holds the robot (HaltedPeb); then, by `follow`,
    /// waypoints within g_thres of `position` are passed (the next one becomes current
    /// in this same update; after the last, Completed) or the robot is projected onto
    /// the path (the carrot at its end and the robot within g_thres of it: Completed);
    /// no progress over the stuck window ends it (Stuck); otherwise the command is Eq. 3
    /// toward the current waypoint or the carrot, with the IS force evaluated at
    /// `position`.
    pub fn update(&mut self, position: [f64; 2], peb_m: Option<f64>) -> Decision {
        if self.status.is_final() || self.status == MissionState::Idle {
            return self.decision(position, None);
        }
        if self.steps >= self.params.max_steps {
            self.status = MissionState::StepLimit;
            return self.decision(position, None);
        }
        self.steps += 1;
        let finite = position[0].is_finite() && position[1].is_finite();
        // An unbounded PEB (`None`, or NaN) counts as +∞: held unless the guard is off.
        let peb = peb_m.filter(|p| !p.is_nan()).unwrap_or(f64::INFINITY);
        if !(finite && (self.recovery || peb <= self.params.max_peb_m)) {
            self.status = MissionState::HaltedPeb;
            self.halted_updates += 1;
            return self.decision(position, None);
        }
        self.status = MissionState::Active;
        self.halted_updates = 0;
        self.active_steps += 1;
        match self.params.follow {
            Follow::Waypoints => self.toward_waypoint(position),
            Follow::Path => self.along_path(position),
        }
    }

    /// `follow: waypoints` (paper 002): waypoints within g_thres of `position` (or
    /// `via_thres_m`, but the last) are passed, the next one becoming current in this
    /// same update (after the last, Completed); no progress toward the current one over
    /// the stuck window ends the mission (Stuck); otherwise Eq. 3 toward it.
    fn toward_waypoint(&mut self, position: [f64; 2]) -> Decision {
        while let Some(&w) = self.waypoints.get(self.current) {
            let last = self.current + 1 == self.waypoints.len();
            let reach = match self.params.via_thres_m {
                Some(via) if !last => via,
                _ => self.params.g_thres_m,
            };
            if (w[0] - position[0]).hypot(w[1] - position[1]) > reach {
                break;
            }
            self.current += 1;
            self.checkpoint = None;
        }
        let Some(&waypoint) = self.waypoints.get(self.current) else {
            self.status = MissionState::Completed;
            return self.decision(position, None);
        };
        let distance = (waypoint[0] - position[0]).hypot(waypoint[1] - position[1]);
        if self.no_progress(distance) {
            self.status = MissionState::Stuck;
            return self.decision(position, None);
        }
        let forces = command(
            &self.params,
            &self.obstacles,
            &self.information,
            position,
            waypoint,
        );
        self.decision(position, Some(&forces))
    }

    /// `follow: path` ([`crate::carrot`]): the path is the polyline from `position` at
    /// the mission's first driven update through the waypoints (one that is not a
    /// finite point is left out, as `waypoints` passes it at once). The robot is
    /// projected onto it, forward only; with the carrot at the last point and the robot
    /// within g_thres of it, Completed; no progress along the path over the stuck
    /// window, Stuck; otherwise Eq. 3 with f_a toward the carrot.
    fn along_path(&mut self, position: [f64; 2]) -> Decision {
        if self.path.is_none() {
            let (indices, points): (Vec<usize>, Vec<[f64; 2]>) = self
                .waypoints
                .iter()
                .enumerate()
                .filter(|(_, w)| w[0].is_finite() && w[1].is_finite())
                .map(|(i, &w)| (i, w))
                .unzip();
            if points.is_empty() {
                // Nothing to drive to: as `waypoints` passes every such waypoint.
                self.current = self.waypoints.len();
                self.status = MissionState::Completed;
                return self.decision(position, None);
            }
            // `position` is finite here (`update` holds a robot that is not), and so is
            // every point: the tracker cannot refuse the path.
            match PathTracker::new(std::iter::once(position).chain(points).collect()) {
                Ok(path) => self.path = Some(path),
                Err(e) => {
                    tracing::warn!("the mission's path cannot be followed: {e}");
                    self.end_mission();
                    return self.decision(position, None);
                }
            }
            self.path_waypoints = indices;
        }
        let (lookahead, window) = (self.params.lookahead_m, self.params.window_m());
        let Some(path) = self.path.as_mut() else {
            return self.decision(position, None);
        };
        let pursuit = path.pursue(position, lookahead, window);
        let Some(&end) = path.points().last() else {
            return self.decision(position, None);
        };
        // Path point k ≥ 1 is mission waypoint path_waypoints[k − 1].
        self.current = pursuit
            .next_point
            .checked_sub(1)
            .and_then(|k| self.path_waypoints.get(k))
            .copied()
            .unwrap_or(0);
        if pursuit.at_end
            && (end[0] - position[0]).hypot(end[1] - position[1]) <= self.params.g_thres_m
        {
            self.current = self.waypoints.len();
            self.status = MissionState::Completed;
            return self.decision(position, None);
        }
        if self.no_progress(pursuit.distance_left_m) {
            self.status = MissionState::Stuck;
            return self.decision(position, None);
        }
        let forces = command(
            &self.params,
            &self.obstacles,
            &self.information,
            position,
            pursuit.carrot,
        );
        self.decision(position, Some(&forces))
    }

    /// The stuck rule: whether `distance` (what is left to drive) has not improved by
    /// `stuck_min_progress_m` on its best over `stuck_window_steps` unhalted updates.
    fn no_progress(&mut self, distance: f64) -> bool {
        match self.checkpoint {
            None => self.checkpoint = Some((distance, self.active_steps)),
            Some((best, _)) if distance <= best - self.params.stuck_min_progress_m => {
                self.checkpoint = Some((distance, self.active_steps));
            }
            Some((_, since)) if self.active_steps - since >= self.params.stuck_window_steps => {
                return true;
            }
            Some(_) => {}
        }
        false
    }
}

#[cfg(test)]
pub(crate) mod tests;
