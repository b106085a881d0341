//! Via-point seeds for the GA's first population: roam's addition to paper 000 §II.A.1.
//!
//! Paper 000 starts the GA from random walks from S. A random walk stays near where it
//! starts (after n steps it is some √n cells away), so information off the straight
//! route (a room beside a corridor, a zone behind the start) is seldom in the first
//! population, and crossover and mutation, which recombine and nudge what is there,
//! rarely get there later. roam therefore also seeds paths through informative places:
//!
//! 1. **Fields.** The cost to G from every cell is the GA's goal field; the cost to S
//!    from every cell is one more Dijkstra (the same field when S = G). A cell v is in
//!    reach when cost(S, v) + cost(v, G), as distance at v_lin (Eq. 2 without its turns:
//!    a lower bound, see [`crate::search::STRAIGHT`]), fits t_exec.
//! 2. **Candidates.** Up to [`MAX_CANDIDATES`] cells in reach, drawn with probability
//!    ∝ their information score I_xy (uniformly when no cell in reach has information),
//!    at least a perception window apart so that no two show the same cells. Each gets a
//!    field of its own (the cost to it from every cell). The fields' memory is capped
//!    ([`MAX_FIELD_ENTRIES`]): a huge map gets fewer candidates, never more memory.
//! 3. **Routes.** A seed starts as S → G, takes a first via-point drawn ∝ I_xy among
//!    *all* cells in reach (it needs no field: each of its legs leads to S, G or a
//!    candidate, which have one), then up to [`MAX_VIAS`] − 1 candidates drawn ∝ I_xy,
//!    each inserted where it lengthens the route least, as long as the lower bound fits.
//! 4. **Paths.** Each leg is the descent along the field of one of its ends: a shortest
//!    path on the traversable grid, as the GA's walks finish with. A path is kept only
//!    when its exact t_ETA (Eq. 2, turns included) is within t_exec and it is no longer
//!    than the chromosome bound ([`crate::limits`]); otherwise its last via-point is
//!    dropped and it is rebuilt. A route left with no via-point is the shortest path,
//!    which the first population holds already, and is not kept twice.
//!
//! With S = G (a robot whose next task is where it stands) every route is a loop:
//! S → v → S goes out and back via the turning point v, more via-points make a tour.
//!
//! The work is bounded: at most [`MAX_CANDIDATES`] + 1 Dijkstras (checked against the
//! plan's deadline and cancel between them), and per seed at most [`MAX_VIAS`] path
//! builds of at most the chromosome bound.
//!
//! Every draw comes from a ChaCha8 generator seeded by the request's seed on a stream of
//! its own ([`SEED_STREAM`]; the GA's walks use stream 0), so the seeds are the same bit
//! for bit for the same request, and seeding them does not change the walks the GA draws.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::eta::path_eta;
use crate::params::GaParams;
use crate::search::{descend_to_goal, distance_field, STRAIGHT};
use crate::world::{Cell, World};

/// Most via-point candidates with a field of their own.
pub const MAX_CANDIDATES: usize = 12;
/// Most via-points on one seed's route.
pub const MAX_VIAS: usize = 6;
/// Most field entries (4 bytes each) the candidates' fields may hold together: 16 MB,
/// the memory `max_population_cells`' default allows a population. The built-in world
/// (10,000 cells) gets all [`MAX_CANDIDATES`]; a 1.7-million-cell warehouse gets 2.
pub const MAX_FIELD_ENTRIES: usize = 4_000_000;
/// The ChaCha8 stream the seeds draw from.
pub const SEED_STREAM: u64 = 1;

/// What seeding needs of a plan.
#[derive(Debug, Clone, Copy)]
pub struct SeedProblem<'a> {
    pub world: &'a World,
    pub params: &'a GaParams,
    pub start: Cell,
    pub goal: Cell,
    pub t_exec: f64,
    /// Cost to G from every cell ([`distance_field`]).
    pub goal_field: &'a [u32],
    /// The longest chromosome ([`crate::ga::GaOptions::max_path_cells`]).
    pub max_path_cells: usize,
}

/// The via-point seeds of one plan.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ViaSeeds {
    /// Paths from S to G, each within t_exec and the chromosome bound.
    pub paths: Vec<Vec<Cell>>,
    /// The candidates drawn (step 2 of the module doc), in draw order.
    pub candidates: Vec<Cell>,
}

/// How many chromosomes of the first population are via-point seeds:
/// `round(via_share · population)`, leaving one place for the shortest path.
pub fn seed_count(params: &GaParams) -> usize {
    let share = (params.via_share * params.population as f64).round();
    (share.max(0.0) as usize).min(params.population.saturating_sub(1))
}

