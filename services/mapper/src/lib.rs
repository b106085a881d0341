//! roam's change-rate mapper and curious exploration learner: paper 004 (Lehnert &
//! Precup, "Building a Curious Robot for Mapping").
//!
//! This is the algorithm core, plain Rust over plain types (no Zenoh, no tokio): a
//! [`ChangeMap`] turns sensor windows into an obstacle map with two Poisson processes
//! per cell (§3), and an [`Explorer`] per robot runs §4's loop (strategy choice by a
//! tile-coded learner, goal sampling, §2's wavefront controller) and answers each
//! update with the robot's next unit command. The batch experiment
//! (`roam_experiments::reproduce::mapper`, `roam reproduce mapper`), the bench
//! (`roam_bench::mapper`, `roam bench mapper`) and the network service
//! all call the same code.
//!
//! # Modules
//!
//! - [`poisson`]: one cell's pair of processes: watched time, events, Eq. 1 (T^c and
//!   the rate 1/T^c), Eq. 2 (P_c(E > 0)), recency.
//! - [`change_map`]: the map of processes and the obstacle grid; `observe` one window
//!   at a time; the rate, probability and recency layers; the learner's features.
//! - [`features`]: p = Σ P_c and r = max r^c from per-tile caches, exact to ~10⁻¹²
//!   without summing a million `exp`s per update.
//! - [`learner`]: strategies, modes, the tile coder, V_S, its update and the softmax.
//! - [`goals`]: goal sampling from the patch-averaged weights.
//! - [`wavefront`]: the wavefront planner with hill climbing and "as close as possible".
//! - [`prior`]: the Gamma prior on a cell's rates, λ̂ = (n + α)/(D + β).
//! - [`news`]: the news value P_news = 1 − exp(−λ̂Δt) per cell, shared across a fleet
//!   with each robot's reservation of its plan; the `news` scores.
//! - [`belief`]: the map now, P(occupied now) from the last sighting and the cell's two
//!   rates as a two-state Markov chain; the `occupied_now` layer.
//! - [`brier`]: the Brier score of a belief against the truth.
//! - [`reserve`]: the cells a robot's path will show it, with the times it should.
//! - observation times are checked against the sim clock by `roam_world::epoch`, shared
//!   with localization.
//! - [`explorer`]: the per-robot loop: episodes, navigation, local exploration, reward.
//! - [`seed`]: the seeded ChaCha8 streams every random choice draws from.
//! - [`error`]: [`MapperError`], naming the limit when a size is refused; [`limits`]:
//!   the limits it names.
//!
//! # Where paper 004 is ambiguous, and roam's choices
//!
//! Each is written next to the code that makes it and is a parameter unless noted.
//!
//! - **How the blocks move** (roam-sim, `config/scenarios/grid004.yaml`): a block
//!   jumps to the next position of its path every `period_steps`, cycling; the bottom
//!   block's "cycle along the bottom wall" is a shuttle written out there and back.
//! - **The grid world's sensor range** (grid004.yaml): a disk of 4 cells with line of
//!   sight; a blocking cell is seen, what it hides is not.
//! - **Time not observed** ([`poisson`]): sightings at most one sensor period apart
//!   (`MapParams::observation_period_s`, 1 s on grid004) mean the cell was watched in
//!   between; a longer gap adds gap − period to t_not obs.
//! - **Which changes are events** ([`poisson`]): only changes between sightings one
//!   period apart, so events and watched time cover the same time (unbiased);
//!   `MapParams::events_across_gaps` counts changes found after a gap too. Two
//!   sightings at one instant that disagree are never an event.
//! - **Map changes** ([`change_map`]): flips (free ↔ occupied) and discoveries (unknown
//!   → known) are both changes of the obstacle map; the explorer counts both for the
//!   reward and the local centroid by default (`ExplorerParams::count_discoveries`).
//!   Seen values ≥ 50 are occupied.
//! - **Cells never seen**: rate 0 and P = 0 (nothing is known); recency t_now − t_first +
//!   one period, strictly the stalest, so recency exploration goes there first.
//! - **The features** run over every cell of the map (the paper's "c ∈ M"), walls and
//!   cells never seen included (r counts those as the stalest;
//!   `MapParams::r_over_seen_cells` leaves them out of r).
//! - **Patches** ([`goals`]): 3 × 3 cells by default; a patch weighs the mean of all its
//!   cells; the goal is uniform among its cells not known occupied; all weights 0 →
//!   uniform over the known-free cells ("zig-zags until a first change is detected").
//! - **Tile coder** ([`learner`]): each of the five tilings displaced by a uniform
//!   offset in [0, 1) tile per axis from the seed; 128 × 128 tiles per tiling, features
//!   beyond clamped to the last tile; V_S the *mean* of the active tiles' weights
//!   (keeps V in reward units for τ = 2); each active tile updated w ← w(1 − λ) + Rλ for
//!   every (p, r) of the trajectory; the next strategy drawn at the features of the
//!   update that ends the episode; the first uniformly; one draw of its own stream per
//!   episode in every mode (common random numbers across modes).
//! - **Controller** ([`wavefront`], [`explorer`]): 4-connected; unknown cells passable;
//!   ties +x, +y, −x, −y; "as close as possible" = the reachable cell nearest the goal
//!   in straight line. Local exploration re-targets the centroid of each update's
//!   changes; with no change, one random step; where a second would come the robot
//!   *waits* one step (`AfterRandomStep::Wait`; `EndEpisode` ends the episode instead).
//!   Every command counts toward the 42 steps, waiting too; |T| = 42 updates.
//! - **Metrics** (`roam_experiments::reproduce::mapper`): the true rate of a cell is one process's
//!   events per second over the world's cycle; the error is averaged over the 48 cells
//!   that change (over all free cells it would be a constant multiple here); map quality
//!   over all 625 cells, unknown counting as wrong; 5000 s per run (the paper's x-axis
//!   cannot be read).
//!
//! # The reproduction
//!
//! `roam reproduce mapper` with the defaults: grid004, 5 runs of 5000 steps per mode,
//! seed 0, every mode of run r on run r's random numbers (`roam_experiments::reproduce::mapper::experiment`); about 0.5 s
//! in release on two cores.
//!
//! ```text
//! strategy  rate err AUC  final rate err  final map q  mean map quality  recency share
//! curious         76.637         0.01266        0.978             0.949           0.46
//! recency         79.974         0.01339        0.977             0.961           1.00
//! poisson         95.551         0.01405        0.974             0.868           0.00
//! uniform         77.263         0.01318        0.977             0.950           0.49
//! ```
//!
//! As in the paper, curious learns the rates faster than either strategy alone and
//! Poisson-only maps worse; the claims are judged in `roam::reproduce_mapper`. But the
//! gain is the *mixing's*, not the learner's: the uniform mix does as well (20 runs:
//! curious 76.8, uniform 78.3, recency 81.2, Poisson 106.3; curious − uniform per
//! repetition −1.5 ± 1.2, lower in 11 of 20). Why, measured with
//! `examples/learning_probe.rs` (20 runs):
//! - the feature r is the run's clock: four wall corners are never seen, so r =
//!   t − t_first + 1 s and the learner meets each r-tile (100 s) for about two episodes
//!   a run; at 85% of its choices a strategy has no value there yet, and its P(recency)
//!   stays within 0.05 of 1/2 on average. Taking r over the cells seen
//!   (`MapParams::r_over_seen_cells`, a reading of the paper as good) changes nothing
//!   (77.2 vs 78.3);
//! - the reward ranks the strategies against the metric: in the uniform mix a Poisson
//!   episode earns 0.53 changes per step and a recency one 0.35 (recency wins only in
//!   the first few hundred seconds, while discoveries count), so a learner that follows
//!   its values drifts to Poisson, the worst mapper: τ = 0.1 gives curious 82.8 (recency
//!   share 0.20), τ = 0.02 93.2, against uniform 78.3. A recency episode's worth comes
//!   later (a fresh map for the Poisson episodes after it), which a reward per episode
//!   on (p, r) cannot see.
//! - The final error stays near 40 % of the mean true rate (0.0327/s): a 2 × 2 block
//!   hides its back row while it covers it, so seen from one side a cell's block events
//!   are never watched and its estimate is about half the truth; and each changing cell
//!   is watched only 5–10 % of the run.
//!
//! # The bench (`roam bench mapper`)
//!
//! 1000 × 1000 cells, a disk of radius 50 (7 845 cells) per update at 10 Hz, 1 % of
//! the window churning per update (191 000 cells with a rate by the end): about 4 000
//! updates per second with p and r after each (observe ≈ 42 µs, features ≈ 205 µs
//! mean, 530 µs p99), 400 × real time; the plain sum the cache replaces takes 10 ms.

pub mod belief;
pub mod brier;
pub mod change_map;
pub mod error;
pub mod explorer;
pub mod features;
pub mod goals;
pub mod learner;
pub mod limits;
pub mod news;
pub mod poisson;
pub mod prior;
pub mod reserve;
pub use roam_world::seed;
#[cfg(feature = "zenoh")]
pub mod service;
pub mod wavefront;

pub use belief::{belief_layer, occupied_now, BeliefParams};
pub use brier::brier;
pub use change_map::{ChangeMap, MapParams, ObservationWindow, Update};
pub use error::MapperError;
pub use explorer::{EpisodeEnd, Explorer, ExplorerParams, ExplorerStep};
pub use features::Features;
pub use learner::{Mode, Strategy};
pub use news::NewsMap;
pub use prior::RatePrior;
