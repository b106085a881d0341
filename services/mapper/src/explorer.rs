//! The per-robot loop of paper 004 §2 and §4: the learning agent picks a strategy and a
//! goal, the grid controller drives there and explores locally, and after `max_steps`
//! steps the episode's reward updates the learner. The batch experiment and the Zenoh
//! service both run this, one [`Explorer`] per robot, calling
//! [`Explorer::on_update`] once per sensor update with the map after the update; each
//! call answers the robot's next unit command.
//!
//! **An episode** (one iteration of §4's loop):
//! 1. The strategy: uniformly at random for the first episode (curious mode), then by
//!    the learner's softmax at the features of the update that ended the previous one;
//!    fixed in the single-strategy modes, 50/50 every episode in the uniform mix. Every
//!    mode draws exactly one number per episode for it ([`Strategy::pick`]).
//! 2. The goal: sampled from the strategy's weights (recency r^c or P_c(E > 0)) over
//!    patches ([`crate::goals`]).
//! 3. Navigation: one wavefront step per update toward the goal, or as close as
//!    possible ([`crate::wavefront`]).
//! 4. Local exploration, once the target is reached (§2): if the last update changed
//!    the map, the next goal is the centroid of the changed cells (rounded to a cell)
//!    and the robot steps toward it; if nothing changed (or the robot already stands on
//!    the centroid's target), one random step to a 4-neighbour not known occupied.
//!    Never two random steps in a row (§5): where a second one would come, the robot
//!    instead *waits* one step and keeps looking (the default, [`AfterRandomStep::Wait`]:
//!    a block that passes by is then seen and followed), or the episode ends early
//!    ([`AfterRandomStep::EndEpisode`]: the local area is taken as explored). The paper
//!    bounds consecutive random steps but does not say what happens at the bound.
//! 5. Every command counts as a step, waiting too; after `max_steps` (42, §5) the
//!    episode ends: its trajectory T holds the features (p, r) after each of its
//!    updates, its reward is R = map changes during the episode / |T|, and the learner
//!    updates V_S over T.
//!
//! The robot's cell is given by the caller: paper 004 uses noise-free odometry (the batch
//! experiment passes the sim's true pose, the service the pose an observation carries).
//!
//! **Random streams.** Each kind of draw has its own labelled stream of the explorer's
//! seed ([`crate::seed`]): `"tiles"` (the tilings' offsets), `"explorer/strategy"` (one
//! draw per episode), `"explorer/goals"` (goal sampling) and `"explorer/steps"` (local
//! random steps). Two explorers with one seed in different modes then see the same
//! numbers for the same purpose: episode k's strategy draw is the same number in
//! every mode, and until their choices part, their goals and random steps are too
//! (common random numbers, see [`crate::experiment`]).

use rand::{Rng, RngCore};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::change_map::{ChangeMap, Update};
use crate::error::MapperError;
use crate::features::Features;
use crate::goals::{sample_goal, DEFAULT_PATCH_CELLS};
use crate::learner::{Learner, LearnerParams};
pub use crate::learner::{Mode, Strategy};
use crate::seed;
use crate::wavefront::{Wavefront, NEIGHBOURS};

/// The longest episode (limit `max_episode_steps`): the trajectory is kept in memory.
pub const MAX_EPISODE_STEPS: u32 = 100_000;
/// The largest patch side, cells (limit `max_patch_cells`).
pub const MAX_PATCH_CELLS: u32 = 1024;

/// What happens where a second random step in a row would come.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AfterRandomStep {
    /// Stand still for one step and keep looking.
    Wait,
    /// End the episode now: the local area is explored.
    EndEpisode,
}

