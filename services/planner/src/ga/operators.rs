//! The operators between generations: layered selection, crossover at a shared gene and
//! mutation of inner genes (§II.A.3–4).

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use crate::world::{Cell, World, MOVES};

use super::problem::{Chromosome, GaOptions, Problem};

/// Layered selection: top third twice, middle third once, bottom third dropped; the
/// best so far first.
pub(super) fn layered_selection(
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
pub(super) struct Scratch {
    position: Vec<u32>,
    stamp: Vec<u32>,
    current: u32,
    shared: Vec<(usize, usize)>,
}

impl Scratch {
    pub(super) fn new(cells: usize) -> Self {
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
pub(super) fn crossover(
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
pub(super) fn mutate(
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
    world.via(a, b).map(Bridge::Via)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::curiosity::Model;
    use crate::ga::walk::initial_walk;
    use crate::params::GaParams;
    use crate::search::distance_field;
    use rand::SeedableRng;
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

    /// With S = G the round-trip rule makes every walk a loop that used at
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
