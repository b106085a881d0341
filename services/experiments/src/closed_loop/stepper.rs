//! A batch episode one sim step at a time, so that a caller (the mission executive's
//! day runner) can change a robot's mission between two steps, as the executive does
//! through the services when it replans, and can watch every step's messages.
//!
//! [`run_episode`](crate::closed_loop::episode::run_episode) runs the loop to its end; a [`Stepper`]
//! is the same loop cut at its steps, and nothing else: `Sim::with_params`, a
//! [`Tracker`] with the scenario's sensing model and default [`FimOptions`], and per
//! step
//!
//! 1. `sim.step(&commands)` with the commands of the last step (none on the first);
//! 2. for each robot's report, its messages ([`robot_messages`]) and the estimate from
//!    its range scan ([`Tracker::on_scan`]; a refused scan updates no controller, as the
//!    localization service publishes nothing for it);
//! 3. the update of the robot's controller, when it has one, from the estimate and its
//!    PEB or from the truth ([`PositionSource`]), and its command when the mission is
//!    Active.
//!
//! A caller that sets one mission per robot at the start and [`Stepper::retire`]s each
//! robot when `run_episode` would stop updating it gets `run_episode`'s tracks bit for
//! bit (the test below). Unlike `run_episode`, a stepper may run with the sim's
//! observation on ([`Stepper::new`] takes the sim's parameters): the observation draws
//! no random numbers and moves nothing, so the trajectories do not change (tested too).

use std::collections::BTreeMap;

use roam_localization::fim::FimOptions;
use roam_localization::Tracker;
use roam_proto::localization::PositionEstimate;
use roam_sim::messages::{robot_messages, RobotMessages};
use roam_sim::{Command, Sim, SimParams};

use crate::closed_loop::setup::{EpisodeError, PositionSource, Setup};
use roam_controller::controller::{Controller, Decision, MissionState};
use roam_controller::params::ApfParams;

/// What one robot did in one step.
#[derive(Debug, Clone)]
pub struct RobotStep {
    pub robot: String,
    /// What the sim published for it this step: ranges, truth, observation, events.
    pub messages: RobotMessages,
    /// The localization's estimate from the ranges; `None` when the scan was refused.
    pub estimate: Option<PositionEstimate>,
    /// Its controller's decision on this step's update; `None` without a controller (no
    /// mission was ever set, or it was retired) or when the scan was refused.
    pub decision: Option<Decision>,
}

/// One step of every robot.
#[derive(Debug, Clone)]
pub struct StepOutcome {
    /// The sim step just taken (1 for the first) and the sim time at its end, seconds.
    pub step: u64,
    pub time_s: f64,
    pub robots: Vec<RobotStep>,
}

/// An episode advanced step by step (module doc).
#[derive(Debug, Clone)]
pub struct Stepper {
    setup: Setup,
    params: ApfParams,
    source: PositionSource,
    sim: Sim,
    tracker: Tracker,
    controllers: BTreeMap<String, Controller>,
    /// The commands the next step applies: the last step's decisions.
    commands: Vec<Command>,
    /// Scans localization refused (not a missing fix: an error, such as a range that is
    /// not finite), and the first refusal's message: the step goes on without an
    /// estimate, as the live service's does, and the reports show the count.
    pub localization_errors: u64,
    pub first_localization_error: Option<String>,
}

impl Stepper {
    /// A stepper on `setup`'s scenario with the sim's parameters `sim_params` (e.g.
    /// `setup.sim_params`, or the scenario's own with its observation on), the
    /// controllers' `params`, and seed `seed`. No robot has a mission yet.
    pub fn new(
        setup: &Setup,
        sim_params: roam_sim::SimParams,
        params: &ApfParams,
        source: PositionSource,
        seed: u64,
    ) -> Result<Stepper, EpisodeError> {
        params.check()?;
        let sim = Sim::with_params(&setup.scenario, sim_params, seed)?;
        Ok(Stepper {
            setup: setup.clone(),
            params: params.clone(),
            source,
            sim,
            tracker: Tracker::new(setup.scenario.file.sensing, FimOptions::default()),
            controllers: BTreeMap::new(),
            commands: Vec::new(),
            localization_errors: 0,
            first_localization_error: None,
        })
    }

