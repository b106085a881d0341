//! A generation's new chromosomes evaluated, on several threads when there are enough.

use crate::curiosity::{Evaluation, Evaluator};

use super::problem::Chromosome;

/// Below this many new chromosomes a generation is evaluated on one thread: spawning
/// would cost more than it saves.
const PARALLEL_MIN: usize = 32;

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
