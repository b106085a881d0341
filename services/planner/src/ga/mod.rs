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
//! - Round trips (roam's; [`GaParams::walk_end_share`], default 0.5): a walk
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
//! - Via-point seeds (roam's; [`GaParams::via_share`], default 0.25): that share
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
//! - A chromosome with the genes of one already scored takes its fitness (see
//!   [`known`]): about three in five of a generation's new chromosomes are copies.
//! - Stop at the maximum generations, the deadline, or a cancellation, whichever comes
//!   first; the best path found is returned.
//!
//! Every random choice draws from one ChaCha8 generator seeded by the request, and
//! nothing iterates a hash map, so the same seed and request give the same path bit for
//! bit (when the plan ends by its generation count, not by its wall-clock deadline).

mod evaluate;
mod known;
mod operators;
mod problem;
mod walk;

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use roam_proto::planner::StopReason;

use crate::curiosity::{Evaluation, Evaluator};

use evaluate::evaluate_dirty;
use known::{triage, Triage};
use operators::{crossover, layered_selection, mutate, Scratch};
use problem::Chromosome;
use walk::initial_walk;

pub use problem::{default_threads, GaOptions, GaResult, Problem};

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
        // Paths scored before take their fitness; each distinct new one is walked once.
        let Triage {
            fresh,
            known,
            same_as,
        } = triage(&population, &dirty);
        let results = evaluate_dirty(&mut evaluators, &population, &fresh);
        evaluations += results.len() as u64;
        evaluated_genes += fresh
            .iter()
            .map(|&i| population[i].genes.len() as u64)
            .sum::<u64>();
        for (i, fitness) in known {
            population[i].fitness = Some(fitness);
        }
        for (&i, evaluation) in fresh.iter().zip(results) {
            let chromosome = &mut population[i];
            chromosome.fitness = Some(evaluation.fitness.total);
            if best
                .as_ref()
                .is_none_or(|(_, b)| evaluation.fitness.total > b.fitness.total)
            {
                best = Some((chromosome.clone(), evaluation));
            }
        }
        for (i, first) in same_as {
            population[i].fitness = population[first].fitness;
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