/// The explorer's parameters (paper 004's values where it gives them).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExplorerParams {
    /// Steps per episode (§5: 42, the longest path of a block in the grid world).
    pub max_steps: u32,
    /// Side of the goal distribution's patches, cells (paper: not given; see
    /// [`crate::goals`]).
    pub patch_cells: u32,
    /// Whether discovering an unknown cell is a map change (for the reward and the
    /// local exploration centroid), besides a known cell flipping.
    pub count_discoveries: bool,
    /// See [`AfterRandomStep`].
    pub after_random_step: AfterRandomStep,
    /// The length of the command `u` that moves the robot one cell: the cell size over
    /// the sim's μ (grid world: 1 m / 1.0 = 1).
    pub cell_command: f64,
    pub learner: LearnerParams,
}

impl Default for ExplorerParams {
    fn default() -> Self {
        ExplorerParams {
            max_steps: 42,
            patch_cells: DEFAULT_PATCH_CELLS,
            count_discoveries: true,
            after_random_step: AfterRandomStep::Wait,
            cell_command: 1.0,
            learner: LearnerParams::default(),
        }
    }
}

impl ExplorerParams {
    pub fn check(&self) -> Result<(), MapperError> {
        let bad = |field: &'static str, reason: String| Err(MapperError::Param { field, reason });
        if self.max_steps == 0 || self.max_steps > MAX_EPISODE_STEPS {
            return bad(
                "max_steps",
                format!(
                    "must be 1 to {MAX_EPISODE_STEPS} (limit max_episode_steps), got {}",
                    self.max_steps
                ),
            );
        }
        if self.patch_cells == 0 || self.patch_cells > MAX_PATCH_CELLS {
            return bad(
                "patch_cells",
                format!(
                    "must be 1 to {MAX_PATCH_CELLS} (limit max_patch_cells), got {}",
                    self.patch_cells
                ),
            );
        }
        if !(self.cell_command.is_finite() && self.cell_command > 0.0) {
            return bad(
                "cell_command",
                format!("must be a positive number, got {}", self.cell_command),
            );
        }
        self.learner.check()
    }
}

/// Where the controller is within an episode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Phase {
    /// Driving to the episode's goal.
    Navigate,
    /// At the goal: following changes, or stepping at random.
    Local,
}

/// What the robot does this step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Action {
    /// A planned step toward the goal (or the local goal).
    Move,
    /// A random step (local exploration, nothing changed).
    RandomStep,
    /// Standing still (where a second random step would come, or boxed in).
    Wait,
}

/// An episode that just ended, after the learner was updated.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EpisodeEnd {
    pub strategy: Strategy,
    /// R = map changes / |T|.
    pub reward: f64,
    /// |T|: updates in the episode's trajectory.
    pub length: u32,
    /// Map changes during the episode.
    pub map_changes: u64,
}

/// The explorer's answer to one update.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ExplorerStep {
    /// The next command: one cell along an axis (`±cell_command`), or [0, 0] to stand.
    pub u: [f64; 2],
    /// The cell the command leads to (the robot's own when standing).
    pub next_cell: (u32, u32),
    pub action: Action,
    /// The goal the robot heads for now: the episode's goal while navigating, the local
    /// goal (centroid of the changes) or its own cell while exploring locally.
    pub goal: (u32, u32),
    /// The episode's goal, sampled by its strategy.
    pub episode_goal: (u32, u32),
    pub strategy: Strategy,
    pub phase: Phase,
    /// Steps taken in the current episode, this one included.
    pub episode_steps: u32,
    /// The features after the update.
    pub features: Features,
    /// Set when the update ended an episode (the learner has been updated).
    pub episode: Option<EpisodeEnd>,
}

/// One step's decision: the action, the next cell, the goal the robot heads for now.
type Decision = (Action, (u32, u32), (u32, u32));

#[derive(Debug, Clone)]
struct Episode {
    strategy: Strategy,
    goal: (u32, u32),
    phase: Phase,
    steps: u32,
    trajectory: Vec<Features>,
    map_changes: u64,
    last_random: bool,
}

/// One robot's curious explorer: learner, goal sampling and grid controller.
#[derive(Debug, Clone)]
pub struct Explorer {
    params: ExplorerParams,
    mode: Mode,
    learner: Learner,
    /// One draw per episode for its strategy.
    strategy_rng: ChaCha8Rng,
    /// Goal sampling.
    goal_rng: ChaCha8Rng,
    /// Local random steps.
    step_rng: ChaCha8Rng,
    wave: Wavefront,
    episode: Option<Episode>,
    episodes_ended: u64,
    /// Episodes started with each strategy, in [`Strategy::ALL`] order.
    started: [u64; 2],
}