    /// The scenario's sim parameters with its observation as the file gives it (the sim
    /// service's), where [`Setup::new`] turns it off.
    pub fn observing(setup: &Setup) -> SimParams {
        SimParams::from_file(&setup.scenario.file)
    }

    /// Gives `robot` a new mission, at once: its controller's next update drives it
    /// ([`Controller::set_mission`]; an empty one makes it idle, so it is held). The
    /// command already decided for the next step is the old mission's, as a mission
    /// sent to the controller service takes effect at its next estimate.
    pub fn set_mission(
        &mut self,
        robot: &str,
        waypoints: Vec<[f64; 2]>,
    ) -> Result<(), EpisodeError> {
        self.controller_of(robot)?.set_mission(waypoints);
        Ok(())
    }

    /// Gives `robot` a recovery mission ([`Controller::set_recovery`]: the PEB guard
    /// does not hold it), as a mission with `recovery: true` to the controller service.
    pub fn set_recovery(
        &mut self,
        robot: &str,
        waypoints: Vec<[f64; 2]>,
    ) -> Result<(), EpisodeError> {
        self.controller_of(robot)?.set_recovery(waypoints);
        Ok(())
    }

    fn controller_of(&mut self, robot: &str) -> Result<&mut Controller, EpisodeError> {
        if self.sim.robot(robot).is_none() {
            return Err(EpisodeError::UnknownRobot(robot.to_owned()));
        }
        let (params, setup) = (&self.params, &self.setup);
        Ok(self.controllers.entry(robot.to_owned()).or_insert_with(|| {
            Controller::new(
                params.clone(),
                setup.obstacles.clone(),
                setup.information.clone(),
            )
        }))
    }

    /// Takes `robot`'s controller away: it is updated no more and gets no commands
    /// after the one already decided (as `run_episode` treats a robot that is done).
    pub fn retire(&mut self, robot: &str) -> Option<Controller> {
        self.controllers.remove(robot)
    }

    /// `robot`'s controller, when it has one.
    pub fn controller(&self, robot: &str) -> Option<&Controller> {
        self.controllers.get(robot)
    }

    pub fn sim(&self) -> &Sim {
        &self.sim
    }

