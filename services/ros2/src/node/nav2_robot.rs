//! A robot on Nav2 as roam's robot: the node stands in, on roam's keys, for the two
//! services roam's executive drives a robot through (localization and the controller),
//! and does their work with the robot's own Nav2.
//!
//! - **Estimates.** Each pose on the robot's pose topic
//!   (geometry_msgs/msg/PoseWithCovarianceStamped: AMCL's `/amcl_pose`) becomes a
//!   `position_estimate` on `<root>/robot/<id>/estimate`: the position, the covariance's
//!   x-y block as the CRB (paper 002 Eq. 5's place: AMCL's particle spread is the
//!   robot's own uncertainty) and its √trace as the PEB.
//! - **Missions.** Each `mission` on `<root>/robot/<id>/mission` becomes a goal of the
//!   robot's `follow_path` (nav2_msgs/action/FollowPath): the waypoints as a
//!   nav_msgs/Path (Nav2's controllers prune what is behind the robot), which preempts
//!   the previous goal as Nav2's
//!   controller server does (no stop in between). A mission without waypoints cancels
//!   the goal (the robot stops).
//! - **Status.** A `controller_status` on `<root>/robot/<id>/controller` after every pose
//!   and every change, as roam's controller sends it: `active` while the goal runs
//!   (waypoint and distance left from the pose along the path), `completed` when it
//!   succeeds, `stuck` when the server rejects the goal, aborts it or does not answer
//!   (the executive replans, as for a robot stuck in a potential field's minimum), and
//!   `halted_stale` when no pose came for `pose_timeout_s` (the goal is cancelled: a robot
//!   roam cannot see is held; the first pose after it sends the mission again).
//!
//! Each reason is logged. The executive, its window machine, the planner and the time
//! model's calibration are roam's own and unchanged: the calibration fits paper 000
//! Eq. 2 to what this robot drives, as for any robot.

use std::sync::Arc;
use std::time::{Duration, Instant};

use roam_proto::controller::{ControllerStatus, Mission, MissionState, MAX_MISSION_BYTES};
use roam_proto::localization::PositionEstimate;
use roam_proto::{decode, encode, keys};
use roam_runtime::{Delivery, Service};
use serde::Deserialize;
use tokio::sync::mpsc;
use zenoh::sample::Sample;

use super::action_client::ActionClient;
use super::{Output, Ros2Error};
use crate::convert;
use crate::msg::{
    FeedbackMessage, FollowPathFeedback, FollowPathGoal, FollowPathResult, GetResultResponse,
    GoalState, PoseWithCovarianceStamped, SendGoalRequest, Uuid,
};
use crate::names::Qos;
use crate::types;

/// A robot on Nav2 that roam drives (`roam ros2`'s `nav2_robots`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Nav2Robot {
    /// The robot's name in roam (its keys `<root>/robot/<id>/…`, the executive's
    /// `robot`).
    pub robot: String,
    /// Its pose topic (geometry_msgs/msg/PoseWithCovarianceStamped).
    pub pose_topic: String,
    /// Its FollowPath action.
    pub follow_path: String,
    /// Nav2's controller plugin and goal checker sent with each path (empty: the
    /// controller server's default).
    pub controller_id: String,
    pub goal_checker_id: String,
    /// No pose for this long holds the robot (its goal is cancelled), seconds.
    pub pose_timeout_s: f64,
    /// How long FollowPath may take to accept or refuse a goal, seconds.
    pub answer_timeout_s: f64,
}

impl Default for Nav2Robot {
    fn default() -> Self {
        Nav2Robot {
            robot: "robot".to_owned(),
            pose_topic: "/amcl_pose".to_owned(),
            follow_path: "/follow_path".to_owned(),
            controller_id: String::new(),
            goal_checker_id: String::new(),
            pose_timeout_s: 2.0,
            answer_timeout_s: 5.0,
        }
    }
}

/// The most Nav2 robots one node drives.
pub const MAX_NAV2_ROBOTS: usize = 64;
/// How long a goal's result is waited for at most (a path a robot drives for an hour).
const RESULT_WITHIN: Duration = Duration::from_secs(3600);
const MAX_POSE_BYTES: usize = 64 * 1024;
const MAX_FEEDBACK_BYTES: usize = 1024;
const TICK: Duration = Duration::from_millis(200);