/// Builds up to `count` via-point seeds (the module doc says how). `stop` is asked
/// before each Dijkstra; when it says stop, seeding goes on with the fields it has.
pub fn via_paths(
    problem: &SeedProblem<'_>,
    count: usize,
    seed: u64,
    stop: &dyn Fn() -> bool,
) -> ViaSeeds {
    let world = problem.world;
    if count == 0 || problem.goal_field.len() != world.cell_count() || stop() {
        return ViaSeeds::default();
    }
    let own_start;
    let start_field: &[u32] = if problem.start == problem.goal {
        problem.goal_field
    } else {
        own_start = distance_field(world, problem.start);
        &own_start
    };
    let budget = budget_units(problem);
    let Some(reach) = Reach::new(world, start_field, problem.goal_field, budget) else {
        return ViaSeeds::default();
    };
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(SEED_STREAM);
    let candidates = draw_candidates(problem, &reach, &mut rng);
    let mut fields = Fields {
        world,
        start: (problem.start, start_field),
        goal: (problem.goal, problem.goal_field),
        candidates: Vec::with_capacity(candidates.len()),
    };
    for &c in &candidates {
        if stop() {
            break;
        }
        fields.candidates.push((c, distance_field(world, c)));
    }
    let weights: Vec<u64> = fields
        .candidates
        .iter()
        .map(|&(c, _)| reach.weight_of(c))
        .collect();
    let mut paths = Vec::with_capacity(count);
    let mut scratch = Vec::new();
    // Twice as many tries as seeds: a draw whose path does not fit is not retried.
    for _ in 0..count.saturating_mul(2) {
        if paths.len() == count {
            break;
        }
        if let Some(path) = one_seed(
            problem,
            &fields,
            &reach,
            &weights,
            budget,
            &mut rng,
            &mut scratch,
        ) {
            paths.push(path);
        }
    }
    ViaSeeds { paths, candidates }
}

/// The budget in cost units of [`crate::search`]: a path costing more cannot be within
/// t_exec (see [`STRAIGHT`]). Unbounded when moves cost no time (v_lin = 0).
fn budget_units(problem: &SeedProblem<'_>) -> u64 {
    let per_cell = problem.params.v_lin * problem.world.meta.resolution;
    if per_cell.is_nan() || per_cell <= 0.0 {
        return u64::MAX;
    }
    // The relative slack keeps a route whose cost equals the budget up to rounding.
    let units = problem.t_exec / per_cell * f64::from(STRAIGHT) * (1.0 + 1e-12);
    if units >= u64::MAX as f64 {
        u64::MAX
    } else {
        units.max(0.0).floor() as u64
    }
}

/// The cells in reach (step 1), with cumulative weights to draw them ∝ I_xy.
struct Reach {
    cells: Vec<Cell>,
    /// Inclusive prefix sums of the weights, in `cells` order.
    cumulative: Vec<u64>,
}

impl Reach {
    fn new(world: &World, to_start: &[u32], to_goal: &[u32], budget: u64) -> Option<Reach> {
        let in_reach = |i: usize| {
            let (s, g) = (to_start[i], to_goal[i]);
            s != u32::MAX && g != u32::MAX && u64::from(s) + u64::from(g) <= budget
        };
        let informative = (0..world.cell_count())
            .any(|i| in_reach(i) && world.information[i] > 0 && world.is_traversable(i as Cell));
        let mut cells = Vec::new();
        let mut cumulative = Vec::new();
        let mut total = 0u64;
        for i in 0..world.cell_count() {
            if !in_reach(i) || !world.is_traversable(i as Cell) {
                continue;
            }
            // ∝ I_xy; uniform over the cells in reach when none has information, so
            // that round trips on a blank map still get loops.
            let weight = if informative {
                u64::from(world.information[i])
            } else {
                1
            };
            if weight == 0 {
                continue;
            }
            total += weight;
            cells.push(i as Cell);
            cumulative.push(total);
        }
        (total > 0).then_some(Reach { cells, cumulative })
    }

    fn total(&self) -> u64 {
        self.cumulative.last().copied().unwrap_or(0)
    }

    fn draw(&self, rng: &mut ChaCha8Rng) -> Cell {
        let r = rng.random_range(0..self.total());
        let i = self.cumulative.partition_point(|&c| c <= r);
        self.cells[i.min(self.cells.len() - 1)]
    }

