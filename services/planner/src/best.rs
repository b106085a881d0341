//! Never below an obviously available plan (issue 14).
//!
//! The GA keeps its best chromosome (elitism), and the shortest path and the via-point
//! seeds ([`crate::seeds`]; for S = G, the loops) are in its first population, so its
//! result is at least as fit as each of them whenever they fit in the population. This
//! module makes that a promise rather than a consequence of the GA's bookkeeping (a
//! population too small for every seed, a change to selection): after the GA the
//! planner scores the shortest path and every seed with the same fitness (Eqs. 1, 3–7,
//! the request's model) and returns the fittest of all, the GA's path on a tie. It
//! costs one evaluation per seed.

use crate::curiosity::{Evaluation, Evaluator};
use crate::world::Cell;

/// Where the returned path comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlanSource {
    /// The GA's best chromosome.
    Ga,
    /// The shortest path, unchanged (also what the `shortest` baseline returns).
    Shortest,
    /// Via-point seed number `n` ([`crate::seeds::ViaSeeds::paths`]), unchanged.
    ViaSeed(usize),
    /// The greedy planner's route ([`crate::greedy`]).
    Greedy,
    /// The request's seed route, the remainder of the route the robot drives
    /// ([`crate::remainder`]), unchanged.
    Remainder,
}

impl PlanSource {
    /// Its name on the wire ([`roam_proto::planner::Plan::found_by`]).
    pub fn as_str(self) -> &'static str {
        match self {
            PlanSource::Ga => "ga",
            PlanSource::Shortest => "shortest",
            PlanSource::ViaSeed(_) => "via_seed",
            PlanSource::Greedy => "greedy",
            PlanSource::Remainder => "remainder",
        }
    }
}

/// A path with its fitness and where it comes from.
#[derive(Debug, Clone, PartialEq)]
pub struct Scored {
    pub path: Vec<Cell>,
    pub evaluation: Evaluation,
    pub source: PlanSource,
}

/// The GA's result, the shortest path, the remainder of the robot's route (a replan's
/// seed route, when there is one) and the seeds, fittest first; the earlier on a tie
/// (the GA's first), so the first is [`best_of`]'s. A plan at a coarser planning
/// resolution drives them in this order until one fits (`crate::plan`).
pub fn ranked(
    evaluator: &mut Evaluator<'_>,
    ga: Scored,
    shortest: &[Cell],
    remainder: Option<&[Cell]>,
    seeds: &[Vec<Cell>],
) -> Vec<Scored> {
    let mut all = Vec::with_capacity(3 + seeds.len());
    all.push(ga);
    let others = std::iter::once((PlanSource::Shortest, shortest))
        .chain(remainder.map(|path| (PlanSource::Remainder, path)))
        .chain(
            seeds
                .iter()
                .enumerate()
                .map(|(n, path)| (PlanSource::ViaSeed(n), path.as_slice())),
        );
    for (source, path) in others {
        all.push(Scored {
            evaluation: evaluator.evaluate(path),
            path: path.to_vec(),
            source,
        });
    }
    // Stable: ties keep their order.
    all.sort_by(|a, b| {
        b.evaluation
            .fitness
            .total
            .total_cmp(&a.evaluation.fitness.total)
    });
    all
}

/// The fittest of the GA's result, the shortest path and the seeds; the earlier on a
/// tie (the GA's first), so a GA that has them all returns its own path.
pub fn best_of(
    evaluator: &mut Evaluator<'_>,
    ga: Scored,
    shortest: &[Cell],
    seeds: &[Vec<Cell>],
) -> Scored {
    let mut best = ga;
    let others = std::iter::once((PlanSource::Shortest, shortest)).chain(
        seeds
            .iter()
            .enumerate()
            .map(|(n, path)| (PlanSource::ViaSeed(n), path.as_slice())),
    );
    for (source, path) in others {
        let evaluation = evaluator.evaluate(path);
        if evaluation.fitness.total > best.evaluation.fitness.total {
            best = Scored {
                path: path.to_vec(),
                evaluation,
                source,
            };
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::curiosity::Model;
    use crate::params::GaParams;
    use crate::search::shortest_path;
    use crate::world::World;
    use roam_proto::map::{GridMeta, Origin};
    use roam_world::grid::Grid;

    fn world() -> World {
        let meta = GridMeta {
            width: 20,
            height: 20,
            resolution: 0.2,
            origin: Origin::default(),
        };
        World::new(&Grid::filled(meta, 0i8), &Grid::filled(meta, 30u8), 0.25).expect("world")
    }

    /// A GA result worse than a seed (here: over budget and not at the goal) is replaced
    /// by the fittest seed; a GA result at least as fit is kept.
    #[test]
    fn the_fittest_is_returned_and_ties_keep_the_gas() {
        let world = world();
        let params = GaParams::default();
        let (start, goal) = (world.cell(2, 2), world.cell(10, 2));
        let mut evaluator = Evaluator::new(&world, &params, Model::Novelty, goal, 20.0);
        let shortest = shortest_path(&world, start, goal).expect("path");
        // A detour within budget: up three rows, along, and down.
        let mut detour = vec![start];
        detour.extend((1..=3).map(|y| world.cell(2, 2 + y)));
        detour.extend((3..=9).map(|x| world.cell(x, 5)));
        detour.extend((2..=4).rev().map(|y| world.cell(10, y)));
        assert!(detour.windows(2).all(|w| world.is_legal_move(w[0], w[1])));
        let bad_path: Vec<Cell> = (2..6).map(|x| world.cell(x, 2)).collect();
        let bad = Scored {
            evaluation: evaluator.evaluate(&bad_path),
            path: bad_path,
            source: PlanSource::Ga,
        };
        let seeds = vec![shortest.clone(), detour.clone()];
        let chosen = best_of(&mut evaluator, bad, &shortest, &seeds);
        assert_eq!(chosen.source, PlanSource::ViaSeed(1));
        assert_eq!(chosen.path, detour);
        // The GA's own path, as fit as the best seed, is kept.
        let same = Scored {
            evaluation: evaluator.evaluate(&detour),
            path: detour.clone(),
            source: PlanSource::Ga,
        };
        let kept = best_of(&mut evaluator, same, &shortest, &seeds);
        assert_eq!(kept.source, PlanSource::Ga);
    }
}