impl Nav2Robot {
    /// The config's numbers and names, checked.
    pub fn check(&self) -> Result<(), String> {
        keys::check_name("nav2_robots.robot", &self.robot).map_err(|e| e.to_string())?;
        for (name, value) in [
            ("pose_timeout_s", self.pose_timeout_s),
            ("answer_timeout_s", self.answer_timeout_s),
        ] {
            if !(value.is_finite() && value > 0.0 && value <= 3600.0) {
                return Err(format!(
                    "nav2_robots.{name} = {} must be a number of seconds in (0, 3600]",
                    roam_proto::number(value)
                ));
            }
        }
        Ok(())
    }
}

/// What the goal tasks tell the robot's loop.
#[derive(Debug)]
enum GoalEvent {
    Accepted {
        mission: String,
        goal: Uuid,
    },
    Ended {
        mission: String,
        state: MissionState,
        why: String,
    },
}

/// Declares robot `config`'s subscriptions and action client and drives it until the
/// service stops.
pub(super) async fn declare(
    service: &Service,
    out: Arc<Output>,
    root: &str,
    config: Nav2Robot,
    mission_clock: super::sim_time::MissionClock,
) -> Result<(), Ros2Error> {
    config.check().map_err(|reason| Ros2Error::Declare {
        what: "Nav2 robot",
        key: config.robot.clone(),
        reason,
    })?;
    let (pose, poses, pose_token) = out
        .subscribe(
            "pose subscription",
            &config.pose_topic,
            types::POSE_WITH_COVARIANCE_STAMPED,
            Qos::STREAM,
        )
        .await?;
    let (_, feedbacks, feedback_token) = out
        .subscribe(
            "feedback subscription",
            &format!("{}/_action/feedback", config.follow_path),
            types::FOLLOW_PATH_FEEDBACK_MESSAGE,
            Qos::STREAM,
        )
        .await?;
    let mission_key = keys::robot_mission(root, &config.robot);
    let missions = out
        .session()
        .declare_subscriber(mission_key.clone())
        .await
        .map_err(|e| Ros2Error::Declare {
            what: "mission subscriber",
            key: mission_key.clone(),
            reason: e.to_string(),
        })?;
    let tokens = vec![pose_token, feedback_token];
    let follow_path = ActionClient::declare(
        &out,
        &config.follow_path,
        types::FOLLOW_PATH_SEND_GOAL,
        types::FOLLOW_PATH_GET_RESULT,
    )
    .await?;
    tracing::info!(
        robot = %config.robot,
        pose = %pose.qualified_name,
        follow_path = %config.follow_path,
        "roam ros2: driving a Nav2 robot"
    );
    let robot = Robot {
        estimate_key: keys::robot_estimate(root, &config.robot),
        status_key: keys::robot_controller(root, &config.robot),
        out,
        follow_path,
        config,
        mission_clock,
        mission: None,
        goal: None,
        state: MissionState::Idle,
        position: None,
        last_pose: None,
        step: 0,
        steps: 0,
        peb_m: None,
        distance_to_goal: None,
    };
    let cancel = service.cancel_token();
    service.spawn(async move {
        let _tokens = tokens;
        robot.run(poses, feedbacks, missions, cancel).await;
    });
    Ok(())
}

struct Robot {
    out: Arc<Output>,
    follow_path: ActionClient,
    config: Nav2Robot,
    mission_clock: super::sim_time::MissionClock,
    estimate_key: String,
    status_key: String,
    /// The mission being driven.
    mission: Option<Mission>,
    /// Its FollowPath goal, once accepted.
    goal: Option<Uuid>,
    state: MissionState,
    position: Option<[f64; 2]>,
    last_pose: Option<Instant>,
    step: u64,
    steps: u64,
    peb_m: Option<f64>,
    distance_to_goal: Option<f64>,
}

type Subscriber = zenoh::pubsub::Subscriber<zenoh::handlers::FifoChannelHandler<Sample>>;