    fn weight_of(&self, cell: Cell) -> u64 {
        match self.cells.binary_search(&cell) {
            Ok(i) => self.cumulative[i] - i.checked_sub(1).map_or(0, |j| self.cumulative[j]),
            Err(_) => 0,
        }
    }
}

/// Step 2: candidates drawn ∝ I_xy, a perception window apart, not S or G.
fn draw_candidates(problem: &SeedProblem<'_>, reach: &Reach, rng: &mut ChaCha8Rng) -> Vec<Cell> {
    let world = problem.world;
    let wanted = MAX_CANDIDATES.min(MAX_FIELD_ENTRIES / world.cell_count().max(1));
    let window = problem.params.window();
    let side = window
        .iter()
        .map(|&(x, _)| x)
        .max()
        .zip(window.iter().map(|&(x, _)| x).min())
        .map_or(1, |(hi, lo)| (hi - lo + 1).max(1) as usize);
    let mut candidates: Vec<Cell> = Vec::with_capacity(wanted);
    for _ in 0..wanted * 16 {
        if candidates.len() == wanted {
            break;
        }
        let c = reach.draw(rng);
        if c != problem.start
            && c != problem.goal
            && candidates.iter().all(|&o| world.chebyshev(o, c) >= side)
        {
            candidates.push(c);
        }
    }
    candidates
}

/// S's and G's fields and the candidates'.
struct Fields<'a> {
    world: &'a World,
    start: (Cell, &'a [u32]),
    goal: (Cell, &'a [u32]),
    candidates: Vec<(Cell, Vec<u32>)>,
}

impl Fields<'_> {
    /// The field whose zero is `cell`, if there is one.
    fn to(&self, cell: Cell) -> Option<&[u32]> {
        if cell == self.goal.0 {
            Some(self.goal.1)
        } else if cell == self.start.0 {
            Some(self.start.1)
        } else {
            self.candidates
                .iter()
                .find(|(c, _)| *c == cell)
                .map(|(_, f)| f.as_slice())
        }
    }

    /// The shortest cost between two cells, if one of them has a field and they connect.
    fn cost(&self, a: Cell, b: Cell) -> Option<u64> {
        let d = match self.to(b) {
            Some(f) => f[a as usize],
            None => self.to(a)?[b as usize],
        };
        (d != u32::MAX).then_some(u64::from(d))
    }

    /// Appends the shortest path from `a` (the last cell of `out`) to `b`, without `a`.
    fn leg(&self, a: Cell, b: Cell, out: &mut Vec<Cell>) -> bool {
        if let Some(f) = self.to(b) {
            return descend_to_goal(self.world, f, out);
        }
        let Some(f) = self.to(a) else {
            return false;
        };
        // Moves are symmetric: the descent from b to a, reversed, goes from a to b.
        let mut back = vec![b];
        if !descend_to_goal(self.world, f, &mut back) {
            return false;
        }
        out.extend(back.iter().rev().skip(1));
        true
    }

    /// The path through `stops`, in order, into `out`.
    fn build(&self, stops: &[Cell], out: &mut Vec<Cell>) -> bool {
        out.clear();
        let Some(&first) = stops.first() else {
            return false;
        };
        out.push(first);
        stops.windows(2).all(|pair| self.leg(pair[0], pair[1], out))
    }
}