    /// One step (module doc).
    pub fn step(&mut self) -> Result<StepOutcome, EpisodeError> {
        let commands = std::mem::take(&mut self.commands);
        let report = self.sim.step(&commands)?;
        let mut robots = Vec::with_capacity(report.robots.len());
        for r in &report.robots {
            let messages = robot_messages(&self.sim, report.step, report.time_s, r);
            let estimate = match self.tracker.on_scan(&messages.ranges) {
                Ok(estimate) => Some(estimate),
                Err(e) => {
                    self.localization_errors += 1;
                    self.first_localization_error
                        .get_or_insert_with(|| format!("{}: {e}", r.name));
                    None
                }
            };
            let decision = match (&estimate, self.controllers.get_mut(r.name.as_str())) {
                (Some(e), Some(controller)) => {
                    let truth = r.readings.truth;
                    let (position, peb) = match self.source {
                        PositionSource::Estimate => (e.position, e.peb_m),
                        PositionSource::Truth => (truth, self.setup.information.peb_m(truth)),
                    };
                    Some(controller.update(position, peb))
                }
                _ => None,
            };
            if let Some(d) = decision.filter(|d| d.status == MissionState::Active) {
                self.commands.push(Command {
                    robot: r.name.clone(),
                    u: d.u,
                });
            }
            robots.push(RobotStep {
                robot: r.name.clone(),
                messages,
                estimate,
                decision,
            });
        }
        Ok(StepOutcome {
            step: report.step,
            time_s: report.time_s,
            robots,
        })
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::closed_loop::episode::{
        load_scenario, mission_from_waypoints, run_episode, run_episode_with, Episode,
        RobotMission, RobotTrack,
    };
    use roam_controller::params::Follow;
    use roam_sim::messages::robot_messages;
    use roam_sim::Sim;

    fn scenario(file: &str) -> Setup {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../config/scenarios")
            .join(file);
        Setup::new(&load_scenario(&path).expect("scenario")).expect("setup")
    }

    struct EpisodeRobot {
        index: usize,
        controller: Controller,
        track: RobotTrack,
        done: bool,
    }

    /// The episode loop as paper 002's experiments were first written here, on the sim,
    /// tracker and controllers directly: the reference [`run_episode`] (now a stepper
    /// driven to the end) must match bit for bit.
    fn loop_episode(
        setup: &Setup,
        params: &ApfParams,
        source: PositionSource,
        missions: &[RobotMission],
        seed: u64,
    ) -> Result<Episode, EpisodeError> {
        params.check()?;
        let mut sim = Sim::with_params(&setup.scenario, setup.sim_params, seed)?;
        let mut tracker = Tracker::new(setup.scenario.file.sensing, FimOptions::default());
        let mut driven: BTreeMap<&str, EpisodeRobot> = BTreeMap::new();
        for (index, m) in missions.iter().enumerate() {
            if sim.robot(&m.robot).is_none() {
                return Err(EpisodeError::UnknownRobot(m.robot.clone()));
            }
            let mut controller = Controller::new(
                params.clone(),
                setup.obstacles.clone(),
                setup.information.clone(),
            );
            controller.set_mission(m.waypoints.clone());
            let d = EpisodeRobot {
                index,
                done: !controller.is_active(),
                controller,
                track: RobotTrack {
                    robot: m.robot.clone(),
                    waypoints: m.waypoints.clone(),
                    status: MissionState::Idle,
                    success: m.waypoints.is_empty(),
                    steps: 0,
                    distance_m: 0.0,
                    truth: Vec::new(),
                    estimate: Vec::new(),
                    error_m: Vec::new(),
                    held_updates: 0,
                },
            };
            if driven.insert(m.robot.as_str(), d).is_some() {
                return Err(EpisodeError::DuplicateMission(m.robot.clone()));
            }
        }
        let max_sim_steps = params.max_steps.saturating_add(1);
        let mut report = sim.step(&[])?;
        loop {
            let mut commands = Vec::new();
            for r in &report.robots {
                let messages = robot_messages(&sim, report.step, report.time_s, r);
                // The localization service ignores a scan it refuses; so does the episode.
                let Ok(estimate) = tracker.on_scan(&messages.ranges) else {
                    continue;
                };
                let Some(d) = driven.get_mut(r.name.as_str()) else {
                    continue;
                };
                if d.done {
                    continue;
                }
                let truth = r.readings.truth;
                let (position, peb) = match source {
                    PositionSource::Estimate => (estimate.position, estimate.peb_m),
                    PositionSource::Truth => (truth, setup.information.peb_m(truth)),
                };
                let decision = d.controller.update(position, peb);
                d.done = d.track.record(
                    truth,
                    estimate.position,
                    &decision,
                    params.stuck_window_steps,
                );
                if decision.status == MissionState::Active {
                    commands.push(Command {
                        robot: r.name.clone(),
                        u: decision.u,
                    });
                }
            }
            if driven.values().all(|d| d.done) || sim.steps() >= max_sim_steps {
                break;
            }
            report = sim.step(&commands)?;
        }
        let sim_steps = sim.steps();
        let mut robots: Vec<(usize, RobotTrack)> =
            driven.into_values().map(|d| (d.index, d.track)).collect();
        robots.sort_by_key(|(i, _)| *i);
        Ok(Episode {
            seed,
            source,
            sim_steps,
            localization_errors: 0,
            robots: robots.into_iter().map(|(_, t)| t).collect(),
        })
    }

    #[test]
    fn run_episode_on_a_stepper_gives_the_first_loops_tracks_bit_for_bit() {
        let es1 = scenario("es1.yaml");
        let paper = ApfParams {
            max_steps: 600,
            ..ApfParams::default()
        };
        let m = mission_from_waypoints(&es1, "robot", paper.g_thres_m, false).expect("mission");
        for (seed, source) in [
            (1, PositionSource::Estimate),
            (2, PositionSource::Estimate),
            (3, PositionSource::Truth),
        ] {
            let a =
                run_episode(&es1, &paper, source, std::slice::from_ref(&m), seed).expect("episode");
            let b = loop_episode(&es1, &paper, source, std::slice::from_ref(&m), seed);
            assert_eq!(a, b.expect("episode"), "ES1, seed {seed}");
            assert!(a.robots[0].steps > 50, "it drove");
        }
        // The built-in world's robot along a U (indoor, path following) and along the
        // same waypoints one by one: a mission of many waypoints.
        let downtime = scenario("downtime.yaml");
        let u = RobotMission {
            robot: "robot".into(),
            waypoints: vec![[-8.0, -4.0], [-6.0, -4.0], [-6.0, -8.0], [-3.0, -8.0]],
        };
        for follow in [Follow::Path, Follow::Waypoints] {
            let indoor = ApfParams {
                follow,
                ..ApfParams::indoor()
            };
            let a = run_episode(
                &downtime,
                &indoor,
                PositionSource::Estimate,
                std::slice::from_ref(&u),
                7,
            )
            .expect("episode");
            let b = loop_episode(
                &downtime,
                &indoor,
                PositionSource::Estimate,
                std::slice::from_ref(&u),
                7,
            );
            assert_eq!(a, b.expect("episode"), "{follow:?}");
            assert!(a.success(), "{follow:?}");
        }
    }

    #[test]
    fn the_observation_changes_no_trajectory_and_a_new_mission_takes_effect_at_once() {
        let day = scenario("day.yaml");
        let indoor = ApfParams::indoor();
        let to = RobotMission {
            robot: "robot".into(),
            waypoints: vec![[-8.0, -4.0], [-4.0, -4.0]],
        };
        let quiet = run_episode(
            &day,
            &indoor,
            PositionSource::Estimate,
            std::slice::from_ref(&to),
            3,
        )
        .expect("episode");
        let watched = Stepper::observing(&day);
        assert!(
            watched.sensing.observation_radius_m > 0.0,
            "day.yaml observes"
        );
        let seen = run_episode_with(
            &day,
            watched,
            &indoor,
            PositionSource::Estimate,
            std::slice::from_ref(&to),
            3,
        )
        .expect("episode");
        assert_eq!(quiet, seen);

        // Midway, a new mission back to the start: the robot turns around.
        let mut s =
            Stepper::new(&day, watched, &indoor, PositionSource::Estimate, 3).expect("stepper");
        s.set_mission("robot", to.waypoints.clone())
            .expect("mission");
        let mut observed = 0;
        for _ in 0..10 {
            let out = s.step().expect("step");
            observed += usize::from(out.robots[0].messages.observation.is_some());
        }
        assert_eq!(observed, 10, "every step carries the robot's observation");
        s.set_mission("robot", vec![[-8.0, -8.0]]).expect("mission");
        let mut last = None;
        for _ in 0..200 {
            let out = s.step().expect("step");
            last = out.robots[0].decision;
            if last.is_some_and(|d| d.status.is_final()) {
                break;
            }
        }
        assert_eq!(last.map(|d| d.status), Some(MissionState::Completed));
        let at = s.sim().robot("robot").expect("robot").position();
        assert!(
            (at[0] + 8.0).hypot(at[1] + 8.0) < 0.2,
            "back at the start: {at:?}"
        );
        assert!(matches!(
            s.set_mission("nobody", Vec::new()),
            Err(EpisodeError::UnknownRobot(_))
        ));
    }
}