impl Robot {
    async fn run(
        mut self,
        poses: Subscriber,
        feedbacks: Subscriber,
        missions: Subscriber,
        cancel: tokio_util::sync::CancellationToken,
    ) {
        let (events_tx, mut events) = mpsc::channel::<GoalEvent>(64);
        let mut tick = tokio::time::interval(TICK);
        loop {
            tokio::select! {
                biased;
                _ = cancel.cancelled() => break,
                sample = missions.recv_async() => match sample {
                    Ok(sample) => self.on_mission(&sample, &events_tx).await,
                    Err(_) => break,
                },
                Some(event) = events.recv() => self.on_goal_event(event).await,
                sample = poses.recv_async() => match sample {
                    Ok(sample) => self.on_pose(&sample, &events_tx).await,
                    Err(_) => break,
                },
                sample = feedbacks.recv_async() => match sample {
                    Ok(sample) => self.on_feedback(&sample),
                    Err(_) => break,
                },
                _ = tick.tick() => self.on_tick().await,
            }
        }
        self.cancel_goal();
    }

    async fn on_mission(&mut self, sample: &Sample, events: &mpsc::Sender<GoalEvent>) {
        if sample.payload().len() > MAX_MISSION_BYTES {
            return self
                .out
                .refuse(&self.status_key, "a mission above its size limit");
        }
        let mission = match decode::<Mission>(&sample.payload().to_bytes()) {
            Ok(m) if m.robot == self.config.robot => m,
            Ok(_) => {
                return self
                    .out
                    .refuse(&self.status_key, "a mission for another robot")
            }
            Err(e) => return self.out.refuse(&self.status_key, &e.to_string()),
        };
        self.distance_to_goal = None;
        self.steps = 0;
        if mission.waypoints.is_empty() {
            self.cancel_goal();
            self.mission = Some(mission);
            self.state = MissionState::Idle;
        } else {
            // A new goal preempts the running one (Nav2's controller server replaces the
            // path it follows): no cancel first, so the robot does not stop between
            // the two paths. The old goal's end is ignored (another mission's).
            self.goal = None;
            self.state = MissionState::Active;
            self.send(&mission, events);
            self.mission = Some(mission);
        }
        self.publish_status().await;
    }

    /// Sends `mission` to FollowPath and waits for its result in a task of its own.
    fn send(&self, mission: &Mission, events: &mpsc::Sender<GoalEvent>) {
        let goal_id = Uuid {
            uuid: random_uuid(),
        };
        // The waypoints as planned: Nav2's controllers prune the part of a path behind
        // the robot themselves (the robot's projection onto it), as roam's controller
        // follows it from its projection.
        let waypoints = &mission.waypoints;
        let request = SendGoalRequest {
            goal_id,
            goal: FollowPathGoal {
                path: convert::path(waypoints, super::services::now()),
                controller_id: self.config.controller_id.clone(),
                goal_checker_id: self.config.goal_checker_id.clone(),
                progress_checker_id: String::new(),
            },
        };
        let (client, events, id) = (self.follow_path.clone(), events.clone(), mission.id.clone());
        let within = Duration::from_secs_f64(self.config.answer_timeout_s);
        tokio::spawn(async move {
            let ended = |state, why: String| GoalEvent::Ended {
                mission: id.clone(),
                state,
                why,
            };
            let accepted = match client.send_goal(&request, within).await {
                Ok(r) if r.accepted => r,
                Ok(_) => {
                    let why = "follow_path rejected the goal".to_owned();
                    let _ = events.send(ended(MissionState::Stuck, why)).await;
                    return;
                }
                Err(why) => {
                    let _ = events.send(ended(MissionState::Stuck, why)).await;
                    return;
                }
            };
            let _ = accepted;
            let _ = events
                .send(GoalEvent::Accepted {
                    mission: id.clone(),
                    goal: goal_id,
                })
                .await;
            let event = match client
                .get_result::<GetResultResponse<FollowPathResult>>(goal_id, RESULT_WITHIN)
                .await
            {
                Ok(r) if r.status == GoalState::Succeeded as i8 => {
                    ended(MissionState::Completed, String::new())
                }
                Ok(r) => ended(
                    MissionState::Stuck,
                    format!(
                        "follow_path ended the goal with status {} (error {}: {})",
                        r.status,
                        r.result.error_code,
                        roam_proto::excerpt::excerpt_n(&r.result.error_msg, 200)
                    ),
                ),
                Err(why) => ended(MissionState::Stuck, why),
            };
            let _ = events.send(event).await;
        });
    }

