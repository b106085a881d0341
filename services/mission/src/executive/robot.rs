//! The executive on one robot: its Zenoh ends, what it keeps from window to window, and
//! what it does for the window machine (plans asked, missions and statuses published,
//! the clock and the first estimate waited for, the calibration fed).

use std::sync::Arc;
use std::time::{Duration, Instant};

use roam_planner::client::PlannerClient;
use roam_proto::controller::Mission;
use roam_proto::keys;
use roam_proto::mission::ExecutiveStatus;
use roam_proto::planner::{Plan, PlannerModel};
use roam_runtime::{lock, ClientError, Delivery};
use tokio::task::JoinSet;
use tokio_util::sync::CancellationToken;

use crate::calibration::{store, Calibration, TimeModel};
use crate::config::ExecutiveConfig;
use crate::error::ExecutiveError;
use crate::inputs::Inputs;
use crate::request::plan_request;
use crate::window::{DrivenMission, Handover, Now, PlanAsk};

/// A curious plan is expected to take this times the slowest recent one, plus
/// [`PLAN_WALL_SLACK_S`].
const PLAN_WALL_MARGIN: f64 = 1.5;
const PLAN_WALL_SLACK_S: f64 = 0.05;

/// How long the executive waits for the sim's clock at its start.
const CLOCK_WAIT: Duration = Duration::from_secs(2);

/// The executive on one robot while it runs its tasks: its Zenoh ends, and what it
/// keeps from window to window.
pub(super) struct Executive<'a> {
    pub(super) session: &'a zenoh::Session,
    pub(super) root: &'a str,
    pub(super) config: &'a ExecutiveConfig,
    pub(super) planner: Arc<PlannerClient>,
    pub(super) inputs: Inputs,
    /// The robot's last good estimate.
    pub(super) position: Option<[f64; 2]>,
    /// The robot's time calibration, fitted as it drives.
    pub(super) calibration: Calibration,
    /// Wall seconds the recent curious plans took (request to reply), the slowest.
    pub(super) plan_wall_s: Option<f64>,
    /// The same for the seeded replans alone (they run far fewer generations).
    pub(super) replan_wall_s: Option<f64>,
    /// What the last window handed the next (the arrival margin, the mission and ask
    /// counts, the next window's plan).
    pub(super) handover: Handover,
    /// This executive's own tag in its mission ids (from its Zenoh session id), so a
    /// restarted executive never reuses an id its predecessor sent: the controller's
    /// statuses on an old mission are not taken for a new one's.
    pub(super) tag: String,
    /// What it heard last, for its status.
    pub(super) heard: Heard,
    /// The fleet's believed obstacles, when `obstacles_layer` is followed.
    pub(super) obstacles: Option<crate::obstacles::ObstacleSets>,
    /// The route a predecessor was driving (its `resume_file`), until the window of its
    /// task begins.
    pub(super) resume: Option<crate::window::Resumed>,
}

/// The sim steps of the last estimate and controller status the loop handled.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Heard {
    pub(super) estimate_step: Option<u64>,
    pub(super) status_step: Option<u64>,
}

/// A plan request's answer as the loop gets it back: the ask's id, whether it was
/// curious, the wall seconds it took, and the reply.
pub(super) type Answered = (u64, bool, f64, Result<Plan, ClientError>);

