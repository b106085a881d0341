//! The genetic algorithm of paper 000 §II.A.
//!
//! - Chromosomes are 8-connected paths of cells starting at S.
//! - Initialisation (§II.A.1): random walks from S over legal moves, of a length drawn
//!   between the Manhattan distance and a cap, stopping early at G. roam's choices
//!   (both parameters of [`GaOptions`]): the cap is the number of cells the time budget
//!   allows (t_exec / (resolution · v_lin)) rather than every cell of the map, since
//!   longer walks can never fit the budget; and a walk that has not reached G is
//!   finished along the shortest route to G, so that the first population already
//!   reaches the goal and the GA spends its generations on information and time.
//!   A walk also stops early where finishing it at the goal would make it longer than
//!   the longest chromosome ([`GaOptions::max_path_cells`]).
//!   One more choice: the shortest path (which the request was checked against, so it
//!   fits the budget) joins the first population. The GA therefore always holds a path
//!   that reaches the goal in time, and a tight budget cannot end in an over-budget
//!   plan just because no random walk happened to fit. These three choices (budget cap,
//!   finish at G, shortest path) force "on time at the goal";
//!   [`GaParams::random_walks_only`] turns all three off, for the reproduction.
//! - Round trips (roam, issue 14; [`GaParams::walk_end_share`], default 0.5): a walk
//!   ends only once its t_ETA (Eq. 2, summed as it walks) has reached
//!   `walk_end_share · t_exec`. Before that, arriving at G does not end it (it walks on
//!   through G) and neither does its drawn length; after that, the first of the two
//!   does, and the walk is finished at G as above. With S = G the paper's rule ends every
//!   walk at once, at S: the first population is the one cell S, no operator can grow
//!   it, and the plan tells a robot whose next task is where it stands to stand still.
//!   With the rule every walk is a loop that used at least half the budget before
//!   heading back. Far goals change little: a walk that reaches G late, or is drawn
//!   long (random walks turn at almost every step, so they cost several times the
//!   budget's cells), has used the share anyway. `walk_end_share = 0` is the paper's rule.
//! - Via-point seeds (roam, issue 14; [`GaParams::via_share`], default 0.25): that share
//!   of the first population is built by [`crate::seeds`] (paths through cells drawn ∝
//!   information, joined by shortest paths, within the budget) and handed in with the
//!   shortest path as [`Problem::seed_paths`]; the rest are random walks.
//! - Loops stay loops: a chromosome starts at S and ends at G, and no operator moves its
//!   first gene or a last gene that is G (crossover joins a head of one parent to a tail
//!   of the other, mutation moves inner genes only). A loop through S or G in its middle
//!   may be cut or nudged there like any other inner gene.
//! - Selection (§II.A.3): "layered selection" after Li et al. is not spelled out in the
//!   paper. roam sorts by fitness and splits the population into three layers: the top
//!   third enters the next generation twice, the middle third once, the bottom third
//!   not at all. The best chromosome so far is kept unchanged (elitism).
//! - Crossover (§II.A.4): a share r_c of chromosomes is paired at random; a pair is
//!   crossed only at a gene both share besides S and G (picked at random among them),
//!   so children need no repair.
//! - Mutation (§II.A.4): in a share r_m of chromosomes, a share p_m of genes moves to a
//!   random legal 8-neighbour; a gap this opens to the previous or next gene is closed
//!   with the one cell between them (the mutation is dropped if no legal cell closes it).
//! - Stop at the maximum generations, the deadline, or a cancellation, whichever comes
//!   first; the best path found is returned.
//!
//! Every random choice draws from one ChaCha8 generator seeded by the request, and
//! nothing iterates a hash map, so the same seed and request give the same path bit for
//! bit (when the plan ends by its generation count, not by its wall-clock deadline).

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use roam_proto::planner::StopReason;

