//! The sim: a world and its robots, stepped explicitly, deterministic from a seed.

use std::collections::BTreeMap;
use std::sync::Arc;

use roam_world::scenario::{
    MotionModel, MotionSpec, Scenario, ScenarioFile, SensingSpec, TimeSpec,
};
use serde::Serialize;

use crate::event::Event;
use crate::los::LosTable;
use crate::robot::{step_motion, Resumed, Robot};
use crate::sensors::{self, Readings};
use crate::snapshot::{RobotState, SimSnapshot};
use crate::unicycle::Unicycle;
use crate::world::{Anchor, Obstacle, World, WorldError};
use roam_world::noise;

/// The most robots one sim holds (limit `max_robots`): each costs a stream, a report
/// per step and its sensing, so a client cannot grow the sim without bound.
pub const MAX_ROBOTS: usize = 1000;

/// The longest robot name, in bytes (limit `max_robot_name_bytes`).
pub const MAX_ROBOT_NAME_BYTES: usize = 64;

/// The sim's parameters: the scenario's `sensing`, `motion` and `time` sections, or
/// anything else a batch experiment sets in code.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimParams {
    pub sensing: SensingSpec,
    pub motion: MotionSpec,
    pub time: TimeSpec,
}

impl SimParams {
    /// The parameters a scenario file gives (its defaults where it is silent).
    pub fn from_file(file: &ScenarioFile) -> SimParams {
        SimParams {
            sensing: file.sensing,
            motion: file.motion,
            time: file.time,
        }
    }

    /// Checks every field as a scenario file's are checked; `resolution` is the map's.
    pub fn check(&self, resolution: f64) -> Result<(), SimError> {
        let param = |i: roam_world::scenario::FieldIssue| SimError::Param {
            field: i.field,
            reason: i.reason,
        };
        self.sensing.check(resolution).map_err(param)?;
        self.motion.check().map_err(param)?;
        self.time.check().map_err(param)
    }
}

/// A motion command for one robot: `u` in paper 002 Eq. 1 (the point robot moves μ·u,
/// at most the top speed; the unicycle turns toward u and drives, see
/// [`crate::unicycle`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Command {
    pub robot: String,
    pub u: [f64; 2],
}

/// What one robot did and sensed in a step.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RobotReport {
    pub name: String,
    /// What happened to it, in order (displaced, speed clipped, collision).
    pub events: Vec<Event>,
    pub readings: Readings,
}

/// The result of one step.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StepReport {
    /// The step just taken: 1 for the first.
    pub step: u64,
    /// Sim time at the end of the step: `step · time.step_s`, seconds.
    pub time_s: f64,
    /// Every robot, by name.
    pub robots: Vec<RobotReport>,
}

/// Why the sim refused something. Nothing changes when a call is refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    #[error("parameter {field}: {reason}")]
    Param { field: String, reason: String },
    #[error("{0}")]
    World(#[from] WorldError),
    #[error("robot '{robot}' at ({x}, {y}): {reason}")]
    BadStart {
        robot: String,
        x: f64,
        y: f64,
        reason: String,
    },
    #[error("robot name '{0}': a name is 1 to {MAX_ROBOT_NAME_BYTES} bytes (limit max_robot_name_bytes)")]
    BadName(String),
    #[error("there is no robot named '{0}'")]
    UnknownRobot(String),
    #[error("a robot named '{0}' already exists")]
    DuplicateRobot(String),
    #[error("the sim holds at most {max} robots (limit max_robots)")]
    TooManyRobots { max: usize },
    #[error("robot '{robot}': the command u = {u:?} must be two finite numbers")]
    BadCommand { robot: String, u: [f64; 2] },
    #[error("robot '{0}' has more than one command in one step")]
    DuplicateCommand(String),
}