/// Steps 3 and 4 for one seed: `None` when no route with a via-point fits.
fn one_seed(
    problem: &SeedProblem<'_>,
    fields: &Fields<'_>,
    reach: &Reach,
    weights: &[u64],
    budget: u64,
    rng: &mut ChaCha8Rng,
    scratch: &mut Vec<Cell>,
) -> Option<Vec<Cell>> {
    let (start, goal) = (problem.start, problem.goal);
    let vias = rng.random_range(1..=MAX_VIAS);
    let first = reach.draw(rng);
    if first == start || first == goal {
        return None;
    }
    let mut stops = vec![start, first, goal];
    let mut units = fields.cost(start, first)? + fields.cost(first, goal)?;
    if units > budget {
        return None;
    }
    // The via-points in the order they were inserted, to drop the last one first.
    let mut inserted = vec![first];
    let total: u64 = weights.iter().sum();
    for _ in 1..vias {
        if total == 0 {
            break;
        }
        let r = rng.random_range(0..total);
        let mut acc = 0;
        let pick = weights.iter().position(|&w| {
            acc += w;
            r < acc
        });
        let Some(c) = pick.map(|i| fields.candidates[i].0) else {
            break;
        };
        if stops.contains(&c) {
            continue;
        }
        // The cheapest place for c: the least added cost between two consecutive stops.
        let best = stops
            .windows(2)
            .enumerate()
            .filter_map(|(j, pair)| {
                let added = fields.cost(pair[0], c)? + fields.cost(c, pair[1])?;
                Some((added.saturating_sub(fields.cost(pair[0], pair[1])?), j + 1))
            })
            .min();
        if let Some((delta, at)) = best {
            if units.saturating_add(delta) <= budget {
                stops.insert(at, c);
                units += delta;
                inserted.push(c);
            }
        }
    }
    // Step 4: the exact t_ETA decides; drop the last via-point until the path fits.
    while !inserted.is_empty() {
        if fields.build(&stops, scratch)
            && scratch.len() <= problem.max_path_cells
            && path_eta(problem.world, problem.params, scratch) <= problem.t_exec
        {
            return Some(scratch.clone());
        }
        let last = inserted.pop()?;
        stops.retain(|&s| s != last);
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_proto::map::{GridMeta, Origin};
    use roam_world::grid::Grid;

    /// A 40 × 30 open world whose information is one 80-scored square in the top right.
    fn world() -> World {
        let meta = GridMeta {
            width: 40,
            height: 30,
            resolution: 0.2,
            origin: Origin::default(),
        };
        let mut info = Grid::filled(meta, 0u8);
        for y in 20..28 {
            for x in 30..38 {
                info.cells[y * 40 + x] = 80;
            }
        }
        World::new(&Grid::filled(meta, 0i8), &info, 0.25).expect("world")
    }

    fn problem<'a>(world: &'a World, params: &'a GaParams, field: &'a [u32]) -> SeedProblem<'a> {
        SeedProblem {
            world,
            params,
            start: world.cell(2, 2),
            goal: world.cell(2, 2),
            t_exec: 60.0,
            goal_field: field,
            max_path_cells: 151,
        }
    }

    #[test]
    fn seeds_are_loops_within_budget_through_the_information() {
        let world = world();
        let params = GaParams::default();
        let field = distance_field(&world, world.cell(2, 2));
        let p = problem(&world, &params, &field);
        let seeds = via_paths(&p, 20, 7, &|| false);
        assert_eq!(seeds.paths.len(), 20);
        assert!(!seeds.candidates.is_empty());
        for c in &seeds.candidates {
            let (x, y) = world.xy(*c);
            assert!((30..38).contains(&x) && (20..28).contains(&y), "{x}, {y}");
        }
        for path in &seeds.paths {
            assert_eq!(path.first(), Some(&p.start));
            assert_eq!(path.last(), Some(&p.goal));
            assert!(path.windows(2).all(|w| world.is_legal_move(w[0], w[1])));
            assert!(path_eta(&world, &params, path) <= p.t_exec);
            assert!(path.len() <= p.max_path_cells);
            assert!(
                path.iter().any(|&c| world.information[c as usize] > 0),
                "every seed goes through the informative square"
            );
        }
        // The same seed, the same seeds; another seed, others.
        assert_eq!(via_paths(&p, 20, 7, &|| false), seeds);
        assert_ne!(via_paths(&p, 20, 8, &|| false).paths, seeds.paths);
    }

    #[test]
    fn out_of_reach_information_gives_no_seed_and_zero_asks_no_work() {
        let world = world();
        let params = GaParams::default();
        let field = distance_field(&world, world.cell(2, 2));
        // 10 s: 25 straight cells, out and back 12; the square is 28 cells away.
        let short = SeedProblem {
            t_exec: 10.0,
            ..problem(&world, &params, &field)
        };
        let seeds = via_paths(&short, 10, 1, &|| false);
        assert!(
            seeds
                .paths
                .iter()
                .all(|p| p.iter().all(|&c| world.information[c as usize] == 0)),
            "nothing informative is in reach"
        );
        // None of the map is informative in reach: loops are drawn uniformly.
        assert!(!seeds.paths.is_empty());
        let p = problem(&world, &params, &field);
        assert_eq!(via_paths(&p, 0, 1, &|| false), ViaSeeds::default());
        // Stopped before any work: nothing.
        assert_eq!(via_paths(&p, 10, 1, &|| true), ViaSeeds::default());
    }

    #[test]
    fn the_share_leaves_room_for_the_shortest_path() {
        let mut params = GaParams::default();
        assert_eq!(seed_count(&params), 50);
        params.via_share = 1.0;
        assert_eq!(seed_count(&params), 199);
        params.via_share = 0.0;
        assert_eq!(seed_count(&params), 0);
    }
}
