//! The inputs of a GA run (the problem and the options beyond the paper's parameters),
//! what it returns, and the chromosome it evolves.

use std::time::Instant;

use roam_proto::planner::StopReason;

use crate::curiosity::{Evaluation, Model};
use crate::params::GaParams;
use crate::world::{Cell, World};

/// How a GA run starts and when it stops, beyond the paper's parameters.
#[derive(Debug, Clone)]
pub struct GaOptions {
    pub seed: u64,
    /// Wall-clock limit; `None` runs to `max_generations`.
    pub deadline: Option<Instant>,
    /// Cap initial walk lengths at the cells the budget allows (roam) instead of the
    /// map's cell count (the paper).
    pub cap_walks_by_budget: bool,
    /// Finish initial walks at the goal along the shortest route.
    pub complete_walks_to_goal: bool,
    /// Longest chromosome, in cells: no initial walk, crossover or mutation makes a
    /// longer one, so a population holds at most population × this many genes. The
    /// planner sets it to the longest path the budget allows ([`crate::limits`], from
    /// Eq. 2), so a chromosome that could never be on time is never built.
    pub max_path_cells: usize,
    /// Threads that evaluate a generation's new chromosomes. Evaluation is a pure
    /// function of the path and the best is picked in population order afterwards, so
    /// the result is the same for any thread count.
    pub threads: usize,
}

/// The default evaluation threads: the machine's cores, at most 4.
pub fn default_threads() -> usize {
    std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .clamp(1, 4)
}

/// What a GA run returns.
#[derive(Debug, Clone)]
pub struct GaResult {
    pub best: Vec<Cell>,
    pub evaluation: Evaluation,
    pub generations: u32,
    pub evaluations: u64,
    /// Genes of all evaluated chromosomes: the GA's work, which grows with path length.
    pub evaluated_genes: u64,
    pub stop_reason: StopReason,
}

#[derive(Debug, Clone)]
pub(super) struct Chromosome {
    pub(super) genes: Vec<Cell>,
    pub(super) fitness: Option<f64>,
}

/// The inputs of one GA run.
#[derive(Debug)]
pub struct Problem<'a> {
    pub world: &'a World,
    pub params: &'a GaParams,
    pub model: Model,
    pub start: Cell,
    pub goal: Cell,
    pub t_exec: f64,
    /// Cost-to-goal from every cell (see [`crate::search::distance_field`]).
    pub goal_field: &'a [u32],
    /// Paths placed in the first population as they are (roam seeds the shortest path,
    /// see the module doc); the rest of the population is random walks.
    pub seed_paths: &'a [Vec<Cell>],
}
