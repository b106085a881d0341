//! The robots loop: true positions, estimates, missions and driven paths.

use std::sync::atomic::Ordering;
use std::sync::Arc;

use foxglove::messages::Timestamp;
use roam_proto::controller::{Mission, MAX_WAYPOINTS};
use roam_proto::localization::PositionEstimate;
use roam_proto::sim::GroundTruth;
use tokio::sync::watch;
use tokio::time::{Instant, MissedTickBehavior};
use tokio_util::sync::CancellationToken;
use zenoh::sample::Sample;

use crate::convert::{self, DrivenPath};
use crate::output::Outputs;
use crate::roster::{Roster, Touched, MAX_ROBOTS};
use crate::wire::{self, shown};

use super::limits::{DRIVEN_PERIOD, DRIVEN_POINTS, DRIVEN_STEP_M};
use super::samples::{check_robot, decode_sample, Ring, SimRobots};
use super::topics::RobotTopics;

/// One robot's driven path and whether it changed since it was last logged.
pub(super) struct LoggedPath {
    path: DrivenPath,
    dirty: bool,
}

/// True positions, estimates, missions and driven paths.
pub(super) struct Robots {
    pub(super) out: Arc<Outputs>,
    pub(super) root: String,
    pub(super) topics: RobotTopics,
    /// The robots whose missions are drawn (the drawings are kept in the latch).
    pub(super) missions: Roster<()>,
    pub(super) driven: Roster<LoggedPath>,
    pub(super) driven_dirty: bool,
    pub(super) sim: watch::Receiver<SimRobots>,
}

impl Robots {
    pub(super) async fn run(
        mut self,
        truth: Ring,
        estimate: Ring,
        mission: Ring,
        cancel: CancellationToken,
    ) {
        let mut last_driven = Instant::now();
        let mut flush = tokio::time::interval(DRIVEN_PERIOD);
        flush.set_missed_tick_behavior(MissedTickBehavior::Delay);
        loop {
            tokio::select! {
                biased;
                _ = cancel.cancelled() => break,
                sample = mission.recv_async() => match sample {
                    Ok(sample) => self.on_mission(&sample),
                    Err(_) => break,
                },
                sample = truth.recv_async() => match sample {
                    Ok(sample) => self.on_truth(&sample),
                    Err(_) => break,
                },
                sample = estimate.recv_async() => match sample {
                    Ok(sample) => self.on_estimate(&sample),
                    Err(_) => break,
                },
                _ = flush.tick() => {}
            }
            if self.driven_dirty && last_driven.elapsed() >= DRIVEN_PERIOD {
                self.log_driven();
                last_driven = Instant::now();
            }
        }
        if self.driven_dirty {
            self.log_driven();
        }
    }

    /// Counts the robots with per-robot state, for [`crate::ViewStats`].
    fn count_robots(&self) {
        let missions = &self.missions;
        let only_driven = self
            .driven
            .names()
            .filter(|robot| !missions.contains(robot))
            .count();
        self.out
            .counters
            .robots
            .store(missions.len() + only_driven, Ordering::Relaxed);
    }

    /// Whether the message about `robot` on `key` is believed (else it is counted dropped).
    fn believed(&self, key: &str, robot: &str) -> bool {
        match check_robot(&self.root, key, robot) {
            Ok(()) => true,
            Err(reason) => {
                self.out.counters.dropped(key, &reason);
                false
            }
        }
    }

    fn on_truth(&mut self, sample: &Sample) {
        let key = sample.key_expr().as_str();
        let Some(t) = decode_sample::<GroundTruth>(&self.out, sample, wire::MAX_TRUTH_BYTES) else {
            return;
        };
        if !self.believed(key, &t.robot) {
            return;
        }
        self.out
            .log(&self.topics.truth, &convert::truth(&t, Timestamp::now()));
        let sim = self.sim.borrow().clone();
        let touched = self.driven.touch(
            &t.robot,
            |r| sim.contains(r),
            || LoggedPath {
                path: DrivenPath::new(DRIVEN_POINTS, DRIVEN_STEP_M),
                dirty: false,
            },
        );
        match touched {
            Touched::Refused => return self.out.counters.dropped(key, &full(&t.robot)),
            Touched::Evicted(gone) => {
                let update = convert::driven_deleted(&gone, Timestamp::now());
                self.out.log(&self.topics.driven, &update);
                self.out.forget_robot(&self.topics.driven, &gone);
            }
            Touched::Kept => {}
        }
        if let Some(driven) = self.driven.get_mut(&t.robot) {
            let moved = driven.path.push(t.at);
            driven.dirty |= moved;
            self.driven_dirty |= moved;
        }
        self.count_robots();
    }

    fn on_estimate(&mut self, sample: &Sample) {
        let key = sample.key_expr().as_str();
        let max = wire::MAX_ESTIMATE_BYTES;
        let Some(p) = decode_sample::<PositionEstimate>(&self.out, sample, max) else {
            return;
        };
        if self.believed(key, &p.robot) {
            let update = convert::estimate(&p, Timestamp::now());
            self.out.log(&self.topics.estimate, &update);
        }
    }

    fn on_mission(&mut self, sample: &Sample) {
        let key = sample.key_expr().as_str();
        let max = wire::MAX_MISSION_BYTES;
        let Some(m) = decode_sample::<Mission>(&self.out, sample, max) else {
            return;
        };
        if !self.believed(key, &m.robot) {
            return;
        }
        // Held to the controller's own checks: the view draws what a robot would drive.
        if m.waypoints.len() > MAX_WAYPOINTS {
            let reason = format!(
                "{} waypoints; a mission holds at most {MAX_WAYPOINTS}",
                m.waypoints.len()
            );
            return self.out.counters.dropped(key, &reason);
        }
        if m.waypoints
            .iter()
            .any(|w| !(w[0].is_finite() && w[1].is_finite()))
        {
            return self
                .out
                .counters
                .dropped(key, &"a waypoint is not a finite point");
        }
        let now = Timestamp::now();
        if m.waypoints.is_empty() {
            // Stopped: the drawing goes, and so does the robot's place in the roster.
            self.missions.remove(&m.robot);
            self.out.forget_robot(&self.topics.mission, &m.robot);
            self.out.log(
                &self.topics.mission,
                &convert::mission_deleted(&m.robot, now),
            );
            return self.count_robots();
        }
        let sim = self.sim.borrow().clone();
        match self.missions.touch(&m.robot, |r| sim.contains(r), || ()) {
            Touched::Refused => return self.out.counters.dropped(key, &full(&m.robot)),
            Touched::Evicted(gone) => {
                self.out.forget_robot(&self.topics.mission, &gone);
                self.out
                    .log(&self.topics.mission, &convert::mission_deleted(&gone, now));
            }
            Touched::Kept => {}
        }
        self.out
            .log_robot(&self.topics.mission, &m.robot, &convert::mission(&m, now));
        self.count_robots();
    }

    /// Logs the path of each robot that moved since the last time (each robot's is kept
    /// for clients that subscribe later).
    fn log_driven(&mut self) {
        let now = Timestamp::now();
        let (out, topic) = (&self.out, &self.topics.driven);
        for (robot, driven) in self.driven.iter_mut() {
            if driven.dirty {
                let update = convert::driven([(robot, &driven.path)].into_iter(), now);
                out.log_robot(topic, robot, &update);
                driven.dirty = false;
            }
        }
        self.driven_dirty = false;
    }
}

fn full(robot: &str) -> String {
    format!(
        "more than {MAX_ROBOTS} robots, all named by the sim; robot \"{}\" is not drawn",
        shown(robot)
    )
}
