//! The robot's loop: missions, goal events, poses, feedback and ticks as they come.

use std::time::{Duration, Instant};

use roam_proto::controller::{Mission, MissionState, MAX_MISSION_BYTES};
use roam_proto::localization::PositionEstimate;
use roam_proto::{decode, encode};
use roam_runtime::Delivery;
use tokio::sync::mpsc;
use zenoh::sample::Sample;

use crate::msg::{FeedbackMessage, FollowPathFeedback, PoseWithCovarianceStamped};

use super::state::{GoalEvent, Robot};

const MAX_POSE_BYTES: usize = 64 * 1024;
const MAX_FEEDBACK_BYTES: usize = 1024;
const TICK: Duration = Duration::from_millis(200);

type Subscriber = zenoh::pubsub::Subscriber<zenoh::handlers::FifoChannelHandler<Sample>>;

impl Robot {
    pub(super) async fn run(
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
}