    async fn on_goal_event(&mut self, event: GoalEvent) {
        let current = self.mission.as_ref().map(|m| m.id.as_str());
        match event {
            GoalEvent::Accepted { mission, goal } if Some(mission.as_str()) == current => {
                self.goal = Some(goal);
            }
            GoalEvent::Ended {
                mission,
                state,
                why,
            } if Some(mission.as_str()) == current && self.state == MissionState::Active => {
                self.goal = None;
                if !why.is_empty() {
                    tracing::warn!(robot = %self.config.robot, %mission, "roam ros2: the Nav2 robot's mission ended {state:?}: {why}");
                }
                self.state = state;
                self.publish_status().await;
            }
            // A goal accepted after the robot was held, or of a mission since replaced by
            // an empty one: cancelled (a newer goal preempts it otherwise).
            GoalEvent::Accepted { goal, .. } if self.state != MissionState::Active => {
                self.cancel_this(goal)
            }
            GoalEvent::Accepted { .. } => {}
            GoalEvent::Ended { .. } => {}
        }
    }

    async fn on_pose(&mut self, sample: &Sample, events: &mpsc::Sender<GoalEvent>) {
        let pose = match crate::cdr::decode::<PoseWithCovarianceStamped>(
            &sample.payload().to_bytes(),
            "pose",
            MAX_POSE_BYTES,
        ) {
            Ok(p) => p,
            Err(e) => return self.out.refuse(&self.estimate_key, &e.to_string()),
        };
        let at = [pose.pose.pose.position.x, pose.pose.pose.position.y];
        if !at.iter().all(|v| v.is_finite()) {
            return self
                .out
                .refuse(&self.estimate_key, "a pose that is not a finite position");
        }
        let c = pose.pose.covariance.0;
        let crb = [[c[0], c[1]], [c[6], c[7]]];
        let bounded = crb.iter().flatten().all(|v| v.is_finite()) && c[0] >= 0.0 && c[7] >= 0.0;
        self.peb_m = bounded.then(|| (c[0] + c[7]).sqrt());
        self.step += 1;
        self.position = Some(at);
        let resumed = self.state == MissionState::HaltedStale;
        self.last_pose = Some(Instant::now());
        let estimate = PositionEstimate {
            robot: self.config.robot.clone(),
            step: self.step,
            // The pose's own stamp: simulated time with `use_sim_time` (what the mission
            // clock follows), wall time without; the clock's latest tick if it has none.
            time_s: match pose.header.stamp.as_nanos() {
                0 => self.mission_clock.now_s().unwrap_or(0.0),
                ns => ns as f64 * 1e-9,
            },
            position: at,
            crb: bounded.then_some(crb),
            peb_m: self.peb_m,
            anchors_used: Vec::new(),
            degraded: false,
        };
        roam_runtime::publish_bytes(
            self.out.session(),
            &self.estimate_key,
            encode(&estimate),
            Delivery::Latest,
        )
        .await;
        if resumed {
            if let Some(mission) = self.mission.clone() {
                tracing::info!(robot = %self.config.robot, "roam ros2: poses again; the mission is sent again");
                self.state = MissionState::Active;
                self.send(&mission, events);
            }
        }
        if self.state == MissionState::Active {
            self.steps += 1;
        }
        self.publish_status().await;
    }

    fn on_feedback(&mut self, sample: &Sample) {
        let Ok(feedback) = crate::cdr::decode::<FeedbackMessage<FollowPathFeedback>>(
            &sample.payload().to_bytes(),
            "feedback",
            MAX_FEEDBACK_BYTES,
        ) else {
            return;
        };
        if Some(feedback.goal_id) == self.goal {
            let d = f64::from(feedback.feedback.distance_to_goal);
            self.distance_to_goal = d.is_finite().then_some(d.max(0.0));
        }
    }