/// The sim world: a scenario's world and robots, stepped by [`Sim::step`].
///
/// **Determinism.** Every random draw comes from a ChaCha8 stream derived from the seed:
/// one for the world (walkers) and one per robot, named by the robot's name (its
/// transition noise and its range noise). A robot draws the same number of values every
/// step (two for its motion, one per anchor), commanded or not, in range or not. So the
/// same seed and the same commands give the same reports bit for bit, after a reset
/// too, and adding or removing a robot changes no other robot's noise. (The bits rely on
/// the platform's `ln`, `sqrt` and `cos`; they are the same on one machine.)
#[derive(Debug, Clone)]
pub struct Sim {
    scenario: Scenario,
    params: SimParams,
    world: World,
    robots: BTreeMap<String, Robot>,
    /// Shared: the table is the same for every clone of a sim (up to tens of MB).
    los: Option<Arc<LosTable>>,
    seed: u64,
}

impl Sim {
    /// The scenario's world and robots at step 0, with the scenario's parameters.
    pub fn new(scenario: &Scenario, seed: u64) -> Result<Sim, SimError> {
        Sim::with_params(scenario, SimParams::from_file(&scenario.file), seed)
    }

    /// The scenario's world and robots at step 0, with parameters set in code.
    pub fn with_params(scenario: &Scenario, params: SimParams, seed: u64) -> Result<Sim, SimError> {
        let meta = scenario.occupancy.meta;
        params.check(meta.resolution)?;
        let radius_cells = params.sensing.observation_radius_m / meta.resolution;
        let mut sim = Sim {
            scenario: scenario.clone(),
            params,
            world: World::new(scenario, seed)?,
            robots: BTreeMap::new(),
            los: (radius_cells > 0.0).then(|| Arc::new(LosTable::new(radius_cells))),
            seed,
        };
        for robot in &scenario.file.robots {
            sim.add_robot_facing(&robot.name, robot.at, robot.heading_rad)?;
        }
        Ok(sim)
    }

    /// Back to step 0 with a new seed: the clock, the blocks and walkers, every robot
    /// (those added since the start too) at its start, every stream restarted. A robot
    /// whose start a block now covers is put on the nearest free cell, and the next
    /// step reports it.
    pub fn reset(&mut self, seed: u64) {
        self.seed = seed;
        self.world.reset(seed);
        for robot in self.robots.values_mut() {
            robot.reset(seed);
            if let Some(event) = displace(&self.world, robot) {
                robot.pending.push(event);
            }
        }
    }

    /// Adds a robot at `at` (world metres), which must be a free cell now, facing +x.
    /// Its stream is derived from the seed and its name, so a robot removed and added
    /// again under the same name draws the same noise again.
    pub fn add_robot(&mut self, name: &str, at: [f64; 2]) -> Result<(), SimError> {
        self.add_robot_facing(name, at, 0.0)
    }

    /// [`Sim::add_robot`] facing `heading_rad` (radians counter-clockwise from +x; only
    /// a unicycle turns and uses it).
    pub fn add_robot_facing(
        &mut self,
        name: &str,
        at: [f64; 2],
        heading_rad: f64,
    ) -> Result<(), SimError> {
        if name.is_empty() || name.len() > MAX_ROBOT_NAME_BYTES {
            return Err(SimError::BadName(name.to_owned()));
        }
        if self.robots.contains_key(name) {
            return Err(SimError::DuplicateRobot(name.to_owned()));
        }
        if self.robots.len() >= MAX_ROBOTS {
            return Err(SimError::TooManyRobots { max: MAX_ROBOTS });
        }
        let bad = |reason: String| SimError::BadStart {
            robot: name.to_owned(),
            x: at[0],
            y: at[1],
            reason,
        };
        if !(at[0].is_finite() && at[1].is_finite()) {
            return Err(bad("the position must be two finite numbers".into()));
        }
        if !heading_rad.is_finite() {
            return Err(bad(format!(
                "the heading must be a finite number of radians, got {heading_rad}"
            )));
        }
        let Some(cell) = self.world.cell_of(at) else {
            return Err(bad("the position is outside the map".into()));
        };
        if let Some(obstacle) = self.world.obstacle_at(cell) {
            return Err(bad(format!(
                "the cell is taken ({}); a robot starts on a free cell",
                describe(&obstacle)
            )));
        }
        self.robots.insert(
            name.to_owned(),
            Robot::new(name, at, heading_rad, self.seed),
        );
        Ok(())
    }

