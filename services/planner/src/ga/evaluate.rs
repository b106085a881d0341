//! A generation's new chromosomes evaluated, on several threads when there are enough.

use crate::curiosity::{Evaluation, Evaluator};

use super::problem::Chromosome;

/// Below this many new chromosomes a generation is evaluated on one thread: spawning
/// would cost more than it saves. Measured on the paper's workload (Model I, 2000
/// generations, this 2-core machine): once copies are no longer walked again
/// (`known.rs`) a generation has about 60 new paths, and splitting them over two
/// threads spawned each generation took 1.09–1.13 s a plan against 0.84–0.96 s on one
/// (at 32); at 128 only the first population, 200 paths, is split: 0.75–1.0 s.
const PARALLEL_MIN: usize = 128;

/// Evaluates the chromosomes at `dirty`, in order, on up to `evaluators.len()` threads.
pub(super) fn evaluate_dirty(
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
