//! Chromosomes whose genes were scored already. Layered selection puts the top third
//! into the next generation twice, so crossover often pairs a chromosome with its own
//! copy (the children are the parents) and a mutation can make what is already there:
//! measured on the paper's workload (Model I, population 200, 2000 generations, the
//! built-in world), 62% of the chromosomes a generation had to score had the genes of
//! one scored before. Evaluation is a pure function of the genes (Eqs. 1–10), so such a
//! chromosome takes that fitness and is not walked again; each distinct new path is
//! walked once. The plan is the same, bit for bit: a copy's fitness equals its
//! original's, so it can never be strictly better than the best kept so far.

use rustc_hash::FxHashMap;

use crate::world::Cell;

use super::problem::Chromosome;

/// What a generation's unscored chromosomes need.
#[derive(Debug, Default, PartialEq)]
pub(super) struct Triage {
    /// Chromosomes to evaluate (distinct genes, none scored before), in population
    /// order.
    pub(super) fresh: Vec<usize>,
    /// Chromosomes with the genes of a scored one: their fitness.
    pub(super) known: Vec<(usize, f64)>,
    /// Chromosomes with the genes of one in `fresh` (the second index): its fitness
    /// once evaluated.
    pub(super) same_as: Vec<(usize, usize)>,
}

/// Splits `dirty` (indices of unscored chromosomes, ascending) by whether their genes
/// were scored. Hashed with FxHash (rustc-hash): a generation hashes about 200 paths of
/// a hundred cells, and SipHash's cost there would be a tenth of what the triage saves;
/// nothing iterates the map, so its order cannot reach a plan.
pub(super) fn triage(population: &[Chromosome], dirty: &[usize]) -> Triage {
    let mut scored: FxHashMap<&[Cell], Result<f64, usize>> = FxHashMap::default();
    for c in population {
        if let Some(f) = c.fitness {
            scored.entry(&c.genes).or_insert(Ok(f));
        }
    }
    let mut triage = Triage::default();
    for &i in dirty {
        match scored.get(population[i].genes.as_slice()) {
            Some(Ok(f)) => triage.known.push((i, *f)),
            Some(Err(first)) => triage.same_as.push((i, *first)),
            None => {
                scored.insert(&population[i].genes, Err(i));
                triage.fresh.push(i);
            }
        }
    }
    triage
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chromosome(genes: &[Cell], fitness: Option<f64>) -> Chromosome {
        Chromosome {
            genes: genes.to_vec(),
            fitness,
        }
    }

    #[test]
    fn copies_of_scored_or_new_paths_are_not_evaluated_again() {
        let population = [
            chromosome(&[1, 2, 3], Some(5.0)),
            chromosome(&[1, 2, 3], None),
            chromosome(&[1, 4, 3], None),
            chromosome(&[1, 4, 3], None),
            chromosome(&[1, 5, 3], None),
        ];
        let t = triage(&population, &[1, 2, 3, 4]);
        assert_eq!(
            t,
            Triage {
                fresh: vec![2, 4],
                known: vec![(1, 5.0)],
                same_as: vec![(3, 2)],
            }
        );
    }
}
