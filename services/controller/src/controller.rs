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

use serde::{Deserialize, Serialize};

use crate::carrot::PathTracker;
use crate::forces::{command, Forces};
use crate::information::InformationField;
use crate::obstacle_field::ObstacleField;
use crate::params::{ApfParams, Follow};

/// Where a mission stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MissionStatus {
    /// No mission (or an empty one).
    Idle,
    /// Driving to the current waypoint.
    Active,
    /// Every waypoint was reached.
    Completed,
    /// No progress toward the current waypoint over the stuck window (a local minimum of
    /// the potential or an oscillation); final.
    Stuck,
    /// The PEB is above `max_peb_m` or unbounded: held while it lasts.
    HaltedPeb,
    /// The mission used up `max_steps` updates; final.
    StepLimit,
}

impl MissionStatus {
    /// Whether the mission is over for good (completed or given up).
    pub fn is_final(self) -> bool {
        matches!(
            self,
            MissionStatus::Completed | MissionStatus::Stuck | MissionStatus::StepLimit
        )
    }
}

/// What the controller decided on one update.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Decision {
    /// The command u of paper 002 Eq. 3; zero unless `status` is Active.
    pub u: [f64; 2],
    pub status: MissionStatus,
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
    status: MissionStatus,
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
            status: MissionStatus::Idle,
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
            MissionStatus::Idle
        } else {
            MissionStatus::Active
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
    pub fn status(&self) -> MissionStatus {
        self.status
    }

    /// Whether the robot still has a mission to drive (Active or HaltedPeb).
    pub fn is_active(&self) -> bool {
        matches!(
            self.status,
            MissionStatus::Active | MissionStatus::HaltedPeb
        )
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
        let active = self.status == MissionStatus::Active;
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
        if self.status.is_final() || self.status == MissionStatus::Idle {
            return self.decision(position, None);
        }
        if self.steps >= self.params.max_steps {
            self.status = MissionStatus::StepLimit;
            return self.decision(position, None);
        }
        self.steps += 1;
        let finite = position[0].is_finite() && position[1].is_finite();
        // An unbounded PEB (`None`, or NaN) counts as +∞: held unless the guard is off.
        let peb = peb_m.filter(|p| !p.is_nan()).unwrap_or(f64::INFINITY);
        if !(finite && (self.recovery || peb <= self.params.max_peb_m)) {
            self.status = MissionStatus::HaltedPeb;
            self.halted_updates += 1;
            return self.decision(position, None);
        }
        self.status = MissionStatus::Active;
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
            self.status = MissionStatus::Completed;
            return self.decision(position, None);
        };
        let distance = (waypoint[0] - position[0]).hypot(waypoint[1] - position[1]);
        if self.no_progress(distance) {
            self.status = MissionStatus::Stuck;
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
                self.status = MissionStatus::Completed;
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
            self.status = MissionStatus::Completed;
            return self.decision(position, None);
        }
        if self.no_progress(pursuit.distance_left_m) {
            self.status = MissionStatus::Stuck;
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
pub(crate) mod tests {
    use super::*;
    use crate::weights::Scheme;
    use roam_localization::fim::FimOptions;
    use roam_localization::model::RangingModel;
    use roam_localization::ToaNoise;
    use roam_proto::map::{GridMeta, Origin};
    use roam_world::grid::{occupancy, Grid};

    /// An empty 40 × 40 m map (0.5 m cells, origin 0) with four anchors around the
    /// middle: covered everywhere near it.
    pub(crate) fn fields() -> (Arc<ObstacleField>, Arc<InformationField>) {
        let meta = GridMeta {
            width: 80,
            height: 80,
            resolution: 0.5,
            origin: Origin::default(),
        };
        let obstacles = ObstacleField::new(&Grid::filled(meta, occupancy::FREE));
        let noise = ToaNoise {
            sigma_m: 0.1,
            d0_m: 15.0,
            k: 2.0,
        };
        let anchors = [[5.0, 5.0], [35.0, 5.0], [35.0, 35.0], [5.0, 35.0]];
        let model = RangingModel::new(&anchors, 30.0, noise).expect("model");
        (
            Arc::new(obstacles),
            Arc::new(InformationField::new(model, FimOptions::default())),
        )
    }

    fn controller(params: ApfParams) -> Controller {
        let (o, i) = fields();
        Controller::new(params, o, i)
    }

    fn plain() -> ApfParams {
        ApfParams {
            scheme: Scheme::Plain,
            ..ApfParams::default()
        }
    }

    const GOOD: Option<f64> = Some(0.1);

    #[test]
    fn idle_until_a_mission_and_after_an_empty_one() {
        let mut c = controller(plain());
        let d = c.update([20.0, 20.0], GOOD);
        assert_eq!(d.status, MissionStatus::Idle);
        assert_eq!((d.u, d.steps, d.waypoint), ([0.0, 0.0], 0, None));
        c.set_mission(vec![[25.0, 20.0]]);
        assert!(c.is_active());
        c.end_mission();
        assert_eq!(c.update([20.0, 20.0], GOOD).status, MissionStatus::Idle);
    }

    #[test]
    fn active_drives_toward_the_waypoint_and_reports_the_distance_left() {
        let mut c = controller(plain());
        c.set_mission(vec![[23.0, 24.0], [23.0, 30.0]]);
        let d = c.update([20.0, 20.0], GOOD);
        assert_eq!(d.status, MissionStatus::Active);
        // Far from the walls: u = f_a = (0.6, 0.8).
        assert!((d.u[0] - 0.6).abs() < 1e-12 && (d.u[1] - 0.8).abs() < 1e-12);
        assert_eq!((d.waypoint, d.steps), (Some(0), 1));
        // 5 m to the first, 6 m more to the second.
        assert!((d.distance_left_m - 11.0).abs() < 1e-12);
        assert_eq!((d.omega_deg, d.z_isa), (0.0, 0.0));
    }

    #[test]
    fn waypoints_within_g_thres_pass_in_the_same_update_then_completed() {
        let mut c = controller(plain());
        c.set_mission(vec![[20.0, 20.0], [20.05, 20.0], [25.0, 20.0]]);
        // The first two are within 0.1 m: the third is current at once.
        let d = c.update([20.0, 20.0], GOOD);
        assert_eq!((d.status, d.waypoint), (MissionStatus::Active, Some(2)));
        assert!((d.u[0] - 1.0).abs() < 1e-12);
        assert!((d.distance_left_m - 5.0).abs() < 1e-12);
        // 0.11 m short is not reached, 0.09 m short is (g_thres = 0.10 m).
        assert_eq!(c.update([24.89, 20.0], GOOD).waypoint, Some(2));
        let d = c.update([24.91, 20.0], GOOD);
        assert_eq!(d.status, MissionStatus::Completed);
        assert_eq!(
            (d.u, d.waypoint, d.distance_left_m),
            ([0.0, 0.0], None, 0.0)
        );
        assert_eq!(d.steps, 3);
        // Final: nothing changes any more.
        let again = c.update([0.0, 0.0], GOOD);
        assert_eq!((again.status, again.steps), (MissionStatus::Completed, 3));
    }

    #[test]
    fn via_thres_loosens_every_waypoint_but_the_last() {
        let mut c = controller(ApfParams {
            via_thres_m: Some(0.5),
            ..plain()
        });
        c.set_mission(vec![[20.4, 20.0], [25.0, 20.0]]);
        // 0.4 m from the first: passed (via 0.5 m), the last is current.
        let d = c.update([20.0, 20.0], GOOD);
        assert_eq!(d.waypoint, Some(1));
        // The last still needs g_thres.
        assert_eq!(c.update([24.6, 20.0], GOOD).waypoint, Some(1));
        assert_eq!(
            c.update([24.95, 20.0], GOOD).status,
            MissionStatus::Completed
        );
    }

    #[test]
    fn a_bad_or_lost_peb_holds_the_robot_until_it_is_good_again() {
        let mut c = controller(plain());
        c.set_mission(vec![[25.0, 20.0]]);
        for (peb, n) in [(None, 1), (Some(2.5), 2)] {
            let d = c.update([20.0, 20.0], peb);
            assert_eq!(d.status, MissionStatus::HaltedPeb);
            assert_eq!((d.u, d.halted_updates, d.steps), ([0.0, 0.0], n, n));
            assert!(c.is_active());
        }
        let d = c.update([20.0, 20.0], Some(2.0));
        assert_eq!((d.status, d.halted_updates), (MissionStatus::Active, 0));
        assert_eq!(d.u, [1.0, 0.0]);
    }

    #[test]
    fn a_recovery_drives_through_a_bad_peb_and_the_next_mission_is_guarded_again() {
        let mut c = controller(plain());
        c.set_recovery(vec![[25.0, 20.0]]);
        let d = c.update([20.0, 20.0], None);
        assert_eq!((d.status, d.u), (MissionStatus::Active, [1.0, 0.0]));
        c.set_mission(vec![[25.0, 20.0]]);
        assert_eq!(
            c.update([20.0, 20.0], None).status,
            MissionStatus::HaltedPeb
        );
    }

    #[test]
    fn an_infinite_bound_turns_the_guard_off() {
        let mut c = controller(ApfParams {
            max_peb_m: f64::INFINITY,
            ..plain()
        });
        c.set_mission(vec![[25.0, 20.0]]);
        for peb in [None, Some(1e9), Some(f64::NAN)] {
            assert_eq!(c.update([20.0, 20.0], peb).status, MissionStatus::Active);
        }
        // A non-finite position is always held.
        let d = c.update([f64::NAN, 20.0], GOOD);
        assert_eq!((d.status, d.u), (MissionStatus::HaltedPeb, [0.0, 0.0]));
    }

    #[test]
    fn no_progress_over_the_window_is_stuck_but_halts_do_not_count() {
        let mut c = controller(ApfParams {
            stuck_window_steps: 10,
            stuck_min_progress_m: 0.25,
            ..plain()
        });
        c.set_mission(vec![[25.0, 20.0]]);
        // The first update sets the checkpoint (5 m); 0.2 m of progress is not enough.
        assert_eq!(c.update([20.0, 20.0], GOOD).status, MissionStatus::Active);
        for k in 1..10 {
            assert_eq!(
                c.update([20.0 + 0.02 * k as f64, 20.0], GOOD).status,
                MissionStatus::Active
            );
            // Halted updates do not advance the window.
            assert_eq!(
                c.update([20.0, 20.0], None).status,
                MissionStatus::HaltedPeb
            );
        }
        let d = c.update([20.2, 20.0], GOOD);
        assert_eq!(d.status, MissionStatus::Stuck);
        assert_eq!(d.u, [0.0, 0.0]);
        assert_eq!(d.steps, 20);
        assert_eq!(c.update([24.0, 20.0], GOOD).status, MissionStatus::Stuck);
        // A new mission starts afresh.
        c.set_mission(vec![[25.0, 20.0]]);
        let d = c.update([20.0, 20.0], GOOD);
        assert_eq!((d.status, d.steps), (MissionStatus::Active, 1));
    }

    #[test]
    fn progress_moves_the_window() {
        let mut c = controller(ApfParams {
            stuck_window_steps: 10,
            ..plain()
        });
        c.set_mission(vec![[30.0, 20.0]]);
        // 0.3 m per 9 updates: progress every window, never stuck.
        for k in 0..100 {
            let x = 20.0 + 0.3 * (k / 9) as f64;
            assert_eq!(
                c.update([x, 20.0], GOOD).status,
                MissionStatus::Active,
                "{k}"
            );
        }
    }

    #[test]
    fn the_step_limit_ends_the_mission() {
        let mut c = controller(ApfParams {
            max_steps: 3,
            ..plain()
        });
        c.set_mission(vec![[30.0, 20.0]]);
        for _ in 0..3 {
            assert_eq!(c.update([20.0, 20.0], GOOD).status, MissionStatus::Active);
        }
        let d = c.update([20.0, 20.0], GOOD);
        assert_eq!(
            (d.status, d.steps, d.u),
            (MissionStatus::StepLimit, 3, [0.0, 0.0])
        );
        assert_eq!(
            c.update([30.0, 20.0], GOOD).status,
            MissionStatus::StepLimit
        );
    }

    #[test]
    fn walls_push_and_the_is_force_is_weighted_by_the_scheme() {
        // 1 m from the west edge (x = 0): f_Tr = (1 − 1/3)·(1, 0), times z_r = 20.
        let mut c = controller(plain());
        c.set_mission(vec![[1.0, 30.0]]);
        let d = c.update([1.0, 20.0], GOOD);
        assert!((d.u[0] - 20.0 * 2.0 / 3.0).abs() < 1e-6, "{:?}", d.u);
        assert!((d.u[1] - 1.0).abs() < 1e-9);
        // Fixed IS: u = f_a + 0.8 f_is, and ω is reported.
        let (o, i) = fields();
        let mut c = Controller::new(
            ApfParams {
                scheme: Scheme::Fixed,
                ..ApfParams::default()
            },
            o,
            i.clone(),
        );
        c.set_mission(vec![[30.0, 12.0]]);
        let p = [12.0, 12.0];
        let d = c.update(p, GOOD);
        let f_is = i.is_force(p);
        assert!((d.u[0] - (1.0 + 0.8 * f_is[0])).abs() < 1e-12);
        assert!((d.u[1] - 0.8 * f_is[1]).abs() < 1e-12);
        assert!((d.omega_deg - crate::forces::omega_deg([1.0, 0.0], f_is)).abs() < 1e-12);
        assert_eq!(d.z_isa, 0.8);
    }

    fn path_params() -> ApfParams {
        ApfParams {
            follow: Follow::Path,
            lookahead_m: 0.4,
            ..plain()
        }
    }

    #[test]
    fn under_follow_path_f_a_pulls_toward_the_carrot_along_the_path() {
        let mut c = controller(path_params());
        // An L from where the robot is: east 4 m, then north 4 m.
        c.set_mission(vec![[22.0, 20.0], [24.0, 20.0], [24.0, 24.0]]);
        let d = c.update([20.0, 20.0], GOOD);
        assert_eq!((d.status, d.waypoint), (MissionStatus::Active, Some(0)));
        // On the path: the carrot is 0.4 m ahead, straight east.
        assert!(
            (d.u[0] - 1.0).abs() < 1e-12 && d.u[1].abs() < 1e-12,
            "{:?}",
            d.u
        );
        assert!((d.distance_left_m - 8.0).abs() < 1e-12);
        // A step at a time (the projection moves at most 2 L = 0.8 m per update), then
        // 0.3 m north of the first leg at x = 21: the carrot (21.4, 20) pulls back
        // toward the path, where f_a toward the waypoint (22, 20) would cut across.
        c.update([20.4, 20.0], GOOD);
        c.update([20.8, 20.0], GOOD);
        let d = c.update([21.0, 20.3], GOOD);
        let expect = crate::forces::attractive([21.0, 20.3], [21.4, 20.0]);
        assert!((d.u[0] - expect[0]).abs() < 1e-12 && (d.u[1] - expect[1]).abs() < 1e-12);
        assert!((d.distance_left_m - (0.3 + 7.0)).abs() < 1e-12);
        // Next to the corner: the carrot is round it and the reported waypoint is the one
        // ahead of the projection.
        for x in [21.6, 22.4, 23.2] {
            c.update([x, 20.0], GOOD);
        }
        let d = c.update([23.9, 20.0], GOOD);
        assert_eq!(d.waypoint, Some(1));
        let expect = crate::forces::attractive([23.9, 20.0], [24.0, 20.3]);
        assert!((d.u[0] - expect[0]).abs() < 1e-12 && (d.u[1] - expect[1]).abs() < 1e-12);
        c.update([24.0, 20.4], GOOD);
        let d = c.update([24.0, 21.0], GOOD);
        assert_eq!(d.waypoint, Some(2));
        assert!((d.u[1] - 1.0).abs() < 1e-12);
    }

    #[test]
    fn under_follow_path_the_mission_completes_at_the_last_point_only() {
        let mut c = controller(path_params());
        // Out 3 m and back to 0.05 m from the start: the start is within g_thres of the
        // last point, but the carrot is not at the end yet.
        c.set_mission(vec![
            [23.0, 20.0],
            [23.0, 20.5],
            [20.05, 20.5],
            [20.05, 20.05],
        ]);
        let d = c.update([20.0, 20.0], GOOD);
        assert_eq!(d.status, MissionStatus::Active);
        // Along the way, then within g_thres of the end with the carrot there.
        for x in [20.4, 20.8, 21.2, 21.6, 22.0, 22.4, 22.8] {
            assert_eq!(c.update([x, 20.0], GOOD).status, MissionStatus::Active);
        }
        for p in [
            [23.0, 20.2],
            [22.6, 20.5],
            [22.2, 20.5],
            [21.8, 20.5],
            [21.4, 20.5],
        ] {
            assert_eq!(c.update(p, GOOD).status, MissionStatus::Active);
        }
        for x in [21.0, 20.6, 20.2] {
            assert_eq!(c.update([x, 20.5], GOOD).status, MissionStatus::Active);
        }
        // 0.11 m short is not reached; 0.09 m is.
        assert_eq!(c.update([20.05, 20.16], GOOD).status, MissionStatus::Active);
        let d = c.update([20.05, 20.14], GOOD);
        assert_eq!(d.status, MissionStatus::Completed);
        assert_eq!(
            (d.u, d.waypoint, d.distance_left_m),
            ([0.0, 0.0], None, 0.0)
        );
        // A one-waypoint mission where the robot stands is complete at once.
        c.set_mission(vec![[20.05, 20.0]]);
        assert_eq!(
            c.update([20.0, 20.0], GOOD).status,
            MissionStatus::Completed
        );
    }

    #[test]
    fn under_follow_path_progress_along_the_path_is_what_the_stuck_rule_counts() {
        let mut c = controller(ApfParams {
            stuck_window_steps: 10,
            stuck_min_progress_m: 0.25,
            ..path_params()
        });
        c.set_mission(vec![[30.0, 20.0]]);
        // Sideways on the spot (no progress along the path): stuck after the window.
        for k in 0..10 {
            let y = if k % 2 == 0 { 20.1 } else { 19.9 };
            assert_eq!(
                c.update([20.0, y], GOOD).status,
                MissionStatus::Active,
                "{k}"
            );
        }
        assert_eq!(c.update([20.0, 20.1], GOOD).status, MissionStatus::Stuck);
        // 0.3 m along the path per 9 updates: never stuck.
        c.set_mission(vec![[40.0, 20.0]]);
        for k in 0..150 {
            let x = 10.0 + 0.3 * (k / 9) as f64;
            assert_eq!(
                c.update([x, 20.0], GOOD).status,
                MissionStatus::Active,
                "{k}"
            );
        }
    }

    #[test]
    fn under_follow_path_a_waypoint_that_is_not_finite_is_left_out() {
        let mut c = controller(path_params());
        c.set_mission(vec![[f64::NAN, 0.0], [22.0, 20.0]]);
        let d = c.update([20.0, 20.0], GOOD);
        assert_eq!((d.status, d.waypoint), (MissionStatus::Active, Some(1)));
        assert!((d.u[0] - 1.0).abs() < 1e-12);
        c.set_mission(vec![[f64::INFINITY, 0.0]]);
        assert_eq!(
            c.update([20.0, 20.0], GOOD).status,
            MissionStatus::Completed
        );
    }

    #[test]
    fn under_follow_path_the_path_starts_where_the_first_driven_update_is() {
        let mut c = controller(path_params());
        c.set_mission(vec![[24.0, 20.0]]);
        // Held for the PEB at first: the path starts at the first update that drives.
        assert_eq!(
            c.update([10.0, 10.0], None).status,
            MissionStatus::HaltedPeb
        );
        let d = c.update([20.0, 24.0], GOOD);
        // The carrot is 0.4 m along the segment (20, 24) → (24, 20): diagonal.
        let s = std::f64::consts::FRAC_1_SQRT_2;
        assert!(
            (d.u[0] - s).abs() < 1e-12 && (d.u[1] + s).abs() < 1e-12,
            "{:?}",
            d.u
        );
        assert!((d.distance_left_m - 32f64.sqrt()).abs() < 1e-12);
    }
}