    /// Removes a robot.
    pub fn remove_robot(&mut self, name: &str) -> Result<(), SimError> {
        self.robots
            .remove(name)
            .map(|_| ())
            .ok_or_else(|| SimError::UnknownRobot(name.to_owned()))
    }

    /// One step: the world moves (blocks to their scripted positions, walkers at
    /// random), robots that a block or walker came onto are put on a free cell, every
    /// robot moves by its command (no command: it stays), then senses. Commands are
    /// all checked first; a refused step changes nothing.
    pub fn step(&mut self, commands: &[Command]) -> Result<StepReport, SimError> {
        let mut u_of: BTreeMap<&str, [f64; 2]> = BTreeMap::new();
        for c in commands {
            if !self.robots.contains_key(&c.robot) {
                return Err(SimError::UnknownRobot(c.robot.clone()));
            }
            if !(c.u[0].is_finite() && c.u[1].is_finite()) {
                return Err(SimError::BadCommand {
                    robot: c.robot.clone(),
                    u: c.u,
                });
            }
            if u_of.insert(&c.robot, c.u).is_some() {
                return Err(SimError::DuplicateCommand(c.robot.clone()));
            }
        }
        let robot_cells: Vec<_> = self
            .robots
            .values()
            .filter_map(|r| self.world.cell_of(r.position()))
            .collect();
        self.world.advance(&robot_cells);
        let (world, params, los) = (&self.world, &self.params, &self.los);
        let unicycle = match &params.motion.model {
            MotionModel::Point => None,
            MotionModel::Unicycle(spec) => Some(Unicycle::new(&params.motion, spec, &params.time)),
        };
        let meta = *world.meta();
        let mut reports = Vec::with_capacity(self.robots.len());
        for (name, robot) in &mut self.robots {
            let mut events = std::mem::take(&mut robot.pending);
            events.extend(displace(world, robot));
            let nu = noise::transition(params.motion.sigma_tr_m, robot.rng());
            let u = u_of.get(name.as_str()).copied().unwrap_or([0.0, 0.0]);
            let moved = match &unicycle {
                None => step_motion(robot.position(), u, nu, &params.motion, world),
                Some(model) => {
                    let stepped = model.step(robot.position(), robot.heading_rad(), u, nu, world);
                    robot.set_heading(stepped.heading);
                    stepped.moved
                }
            };
            robot.set_position(moved.at);
            events.extend(moved.events);
            let at = robot.position();
            let ranges = sensors::ranges(at, world.anchors(), &params.sensing, robot.rng());
            let observation = los.as_ref().and_then(|table| {
                let cell = world.cell_of(at)?;
                Some(table.observe(cell, meta.width, meta.height, |c| world.is_blocked(c)))
            });
            reports.push(RobotReport {
                name: name.clone(),
                events,
                readings: Readings {
                    truth: at,
                    heading_rad: unicycle.is_some().then(|| robot.heading_rad()),
                    ranges,
                    observation,
                },
            });
        }
        Ok(StepReport {
            step: self.world.step(),
            time_s: self.time_s(),
            robots: reports,
        })
    }

    /// Whether the robots are unicycles (they have a heading that matters).
    fn has_heading(&self) -> bool {
        matches!(self.params.motion.model, MotionModel::Unicycle(_))
    }

    /// What a snapshot keeps of this sim (see [`crate::snapshot`]): the headings too
    /// when the robots are unicycles (a point robot's snapshot is what it always was).
    pub fn snapshot(&self, scenario: &str) -> SimSnapshot {
        let heading = self.has_heading();
        let robots = self
            .robots
            .values()
            .map(|r| RobotState {
                name: r.name().to_owned(),
                start: r.start(),
                at: r.position(),
                start_heading_rad: heading.then(|| r.start_heading_rad()),
                heading_rad: heading.then(|| r.heading_rad()),
            })
            .collect();
        SimSnapshot::new(scenario, self.seed, self.steps(), robots)
    }