impl Executive<'_> {
    pub(super) fn now(&self) -> f64 {
        lock(&self.inputs.clock).now_s()
    }

    /// The model plans are made with: the fit, or Table I when not calibrating.
    pub(super) fn time_model(&self) -> TimeModel {
        if self.config.calibrate {
            self.calibration.model()
        } else {
            TimeModel::table_i()
        }
    }

    /// What a curious plan costs on the mission clock: the config's fixed figure when
    /// it sets one, else the wall time the last ones took (with a margin; the deadline
    /// until one was measured) at the clock's rate. Charging the whole deadline would
    /// waste it whenever the GA ends sooner (its generations, on a small map).
    fn planning_cost_s(&self) -> f64 {
        if let Some(cost) = self.config.planning_cost_s {
            return cost;
        }
        self.measured_cost_s(self.plan_wall_s)
    }

    /// What a seeded replan costs on the mission clock: the config's fixed figure (or
    /// its fixed `planning_cost_s`), else what the seeded replans took, measured as
    /// [`Self::planning_cost_s`] is (a curious plan's cost until one was measured).
    fn replan_cost_s(&self) -> f64 {
        if let Some(cost) = self.config.replan_cost_s.or(self.config.planning_cost_s) {
            return cost;
        }
        self.measured_cost_s(self.replan_wall_s.or(self.plan_wall_s))
    }

    /// `wall` seconds (the slowest recent, with a margin; the deadline until one was
    /// measured) on the mission clock.
    fn measured_cost_s(&self, wall: Option<f64>) -> f64 {
        let wall = wall.map_or(self.config.plan_deadline_s, |w| {
            (w * PLAN_WALL_MARGIN + PLAN_WALL_SLACK_S).min(self.config.plan_deadline_s)
        });
        wall * lock(&self.inputs.clock).rate()
    }

    /// The machine's time: the mission clock, wall seconds since `began`, what a plan
    /// costs now, and the clock's rate.
    pub(super) fn moment(&self, began: Instant) -> Now {
        Now {
            mission_s: self.now(),
            wall_s: began.elapsed().as_secs_f64(),
            planning_cost_s: self.planning_cost_s(),
            replan_cost_s: self.replan_cost_s(),
            clock_rate: lock(&self.inputs.clock).rate(),
        }
    }

    /// Sends the request `ask` describes ([`plan_request`]) without waiting: its answer
    /// joins `in_flight`.
    pub(super) fn ask(&self, ask: &PlanAsk, in_flight: &mut JoinSet<Answered>) {
        let request = plan_request(self.config, ask, self.time_model());
        let planner = self.planner.clone();
        let (id, curious) = (ask.id, ask.curious);
        in_flight.spawn(async move {
            let asked = Instant::now();
            let reply = planner.plan(&request).await;
            (id, curious, asked.elapsed().as_secs_f64(), reply)
        });
    }

    /// Learns what a curious plan costs from one that came back.
    pub(super) fn took(&mut self, plan: &Plan, took_s: f64) {
        // Only what the GA took says what a curious plan costs (a fallback to the
        // shortest path is answered at once).
        if plan.model != PlannerModel::Shortest {
            // The slowest of the recent plans, forgetting slowly; seeded replans apart.
            let slowest = if plan.seed_route_used.is_some() {
                &mut self.replan_wall_s
            } else {
                &mut self.plan_wall_s
            };
            *slowest = Some(slowest.map_or(took_s, |w| took_s.max(0.8 * w)));
        }
    }

    /// Sends `mission`, decided on the last estimate heard: the controller starts it
    /// after answering that estimate ([`Mission::after_step`]), as the batch does.
    pub(super) fn publish(&self, mission: &Mission) {
        let key = keys::robot_mission(self.root, &self.config.robot);
        let mission = Mission {
            after_step: self.heard.estimate_step,
            ..mission.clone()
        };
        roam_runtime::publish_wait(self.session, &key, &mission, Delivery::Reliable);
    }

    /// What the executive is doing, for operators and for lock-step drivers: the sim
    /// steps of the last estimate and controller status it handled, and the plans in
    /// flight.
    pub(super) fn publish_status(&self, window: usize, asks: usize) {
        let heard = self.heard;
        let key = keys::robot_executive(self.root, &self.config.robot);
        let status = ExecutiveStatus {
            robot: self.config.robot.clone(),
            window,
            estimate_step: heard.estimate_step,
            status_step: heard.status_step,
            plans_in_flight: asks as u32,
        };
        roam_runtime::publish_wait(self.session, &key, &status, Delivery::Latest);
    }

    /// Waits briefly for the sim's clock, so that an executive restarted mid-mission
    /// sees the mission time and skips the tasks that ended while it was down. Without
    /// a sim (a real fleet on wall time) it goes on after the wait.
    pub(super) async fn hear_the_clock(
        &self,
        cancel: &CancellationToken,
    ) -> Result<(), ExecutiveError> {
        let waited = Instant::now();
        while !lock(&self.inputs.clock).heard() && waited.elapsed() < CLOCK_WAIT {
            tokio::select! {
                _ = cancel.cancelled() => return Err(ExecutiveError::Cancelled),
                _ = tokio::time::sleep(Duration::from_millis(20)) => {}
            }
        }
        Ok(())
    }

    pub(super) async fn first_position(
        &mut self,
        cancel: &CancellationToken,
    ) -> Result<[f64; 2], ExecutiveError> {
        if let Some(p) = self.position {
            return Ok(p);
        }
        let waited = Duration::from_secs(30);
        let deadline = tokio::time::sleep(waited);
        tokio::pin!(deadline);
        loop {
            tokio::select! {
                _ = cancel.cancelled() => return Err(ExecutiveError::Cancelled),
                _ = &mut deadline => {
                    return Err(ExecutiveError::NoEstimate { robot: self.config.robot.clone(), waited });
                }
                sample = self.inputs.estimates.recv_async() => {
                    let Ok(sample) = sample else { return Err(ExecutiveError::Cancelled) };
                    if let Some(e) = self.inputs.estimate(&sample) {
                        self.heard.estimate_step = Some(e.step);
                        if !e.degraded {
                            self.position = Some(e.position);
                            // A sim that stepped for this estimate published its clock
                            // too: the window begins on the sim's time, not on wall time.
                            self.hear_the_clock(cancel).await?;
                            lock(&self.inputs.clock).heard_at(e.time_s);
                            return Ok(e.position);
                        }
                    }
                }
            }
        }
    }

    /// Keeps the route the robot now drives in the resume file, when one is configured.
    pub(super) fn keep_route(&self, route: Option<crate::window::Resumed>) {
        if let (Some(path), Some(route)) = (&self.config.resume_file, route) {
            if let Err(e) = crate::resume::save(path, &self.config.robot, &route) {
                tracing::warn!("the route is not kept for a restart: {e}");
            }
        }
    }

    /// The calibration learns from the window's drives (the parts driven of missions
    /// replans replaced, and the one that arrived: each one's Σd and Σθ as Eq. 2
    /// counts them on the cells, and how long driving it took) and keeps the fit in
    /// the calibration file.
    pub(super) fn calibrate(&mut self, window: usize, drives: &[DrivenMission]) {
        if !self.config.calibrate {
            return;
        }
        let learned = drives
            .iter()
            .filter(|drive| drive.teach(&mut self.calibration))
            .count();
        if learned == 0 {
            return;
        }
        if let Some(path) = &self.config.calibration_file {
            if let Err(e) = store::save(path, &self.config.robot, &self.calibration) {
                tracing::warn!("{e}");
            }
        }
        let fitted = self.calibration.model();
        tracing::info!(
            window,
            v_lin = fitted.v_lin,
            v_ang = fitted.v_ang,
            drives = learned,
            "time model updated from the window's driving"
        );
    }
}