impl Explorer {
    /// An explorer whose every random choice comes from `seed`, one labelled stream per
    /// kind of draw (module doc).
    pub fn new(params: ExplorerParams, mode: Mode, seed: u64) -> Result<Explorer, MapperError> {
        params.check()?;
        let learner = Learner::new(&params.learner, &mut seed::stream(seed, "tiles"))?;
        Ok(Explorer {
            params,
            mode,
            learner,
            strategy_rng: seed::stream(seed, "explorer/strategy"),
            goal_rng: seed::stream(seed, "explorer/goals"),
            step_rng: seed::stream(seed, "explorer/steps"),
            wave: Wavefront::new(),
            episode: None,
            episodes_ended: 0,
            started: [0, 0],
        })
    }

    pub fn params(&self) -> &ExplorerParams {
        &self.params
    }

    pub fn mode(&self) -> Mode {
        self.mode
    }

    pub fn learner(&self) -> &Learner {
        &self.learner
    }

    /// Episodes ended so far.
    pub fn episodes_ended(&self) -> u64 {
        self.episodes_ended
    }

    /// Episodes started with each strategy, in [`Strategy::ALL`] order.
    pub fn strategy_counts(&self) -> [u64; 2] {
        self.started
    }

    /// One sensor update: `update` is what the robot's latest observation did to `map`
    /// (already applied), `robot` its cell now, `t` the time (seconds). Records the
    /// update in the episode, ends the episode when it is over, starts the next, and
    /// answers the next command. `&mut` on the map only refreshes its feature caches.
    pub fn on_update(
        &mut self,
        map: &mut ChangeMap,
        update: &Update,
        robot: (u32, u32),
        t: f64,
    ) -> Result<ExplorerStep, MapperError> {
        if !t.is_finite() {
            return Err(MapperError::BadTime(t));
        }
        if map.index(robot.0, robot.1).is_none() {
            return Err(MapperError::CellOffMap {
                x: i64::from(robot.0),
                y: i64::from(robot.1),
                width: map.width(),
                height: map.height(),
            });
        }
        let features = map.features(t);
        let mut ended = None;
        let mut ep = match self.episode.take() {
            Some(mut ep) => {
                ep.trajectory.push(features);
                ep.map_changes += update.map_changes(self.params.count_discoveries) as u64;
                if ep.steps >= self.params.max_steps {
                    ended = Some(self.end_episode(ep));
                    self.start_episode(map, robot, t, features)
                } else {
                    ep
                }
            }
            None => self.start_episode(map, robot, t, features),
        };
        let (action, next, goal) = match self.decide(&mut ep, map, update, robot) {
            Some(step) => step,
            None => {
                // The local area is explored: a new episode takes this step. Its first
                // decision is never an early end (no random step came before it).
                ended = Some(self.end_episode(ep));
                ep = self.start_episode(map, robot, t, features);
                self.decide(&mut ep, map, update, robot)
                    .unwrap_or((Action::Wait, robot, robot))
            }
        };
        ep.steps += 1;
        let c = self.params.cell_command;
        let u = [
            (i64::from(next.0) - i64::from(robot.0)) as f64 * c,
            (i64::from(next.1) - i64::from(robot.1)) as f64 * c,
        ];
        let step = ExplorerStep {
            u,
            next_cell: next,
            action,
            goal,
            episode_goal: ep.goal,
            strategy: ep.strategy,
            phase: ep.phase,
            episode_steps: ep.steps,
            features,
            episode: ended,
        };
        self.episode = Some(ep);
        Ok(step)
    }