use crate::curiosity::{Evaluation, Evaluator, Model};
use crate::eta::step_time;
use crate::params::GaParams;
use crate::search::{descend_to_goal, descent_steps};
use crate::world::{Cell, World, MOVES};

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

/// Below this many new chromosomes a generation is evaluated on one thread: spawning
/// would cost more than it saves.
const PARALLEL_MIN: usize = 32;

/// Evaluates the chromosomes at `dirty`, in order, on up to `evaluators.len()` threads.
fn evaluate_dirty(
    evaluators: &mut [Evaluator<'_>],
    population: &[Chromosome],
    dirty: &[usize],
) -> Vec<Evaluation> {
    if evaluators.len() <= 1 || dirty.len() < PARALLEL_MIN {
        let evaluator = &mut evaluators[0];
        return dirty
            .iter()
            .map(|&i| evaluator.evaluate(&population[i].genes))
            .collect();
    }
    let chunk = dirty.len().div_ceil(evaluators.len());
    std::thread::scope(|scope| {
        let handles: Vec<_> = evaluators
            .iter_mut()
            .zip(dirty.chunks(chunk))
            .map(|(evaluator, part)| {
                scope.spawn(move || {
                    part.iter()
                        .map(|&i| evaluator.evaluate(&population[i].genes))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| {
                h.join()
                    .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
            })
            .collect()
    })
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
struct Chromosome {
    genes: Vec<Cell>,
    fitness: Option<f64>,
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

/// Runs the GA. `progress` gets each generation's number and best fitness, and
/// `cancel` stops the run at the next generation.
pub fn run(
    problem: &Problem<'_>,
    options: &GaOptions,
    cancel: &AtomicBool,
    mut progress: impl FnMut(u32, f64),
) -> GaResult {
    let params = problem.params;
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
    let mut evaluators: Vec<Evaluator<'_>> = (0..options.threads.max(1))
        .map(|_| {
            Evaluator::new(
                problem.world,
                params,
                problem.model,
                problem.goal,
                problem.t_exec,
            )
        })
        .collect();
    let seeded = problem.seed_paths.len().min(params.population);
    let mut population: Vec<Chromosome> = problem.seed_paths[..seeded]
        .iter()
        .map(|genes| Chromosome {
            genes: genes.clone(),
            fitness: None,
        })
        .collect();
    population.extend((seeded..params.population).map(|_| Chromosome {
        genes: initial_walk(problem, options, &mut rng),
        fitness: None,
    }));
    let mut scratch = Scratch::new(problem.world.cell_count());
    let mut best: Option<(Chromosome, Evaluation)> = None;
    let mut evaluations = 0u64;
    let mut evaluated_genes = 0u64;
    let mut generation = 0u32;
    let stop_reason = loop {
        // Evaluate what changed, then take the best in population order.
        let dirty: Vec<usize> = (0..population.len())
            .filter(|&i| population[i].fitness.is_none())
            .collect();
        let results = evaluate_dirty(&mut evaluators, &population, &dirty);
        evaluations += results.len() as u64;
        evaluated_genes += dirty
            .iter()
            .map(|&i| population[i].genes.len() as u64)
            .sum::<u64>();
        for (&i, evaluation) in dirty.iter().zip(results) {
            let chromosome = &mut population[i];
            chromosome.fitness = Some(evaluation.fitness.total);
            if best
                .as_ref()
                .is_none_or(|(_, b)| evaluation.fitness.total > b.fitness.total)
            {
                best = Some((chromosome.clone(), evaluation));
            }
        }
        generation += 1;
        let best_fitness = best
            .as_ref()
            .map_or(f64::NEG_INFINITY, |(_, e)| e.fitness.total);
        progress(generation, best_fitness);
        if generation >= params.max_generations {
            break StopReason::MaxGenerations;
        }
        if cancel.load(Ordering::Relaxed) {
            break StopReason::Cancelled;
        }
        if options.deadline.is_some_and(|d| Instant::now() >= d) {
            break StopReason::Deadline;
        }
        population = layered_selection(population, best.as_ref().map(|(c, _)| c));
        // Index 0 is the elite: never crossed or mutated.
        let n = population.len();
        let mut order: Vec<usize> = (1..n).collect();
        order.shuffle(&mut rng);
        let crossed = ((params.crossover_ratio * n as f64).round() as usize).min(order.len()) & !1;
        for pair in order[..crossed].chunks_exact(2) {
            crossover(
                &mut population,
                pair[0],
                pair[1],
                problem,
                options,
                &mut scratch,
                &mut rng,
            );
        }
        order.shuffle(&mut rng);
        let mutated = ((params.mutation_ratio * n as f64).round() as usize).min(order.len());
        for &i in &order[..mutated] {
            mutate(&mut population[i], problem, options, &mut rng);
        }
    };
    let (chromosome, evaluation) = match best {
        Some(b) => b,
        None => {
            let genes = vec![problem.start];
            let evaluation = evaluators[0].evaluate(&genes);
            (
                Chromosome {
                    genes,
                    fitness: None,
                },
                evaluation,
            )
        }
    };
    GaResult {
        best: chromosome.genes,
        evaluation,
        generations: generation,
        evaluations,
        evaluated_genes,
        stop_reason,
    }
}

/// A random walk from S (§II.A.1), see the module doc for roam's two choices.
fn initial_walk(problem: &Problem<'_>, options: &GaOptions, rng: &mut ChaCha8Rng) -> Vec<Cell> {
    let world = problem.world;
    let manhattan = world.manhattan(problem.start, problem.goal).max(1);
    let map_cap = world.traversable_count().max(manhattan);
    let cap = if options.cap_walks_by_budget {
        let per_cell = world.meta.resolution * problem.params.v_lin;
        let budget_cells = if per_cell > 0.0 {
            (problem.t_exec / per_cell).ceil() as usize
        } else {
            map_cap
        };
        budget_cells.clamp(manhattan, map_cap)
    } else {
        map_cap
    };
    let max_cells = options.max_path_cells.max(1);
    let cap = cap.min(max_cells.saturating_sub(1).max(manhattan));
    let length = rng.random_range(manhattan..=cap);
    let mut walk = Vec::with_capacity((length + 1).min(max_cells));
    walk.push(problem.start);
    let mut cell = problem.start;
    let mut moves = [0 as Cell; 8];
    // Room for one more step: with it the walk, and the descent to the goal that
    // finishes it (a neighbour's descent is at most two steps longer), stays within
    // `max_cells`.
    let room = |walk: &Vec<Cell>, cell: Cell| {
        let descent = if options.complete_walks_to_goal {
            descent_steps(problem.goal_field, cell).saturating_add(2)
        } else {
            0
        };
        walk.len().saturating_add(1).saturating_add(descent) <= max_cells
    };
    // The round-trip rule (`walk_end_share`, see the module doc): neither the drawn
    // length nor G ends a walk before it has used this much of t_exec. 0 is the paper's
    // rule: 0 s are always used, so the walk stops at its length or at G.
    let floor = problem.params.walk_end_share * problem.t_exec;
    let mut t = 0.0;
    let mut prev_dir = None;
    let mut dirs = [0usize; 8];
    loop {
        let done = walk.len() >= length || cell == problem.goal;
        if (done && t >= floor) || !room(&walk, cell) {
            break;
        }
        let mut count = 0;
        for dir in 0..MOVES.len() {
            if let Some(next) = world.step(cell, dir) {
                moves[count] = next;
                dirs[count] = dir;
                count += 1;
            }
        }
        if count == 0 {
            break;
        }
        let pick = rng.random_range(0..count);
        cell = moves[pick];
        t += step_time(world, problem.params, prev_dir, dirs[pick]);
        prev_dir = Some(dirs[pick]);
        walk.push(cell);
    }
    if options.complete_walks_to_goal && cell != problem.goal {
        descend_to_goal(world, problem.goal_field, &mut walk);
    }
    // Only a walk that took no step can get here longer (its descent is the shortest
    // route, which fits the budget); cut it all the same, the bound is a promise.
    walk.truncate(max_cells);
    walk
}

/// Layered selection: top third twice, middle third once, bottom third dropped; the
/// best so far first.
fn layered_selection(
    mut population: Vec<Chromosome>,
    best: Option<&Chromosome>,
) -> Vec<Chromosome> {
    let n = population.len();
    // Stable sort on fitness, best first; ties keep their order (determinism).
    population.sort_by(|a, b| {
        b.fitness
            .unwrap_or(f64::NEG_INFINITY)
            .total_cmp(&a.fitness.unwrap_or(f64::NEG_INFINITY))
    });
    let third = n.div_ceil(3);
    let mut next = Vec::with_capacity(n);
    if let Some(best) = best {
        next.push(best.clone());
    }
    // Chromosomes are moved, not copied, except the top layer's second copies.
    let mut ranked = population.into_iter();
    for c in ranked.by_ref().take(third) {
        next.push(c.clone());
        next.push(c);
    }
    let room = n.saturating_sub(next.len());
    next.extend(ranked.take(room));
    next.truncate(n);
    next
}

/// Reusable buffers for crossover: the position of each cell in the first parent.
struct Scratch {
    position: Vec<u32>,
    stamp: Vec<u32>,
    current: u32,
    shared: Vec<(usize, usize)>,
}

impl Scratch {
    fn new(cells: usize) -> Self {
        Scratch {
            position: vec![0; cells],
            stamp: vec![0; cells],
            current: 0,
            shared: Vec::new(),
        }
    }

    fn next(&mut self) {
        self.current = self.current.wrapping_add(1);
        if self.current == 0 {
            self.stamp.fill(0);
            self.current = 1;
        }
    }
}

/// Crosses chromosomes `a` and `b` at a shared gene other than S and G (§II.A.4).
fn crossover(
    population: &mut [Chromosome],
    a: usize,
    b: usize,
    problem: &Problem<'_>,
    options: &GaOptions,
    scratch: &mut Scratch,
    rng: &mut ChaCha8Rng,
) {
    let (pa, pb) = (&population[a].genes, &population[b].genes);
    if pa.len() < 3 || pb.len() < 3 {
        return;
    }
    scratch.next();
    let cur = scratch.current;
    for (i, &cell) in pa.iter().enumerate().take(pa.len() - 1).skip(1) {
        if cell == problem.goal {
            continue;
        }
        scratch.stamp[cell as usize] = cur;
        scratch.position[cell as usize] = i as u32;
    }
    scratch.shared.clear();
    for (j, &cell) in pb.iter().enumerate().take(pb.len() - 1).skip(1) {
        if scratch.stamp[cell as usize] == cur {
            scratch
                .shared
                .push((scratch.position[cell as usize] as usize, j));
        }
    }
    if scratch.shared.is_empty() {
        return;
    }
    let (i, j) = scratch.shared[rng.random_range(0..scratch.shared.len())];
    let child_a: Vec<Cell> = pa[..=i].iter().chain(&pb[j + 1..]).copied().collect();
    let child_b: Vec<Cell> = pb[..=j].iter().chain(&pa[i + 1..]).copied().collect();
    if child_a.len() > options.max_path_cells || child_b.len() > options.max_path_cells {
        return;
    }
    population[a] = Chromosome {
        genes: child_a,
        fitness: None,
    };
    population[b] = Chromosome {
        genes: child_b,
        fitness: None,
    };
}

/// Mutates a share p_m of the genes of one chromosome (§II.A.4).
fn mutate(
    chromosome: &mut Chromosome,
    problem: &Problem<'_>,
    options: &GaOptions,
    rng: &mut ChaCha8Rng,
) {
    let world = problem.world;
    let len = chromosome.genes.len();
    if len < 2 {
        return;
    }
    let count = ((problem.params.mutation_percentage * len as f64).round() as usize).max(1);
    let mut changed = false;
    for _ in 0..count {
        let genes = &mut chromosome.genes;
        // A mutation adds at most two genes (a bridge on each side).
        if genes.len() + 2 > options.max_path_cells || genes.len() < 2 {
            break;
        }
        // Any gene but S; the last gene only when it is not G.
        let last_movable = if *genes.last().unwrap_or(&problem.goal) == problem.goal {
            genes.len() - 1
        } else {
            genes.len()
        };
        if last_movable <= 1 {
            break;
        }
        let i = rng.random_range(1..last_movable);
        let dir = rng.random_range(0..MOVES.len());
        let Some(moved) = world.step(genes[i], dir) else {
            continue;
        };
        let prev = genes[i - 1];
        let next = genes.get(i + 1).copied();
        if moved == prev || Some(moved) == next {
            continue;
        }
        let Some(before) = bridge(world, prev, moved) else {
            continue;
        };
        let after = match next {
            Some(n) => match bridge(world, moved, n) {
                Some(b) => b,
                None => continue,
            },
            None => Bridge::Direct,
        };
        let mut replacement = Vec::with_capacity(3);
        if let Bridge::Via(c) = before {
            replacement.push(c);
        }
        replacement.push(moved);
        if let Bridge::Via(c) = after {
            replacement.push(c);
        }
        genes.splice(i..=i, replacement);
        changed = true;
    }
    if changed {
        chromosome.fitness = None;
    }
}

enum Bridge {
    Direct,
    Via(Cell),
}

/// How to get from `a` to `b` (at most two cells apart): directly, or through the one
/// legal cell between them.
fn bridge(world: &World, a: Cell, b: Cell) -> Option<Bridge> {
    if world.is_legal_move(a, b) {
        return Some(Bridge::Direct);
    }
    if world.chebyshev(a, b) != 2 {
        return None;
    }
    (0..MOVES.len())
        .filter_map(|d| world.step(a, d))
        .find(|&c| world.is_legal_move(c, b))
        .map(Bridge::Via)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::search::distance_field;
    use roam_proto::map::{GridMeta, Origin};
    use roam_world::grid::Grid;

    fn open_world(side: u32) -> World {
        let meta = GridMeta {
            width: side,
            height: side,
            resolution: 0.2,
            origin: Origin::default(),
        };
        World::new(&Grid::filled(meta, 0i8), &Grid::filled(meta, 50u8), 0.25).expect("world")
    }

    fn options(max_path_cells: usize) -> GaOptions {
        GaOptions {
            seed: 3,
            deadline: None,
            cap_walks_by_budget: true,
            complete_walks_to_goal: true,
            max_path_cells,
            threads: 1,
        }
    }

    /// No chromosome the GA builds is longer than `max_path_cells`: initial walks (with
    /// their descent to the goal), mutations and crossovers all keep to it.
    #[test]
    fn no_chromosome_outgrows_max_path_cells() {
        let world = open_world(60);
        let params = GaParams::default();
        let (start, goal) = (world.cell(5, 5), world.cell(30, 20));
        let field = distance_field(&world, goal);
        // A generous budget (400 s = 1000 cells at 0.4 s per cell) but a tight bound.
        let problem = Problem {
            world: &world,
            params: &params,
            model: Model::Novelty,
            start,
            goal,
            t_exec: 400.0,
            goal_field: &field,
            seed_paths: &[],
        };
        let max = 40;
        let options = options(max);
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let mut population: Vec<Chromosome> = (0..300)
            .map(|_| Chromosome {
                genes: initial_walk(&problem, &options, &mut rng),
                fitness: None,
            })
            .collect();
        assert!(population.iter().all(|c| c.genes.len() <= max));
        assert!(
            population.iter().any(|c| c.genes.len() > max - 5),
            "walks use the room they have"
        );
        assert!(
            population
                .iter()
                .filter(|c| c.genes.last() == Some(&goal))
                .count()
                > 250,
            "walks that stop early still reach the goal"
        );
        let mut scratch = Scratch::new(world.cell_count());
        for round in 0..50 {
            for chromosome in population.iter_mut() {
                mutate(chromosome, &problem, &options, &mut rng);
            }
            for pair in (0..population.len()).collect::<Vec<_>>().chunks_exact(2) {
                crossover(
                    &mut population,
                    pair[0],
                    pair[1],
                    &problem,
                    &options,
                    &mut scratch,
                    &mut rng,
                );
            }
            let longest = population.iter().map(|c| c.genes.len()).max();
            assert!(longest <= Some(max), "round {round}: {longest:?}");
        }
    }

    /// Issue 14: with S = G the round-trip rule makes every walk a loop that used at
    /// least `walk_end_share` of the budget before heading back (the paper's rule makes
    /// every walk the one cell S), and crossover and mutation keep every chromosome a
    /// legal path from S back to S.
    #[test]
    fn round_trip_walks_are_loops_and_the_operators_keep_them_loops() {
        let world = open_world(60);
        let start = world.cell(30, 30);
        let field = distance_field(&world, start);
        let paper = GaParams::default().with_paper_initialization();
        let params = GaParams::default();
        let problem = |params| Problem {
            world: &world,
            params,
            model: Model::Novelty,
            start,
            goal: start,
            t_exec: 60.0,
            goal_field: &field,
            seed_paths: &[],
        };
        // 60 s at 0.4 s per cell: at most 151 cells.
        let options = options(151);
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let paper_problem = problem(&paper);
        for _ in 0..50 {
            assert_eq!(
                initial_walk(&paper_problem, &options, &mut rng),
                vec![start]
            );
        }
        let problem = problem(&params);
        let mut population: Vec<Chromosome> = (0..300)
            .map(|_| Chromosome {
                genes: initial_walk(&problem, &options, &mut rng),
                fitness: None,
            })
            .collect();
        for c in &population {
            assert!(c.genes.len() >= 3, "{:?}", c.genes);
            let eta = crate::eta::path_eta(&world, &params, &c.genes);
            assert!(eta >= 0.5 * 60.0, "a walk of {eta} s");
        }
        let is_loop = |genes: &[Cell]| {
            genes.first() == Some(&start)
                && genes.last() == Some(&start)
                && genes.windows(2).all(|w| world.is_legal_move(w[0], w[1]))
        };
        let mut scratch = Scratch::new(world.cell_count());
        let mut changed = 0;
        for _ in 0..50 {
            for chromosome in population.iter_mut() {
                let before = chromosome.genes.clone();
                mutate(chromosome, &problem, &options, &mut rng);
                changed += usize::from(chromosome.genes != before);
            }
            for pair in (0..population.len()).collect::<Vec<_>>().chunks_exact(2) {
                crossover(
                    &mut population,
                    pair[0],
                    pair[1],
                    &problem,
                    &options,
                    &mut scratch,
                    &mut rng,
                );
            }
            assert!(population.iter().all(|c| is_loop(&c.genes)));
        }
        assert!(changed > 1000, "the operators did work: {changed}");
    }

    /// Without the bound (the map's cell count), the same walks are far longer: the test
    /// above would catch a bound that is not applied.
    #[test]
    fn without_a_tight_bound_walks_are_longer() {
        let world = open_world(60);
        let params = GaParams::default();
        let (start, goal) = (world.cell(5, 5), world.cell(30, 20));
        let field = distance_field(&world, goal);
        let problem = Problem {
            world: &world,
            params: &params,
            model: Model::Novelty,
            start,
            goal,
            t_exec: 400.0,
            goal_field: &field,
            seed_paths: &[],
        };
        let options = options(world.cell_count());
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let longest = (0..300)
            .map(|_| initial_walk(&problem, &options, &mut rng).len())
            .max();
        assert!(longest > Some(400), "{longest:?}");
    }
}
