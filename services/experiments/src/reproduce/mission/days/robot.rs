//! The day's robot as the services run it: the sim, localization's tracker and the APF
//! controller one step at a time ([`Stepper`]), and the mapper's [`ChangeMap`] fed the
//! robot's observation every step. Mission time is sim time.

use crate::closed_loop::setup::EpisodeError;
use crate::closed_loop::stepper::Stepper;
use crate::closed_loop::PositionSource;
use crate::reproduce::executive::Step;
use roam_controller::params::ApfParams;
use roam_mapper::change_map::{ChangeMap, MapParams, ObservationWindow};

use super::error::DaysError;
use super::world::DayWorld;
use roam_proto::controller::Mission;

/// One robot through its day.
#[derive(Debug)]
pub struct Robot {
    name: String,
    stepper: Stepper,
    change: ChangeMap,
    now_s: f64,
    /// The last estimate that was not degraded.
    position: Option<[f64; 2]>,
    /// The ranges of the day's first scan (the common random numbers' check).
    first_ranges: Vec<f64>,
}

impl Robot {
    /// The robot at its start, the sim seeded with `sim_seed`, the controller with
    /// `apf`; no step taken yet.
    pub fn new(world: &DayWorld, apf: &ApfParams, sim_seed: u64) -> Result<Robot, DaysError> {
        let stepper = Stepper::new(
            &world.setup,
            world.sim_params,
            apf,
            PositionSource::Estimate,
            sim_seed,
        )?;
        let change = ChangeMap::new(
            world.setup.scenario.occupancy.meta,
            MapParams {
                observation_period_s: world.step_s,
                ..MapParams::default()
            },
        )
        .map_err(|e| DaysError::Mapper(e.to_string()))?;
        Ok(Robot {
            name: world.robot.clone(),
            stepper,
            change,
            now_s: 0.0,
            position: None,
            first_ranges: Vec::new(),
        })
    }

    pub fn now_s(&self) -> f64 {
        self.now_s
    }

    /// The last estimate that was not degraded.
    pub fn position(&self) -> Option<[f64; 2]> {
        self.position
    }

    pub fn change_map(&self) -> &ChangeMap {
        &self.change
    }

    /// Scans localization refused so far (the stepper's count).
    pub fn localization_errors(&self) -> u64 {
        self.stepper.localization_errors
    }

    pub fn first_ranges(&self) -> &[f64] {
        &self.first_ranges
    }

    /// Sends the controller a mission (an empty one holds the robot), as the
    /// executive's `mission` message does.
    pub fn send(&mut self, mission: &Mission) -> Result<(), EpisodeError> {
        if mission.recovery {
            self.stepper
                .set_recovery(&self.name, mission.waypoints.clone())?;
        } else {
            self.stepper
                .set_mission(&self.name, mission.waypoints.clone())?;
        }
        Ok(())
    }

    /// One sim step: the sim moves the robot by the last command, localization
    /// estimates, the controller decides, the mapper observes.
    pub fn step(&mut self) -> Result<Step, DaysError> {
        let out = self.stepper.step()?;
        self.now_s = out.time_s;
        let Some(r) = out.robots.into_iter().find(|r| r.robot == self.name) else {
            return Err(DaysError::World(format!(
                "the sim has no robot {:?}",
                self.name
            )));
        };
        if self.first_ranges.is_empty() {
            self.first_ranges = r.messages.ranges.ranges.iter().map(|a| a.range_m).collect();
        }
        if let Some(o) = &r.messages.observation {
            if let Some(window) = ObservationWindow::from_wire(o) {
                self.change
                    .observe(&window, out.time_s)
                    .map_err(|e| DaysError::Mapper(e.to_string()))?;
            }
        }
        if let Some(e) = r.estimate.as_ref().filter(|e| !e.degraded) {
            self.position = Some(e.position);
        }
        Ok(Step {
            time_s: out.time_s,
            truth: r.messages.truth.at,
            estimate: r.estimate,
            decision: r.decision,
        })
    }
}