    /// Ends an episode: reward R = map changes / |T|, the learner's update over T.
    fn end_episode(&mut self, ep: Episode) -> EpisodeEnd {
        let length = ep.trajectory.len() as u32;
        let reward = if length == 0 {
            0.0
        } else {
            ep.map_changes as f64 / f64::from(length)
        };
        self.learner.update(ep.strategy, &ep.trajectory, reward);
        self.episodes_ended += 1;
        EpisodeEnd {
            strategy: ep.strategy,
            reward,
            length,
            map_changes: ep.map_changes,
        }
    }

    /// A new episode: its strategy ([`Mode::recency_probability`] against one draw of
    /// the strategy stream, drawn in every mode so the draws stay aligned across modes)
    /// and its goal (the robot's own cell if every cell is known occupied).
    fn start_episode(
        &mut self,
        map: &ChangeMap,
        robot: (u32, u32),
        t: f64,
        features: Features,
    ) -> Episode {
        let u: f64 = self.strategy_rng.random();
        let p = self
            .mode
            .recency_probability(&self.learner, features, self.started == [0, 0]);
        let strategy = Strategy::pick(p, u);
        let weights = match strategy {
            Strategy::Recency => map.recency_layer(t),
            Strategy::Poisson => map.probability_layer(t),
        };
        let goal = sample_goal(
            &weights.cells,
            map.obstacles(),
            map.width(),
            map.height(),
            self.params.patch_cells,
            &mut self.goal_rng,
        )
        .unwrap_or(robot);
        self.started[match strategy {
            Strategy::Recency => 0,
            Strategy::Poisson => 1,
        }] += 1;
        Episode {
            strategy,
            goal,
            phase: Phase::Navigate,
            steps: 0,
            trajectory: Vec::with_capacity(self.params.max_steps as usize),
            map_changes: 0,
            last_random: false,
        }
    }

    /// The controller's decision for this step: (action, next cell, goal now), or
    /// `None` to end the episode early ([`AfterRandomStep::EndEpisode`]).
    fn decide(
        &mut self,
        ep: &mut Episode,
        map: &ChangeMap,
        update: &Update,
        robot: (u32, u32),
    ) -> Option<Decision> {
        let (w, h) = (map.width(), map.height());
        if ep.phase == Phase::Navigate {
            if let Some(next) = self
                .wave
                .plan(map.obstacles(), w, h, robot, ep.goal)
                .and_then(|s| s.next)
            {
                return Some((Action::Move, next, ep.goal));
            }
            ep.phase = Phase::Local;
        }
        if let Some(centroid) = update.centroid(self.params.count_discoveries) {
            if let Some(next) = self
                .wave
                .plan(map.obstacles(), w, h, robot, centroid)
                .and_then(|s| s.next)
            {
                ep.last_random = false;
                return Some((Action::Move, next, centroid));
            }
        }
        if !ep.last_random {
            ep.last_random = true;
            return Some(match random_neighbour(map, robot, &mut self.step_rng) {
                Some(next) => (Action::RandomStep, next, robot),
                None => (Action::Wait, robot, robot),
            });
        }
        ep.last_random = false;
        match self.params.after_random_step {
            AfterRandomStep::Wait => Some((Action::Wait, robot, robot)),
            AfterRandomStep::EndEpisode => None,
        }
    }
}

/// A uniformly drawn 4-neighbour of `robot` on the map and not known occupied.
fn random_neighbour(
    map: &ChangeMap,
    robot: (u32, u32),
    rng: &mut impl RngCore,
) -> Option<(u32, u32)> {
    let options: Vec<(u32, u32)> = NEIGHBOURS
        .iter()
        .filter_map(|&(dx, dy)| {
            let (x, y) = (i64::from(robot.0) + dx, i64::from(robot.1) + dy);
            let (x, y) = (u32::try_from(x).ok()?, u32::try_from(y).ok()?);
            let i = map.index(x, y)?;
            (map.obstacles().get(i) != Some(&roam_world::grid::occupancy::OCCUPIED))
                .then_some((x, y))
        })
        .collect();
    if options.is_empty() {
        return None;
    }
    Some(options[rng.random_range(0..options.len())])
}

#[cfg(test)]
mod tests;