    /// A robot whose poses stopped is held: its goal cancelled, the reason logged.
    async fn on_tick(&mut self) {
        let silent = self
            .last_pose
            .is_none_or(|at| at.elapsed() > Duration::from_secs_f64(self.config.pose_timeout_s));
        if self.state == MissionState::Active && silent {
            tracing::warn!(
                robot = %self.config.robot,
                "roam ros2: no pose on {} for {} s; the Nav2 robot is held (its goal cancelled)",
                self.config.pose_topic,
                self.config.pose_timeout_s
            );
            self.cancel_goal();
            self.state = MissionState::HaltedStale;
            self.publish_status().await;
        }
    }

    fn cancel_goal(&mut self) {
        if let Some(goal) = self.goal.take() {
            self.cancel_this(goal);
        }
    }

    fn cancel_this(&self, goal: Uuid) {
        let (client, within) = (
            self.follow_path.clone(),
            Duration::from_secs_f64(self.config.answer_timeout_s),
        );
        let robot = self.config.robot.clone();
        tokio::spawn(async move {
            if let Err(e) = client.cancel(goal, within).await {
                tracing::warn!(%robot, "roam ros2: cancelling the Nav2 robot's goal: {e}");
            }
        });
    }

    /// The controller's report, from the last pose along the mission's waypoints.
    async fn publish_status(&self) {
        let waypoints = self.mission.as_ref().map_or(&[][..], |m| &m.waypoints[..]);
        let (waypoint, distance_left_m) = match (self.state, self.position) {
            (MissionState::Active, Some(at)) if !waypoints.is_empty() => {
                let (index, left) = ahead(at, waypoints);
                (Some(index), Some(self.distance_to_goal.unwrap_or(left)))
            }
            (MissionState::Completed, _) => (None, Some(0.0)),
            _ => (None, None),
        };
        let status = ControllerStatus {
            robot: self.config.robot.clone(),
            mission: self.mission.as_ref().map(|m| m.id.clone()),
            state: self.state,
            waypoint,
            waypoints: waypoints.len(),
            distance_left_m,
            steps: self.steps,
            estimate_step: (self.step > 0).then_some(self.step),
            peb_m: self.peb_m,
            omega_deg: 0.0,
            z_isa: 0.0,
            u: [0.0, 0.0],
        };
        roam_runtime::publish_bytes(
            self.out.session(),
            &self.status_key,
            encode(&status),
            Delivery::Reliable,
        )
        .await;
    }
}

/// The waypoint ahead of a robot at `at` (the one after the nearest) and the distance
/// left along the path from there.
fn ahead(at: [f64; 2], waypoints: &[[f64; 2]]) -> (usize, f64) {
    let dist = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    let nearest = waypoints
        .iter()
        .enumerate()
        .min_by(|(_, a), (_, b)| dist(at, **a).total_cmp(&dist(at, **b)))
        .map_or(0, |(i, _)| i);
    let index = (nearest + 1).min(waypoints.len() - 1);
    let legs: f64 = waypoints[index..]
        .windows(2)
        .map(|w| dist(w[0], w[1]))
        .sum();
    (index, dist(at, waypoints[index]) + legs)
}

/// A goal id: 128 random bits, as rclcpp's.
fn random_uuid() -> [u8; 16] {
    let hex = roam_planner::token::random_hex128();
    let mut uuid = [0u8; 16];
    for (i, byte) in uuid.iter_mut().enumerate() {
        *byte = hex
            .get(2 * i..2 * i + 2)
            .and_then(|h| u8::from_str_radix(h, 16).ok())
            .unwrap_or(0);
    }
    uuid
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_waypoint_ahead_and_the_distance_left() {
        let path = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 2.0]];
        let (index, left) = ahead([0.9, 0.0], &path);
        assert_eq!(index, 2);
        assert!((left - (1.1 + 2.0)).abs() < 1e-12);
        assert_eq!(ahead([2.0, 2.0], &path), (3, 0.0));
    }

    #[test]
    fn a_bad_config_is_named() {
        let bad = Nav2Robot {
            pose_timeout_s: f64::NAN,
            ..Nav2Robot::default()
        };
        assert!(bad.check().expect_err("NaN").contains("pose_timeout_s"));
        let bad = Nav2Robot {
            robot: "a/b".into(),
            ..Nav2Robot::default()
        };
        assert!(bad.check().is_err());
        assert!(Nav2Robot::default().check().is_ok());
    }

    #[test]
    fn goal_ids_are_random() {
        assert_ne!(random_uuid(), random_uuid());
    }
}