    /// Back to where `snapshot` was taken: the world replayed to its step, its robots
    /// (and only those) at their positions and headings, their streams restarted from
    /// the step. The snapshot's seed becomes the sim's. A snapshot without headings (a
    /// point robot's, or one written before headings were kept) starts each robot at the
    /// scenario's heading for its name (0 for a robot the scenario does not name), and
    /// facing its start heading.
    pub fn resume(&mut self, snapshot: &SimSnapshot) -> Result<(), SimError> {
        if snapshot.robots.len() > MAX_ROBOTS {
            return Err(SimError::TooManyRobots { max: MAX_ROBOTS });
        }
        for r in &snapshot.robots {
            if r.name.is_empty() || r.name.len() > MAX_ROBOT_NAME_BYTES {
                return Err(SimError::BadName(r.name.clone()));
            }
            let headings = r.start_heading_rad.iter().chain(&r.heading_rad);
            if !r
                .at
                .iter()
                .chain(&r.start)
                .chain(headings)
                .all(|v| v.is_finite())
            {
                return Err(SimError::BadStart {
                    robot: r.name.clone(),
                    x: r.at[0],
                    y: r.at[1],
                    reason: "the snapshot's position or heading is not finite".into(),
                });
            }
        }
        self.seed = snapshot.seed;
        self.world.reset(snapshot.seed);
        let starts: Vec<_> = snapshot
            .robots
            .iter()
            .filter_map(|r| self.world.cell_of(r.start))
            .collect();
        for _ in 0..snapshot.step {
            self.world.advance(&starts);
        }
        self.robots.clear();
        for r in &snapshot.robots {
            let start_heading = r.start_heading_rad.unwrap_or_else(|| {
                self.scenario
                    .file
                    .robots
                    .iter()
                    .find(|s| s.name == r.name)
                    .map_or(0.0, |s| s.heading_rad)
            });
            let pose = Resumed {
                start: r.start,
                at: r.at,
                start_heading,
                heading: r.heading_rad.unwrap_or(start_heading),
            };
            let mut robot = Robot::new(&r.name, r.start, start_heading, snapshot.seed);
            robot.resume(pose, snapshot.seed, snapshot.step);
            self.robots.insert(r.name.clone(), robot);
        }
        Ok(())
    }

    /// The seed of the last `new` or `reset`.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Steps taken since the last `new` or `reset`.
    pub fn steps(&self) -> u64 {
        self.world.step()
    }

    /// Sim time: `steps · time.step_s`, seconds.
    pub fn time_s(&self) -> f64 {
        self.world.step() as f64 * self.params.time.step_s
    }

    pub fn params(&self) -> &SimParams {
        &self.params
    }

    /// The scenario as loaded: its file (waypoints, places, zones) and its grids.
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }

    /// The world: grid, anchors, blocks, walkers, occupancy queries.
    pub fn world(&self) -> &World {
        &self.world
    }

    pub fn anchors(&self) -> &[Anchor] {
        self.world.anchors()
    }

    /// The occupancy now: the static map with every block and walker on it.
    pub fn occupancy(&self) -> roam_world::grid::Grid<i8> {
        self.world.occupancy(&self.scenario.occupancy)
    }

    /// Every robot, by name.
    pub fn robots(&self) -> impl Iterator<Item = &Robot> {
        self.robots.values()
    }

    pub fn robot(&self, name: &str) -> Option<&Robot> {
        self.robots.get(name)
    }
}

/// Puts a robot whose cell is taken on the centre of the nearest free cell.
fn displace(world: &World, robot: &mut Robot) -> Option<Event> {
    let from = robot.position();
    let cell = world.cell_of(from);
    let by = match cell {
        None => Obstacle::OffMap,
        Some(c) => world.obstacle_at(c)?,
    };
    match cell.and_then(|c| world.nearest_free(c)) {
        Some(free) => {
            let to = world.centre_of(free);
            robot.set_position(to);
            Some(Event::Displaced { from, to, by })
        }
        None => Some(Event::Trapped { by }),
    }
}

fn describe(obstacle: &Obstacle) -> String {
    match obstacle {
        Obstacle::Wall => "an occupied or unknown cell of the map".into(),
        Obstacle::Block(name) => format!("block '{name}'"),
        Obstacle::Walker(name) => format!("walker '{name}'"),
        Obstacle::Object(zone) => format!("an object of zone '{zone}'"),
        Obstacle::OffMap => "outside the map".into(),
    }
}
