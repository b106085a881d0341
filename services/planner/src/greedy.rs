//! A peer for the GA: greedy insertion of informative via-points by
//! information per second, with local improvement, within the budget. Model `greedy`.
//!
//! Paper 000 compares its GA only with a coverage GA (Model 0) and the shortest path. A
//! user would ask whether a simple informative-path heuristic does as well, so roam
//! plans one in the same service, scored by the same fitness (Eqs. 1, 3–7 with Model
//! I, Eq. 9) on the same planning grid:
//!
//! 1. **Candidates.** Cells on a lattice a perception window apart (so no two show the
//!    same cells), traversable, in reach of the budget (the distance from S plus the
//!    distance to G, at v_lin, a lower bound of Eq. 2, fits t_exec), whose window holds
//!    information. At most [`MAX_CANDIDATES`], the most informative first.
//! 2. **Greedy insertion.** The route starts as the floor path (the shortest path that
//!    fits, else the fastest). Each round, every unused candidate is tried at the place
//!    in the route where it adds the least distance; its legs are shortest paths (the
//!    descents along the distance fields of the route's stops). The one with the most
//!    new model information per second of added Eq. 2 time whose route still fits
//!    t_exec is inserted, and its field computed. Rounds go on until nothing fits or
//!    adds information.
//! 3. **Local improvement.** Then, until nothing improves or the deadline: each
//!    via-point in turn is removed and the candidate (or none) that makes the fittest
//!    route in its place is put back, if that is fitter than the route was (Eq. 1, the
//!    GA's objective).
//!
//! No randomness: the same request gives the same route. Memory: one distance field per
//! stop, at most [`crate::seeds::MAX_FIELD_ENTRIES`] entries in all, so a huge planning
//! grid gets fewer via-points, never more memory. Work: a round evaluates each
//! candidate once (O(L · window) each).

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use crate::curiosity::{Evaluation, Evaluator, Model, Prefix};
use crate::params::GaParams;
use crate::search::{descend_to_goal, distance_field, STRAIGHT};
use crate::seeds::MAX_FIELD_ENTRIES;
use crate::world::{Cell, World};

/// Most candidates tried per round.
pub const MAX_CANDIDATES: usize = 400;
/// Most via-points on a route.
pub const MAX_VIAS: usize = 48;
/// The work of one greedy plan in evaluations of a longest path, for the queue's
/// estimate (`crate::plan::work`): a few dozen rounds over the candidates.
pub const WORK_EVALUATIONS: u64 = (MAX_CANDIDATES as u64) * 40;

/// What the greedy planner needs.
#[derive(Debug)]
pub struct GreedyProblem<'a> {
    pub world: &'a World,
    pub params: &'a GaParams,
    pub start: Cell,
    pub goal: Cell,
    pub t_exec: f64,
    /// The route it starts from: a path from S to G within t_exec.
    pub floor: &'a [Cell],
    /// Cost to G from every cell ([`distance_field`]).
    pub goal_field: &'a [u32],
}

/// What it returns.
#[derive(Debug, Clone)]
pub struct GreedyResult {
    pub path: Vec<Cell>,
    pub evaluation: Evaluation,
    /// Rounds of insertion and improvement done.
    pub rounds: u32,
    /// Evaluations done.
    pub evaluations: u64,
    pub evaluated_genes: u64,
    /// Whether it stopped at its deadline or a cancel rather than when nothing improved.
    pub interrupted: bool,
}

struct Route<'a> {
    world: &'a World,
    /// S, the via-points, G.
    stops: Vec<Cell>,
    /// The distance field of each stop (the cost to it from every cell).
    fields: Vec<std::rc::Rc<Vec<u32>>>,
    /// `legs[k]`: the cells after `stops[k]` up to and including `stops[k + 1]`, the
    /// descent along the next stop's field. A change re-descends only its own legs.
    legs: Vec<Vec<Cell>>,
}

/// A change to the route that step 2 or 3 tries.
#[derive(Debug, Clone, Copy)]
enum Change {
    /// `v` inserted before stop `at` (1 ≤ at < stops).
    Insert { at: usize, v: Cell },
    /// Via-point `i` removed and `v`, if any, put in its place.
    Replace { i: usize, v: Option<Cell> },
}

/// The cells after `from` up to and including the field's own stop: the descent
/// along `field`.
fn leg_to(world: &World, from: Cell, field: &[u32]) -> Option<Vec<Cell>> {
    let mut path = vec![from];
    descend_to_goal(world, field, &mut path).then(|| path.split_off(1))
}

/// The cells after the field's own stop up to and including `to`: the descent from
/// `to` along `field`, reversed (`to` has no field yet).
fn leg_from(world: &World, field: &[u32], to: Cell) -> Option<Vec<Cell>> {
    let mut back = vec![to];
    if !descend_to_goal(world, field, &mut back) {
        return None;
    }
    back.pop();
    back.reverse();
    Some(back)
}

impl Route<'_> {
    fn new<'w>(
        world: &'w World,
        stops: Vec<Cell>,
        fields: Vec<std::rc::Rc<Vec<u32>>>,
    ) -> Option<Route<'w>> {
        let legs = stops
            .windows(2)
            .zip(&fields[1..])
            .map(|(pair, field)| leg_to(world, pair[0], field))
            .collect::<Option<Vec<_>>>()?;
        Some(Route {
            world,
            stops,
            fields,
            legs,
        })
    }

    /// The path through the stops.
    fn path(&self) -> Vec<Cell> {
        let mut path = Vec::with_capacity(1 + self.legs.iter().map(Vec::len).sum::<usize>());
        path.push(self.stops[0]);
        for leg in &self.legs {
            path.extend_from_slice(leg);
        }
        path
    }

    /// The gene (index in [`Route::path`]) of each stop.
    fn stop_genes(&self) -> Vec<usize> {
        std::iter::once(0)
            .chain(self.legs.iter().scan(0, |gene, leg| {
                *gene += leg.len();
                Some(*gene)
            }))
            .collect()
    }

    /// The legs `change` puts in place of its stretch, and the stop the route is
    /// unchanged up to.
    fn new_legs(&self, change: Change) -> Option<(usize, Vec<Vec<Cell>>)> {
        let world = self.world;
        match change {
            Change::Insert { at, v } => Some((
                at - 1,
                vec![
                    leg_from(world, &self.fields[at - 1], v)?,
                    leg_to(world, v, &self.fields[at])?,
                ],
            )),
            Change::Replace { i, v: Some(v) } => Some((
                i - 1,
                vec![
                    leg_from(world, &self.fields[i - 1], v)?,
                    leg_to(world, v, &self.fields[i + 1])?,
                ],
            )),
            Change::Replace { i, v: None } => Some((
                i - 1,
                vec![leg_to(world, self.stops[i - 1], &self.fields[i + 1])?],
            )),
        }
    }

    /// The legs after `change`'s stretch that it leaves as they are.
    fn kept_legs(&self, change: Change) -> &[Vec<Cell>] {
        match change {
            Change::Insert { at, .. } => &self.legs[at..],
            Change::Replace { i, .. } => &self.legs[i + 1..],
        }
    }

    /// Makes `change` with its `new` legs.
    fn apply(&mut self, change: Change, new: Vec<Vec<Cell>>) {
        let world = self.world;
        let field = |v: Cell| std::rc::Rc::new(distance_field(world, v));
        match change {
            Change::Insert { at, v } => {
                self.stops.insert(at, v);
                self.fields.insert(at, field(v));
                self.legs.splice(at - 1..at, new);
            }
            Change::Replace { i, v } => {
                self.stops.remove(i);
                self.fields.remove(i);
                if let Some(v) = v {
                    self.stops.insert(i, v);
                    self.fields.insert(i, field(v));
                }
                self.legs.splice(i - 1..i + 1, new);
            }
        }
    }

    /// Where inserting `v` adds the least distance (cost units), and how much.
    fn cheapest_place(&self, v: Cell) -> Option<(usize, u64)> {
        (1..self.stops.len())
            .filter_map(|i| {
                let (fa, fb) = (&self.fields[i - 1], &self.fields[i]);
                let (av, vb) = (fa[v as usize], fb[v as usize]);
                let ab = fb[self.stops[i - 1] as usize];
                (av != u32::MAX && vb != u32::MAX && ab != u32::MAX).then(|| {
                    let added = (u64::from(av) + u64::from(vb)).saturating_sub(u64::from(ab));
                    (i, added)
                })
            })
            .min_by_key(|&(i, added)| (added, i))
    }
}

/// The current route scored, and the scoring of changes to it from the stop each
/// leaves unchanged ([`Evaluator::evaluate_after`]).
struct Scorer<'w> {
    evaluator: Evaluator<'w>,
    prefix: Prefix,
    tail: Vec<Cell>,
    evaluations: u64,
    genes: u64,
}

impl<'w> Scorer<'w> {
    /// Scores `path` whole.
    fn evaluate(&mut self, path: &[Cell]) -> Evaluation {
        self.evaluations += 1;
        self.genes += path.len() as u64;
        self.evaluator.evaluate(path)
    }

    /// Scores the route as it now is and keeps it as the prefix of the changes tried next.
    fn settle(&mut self, route: &Route<'_>) -> Evaluation {
        let path = route.path();
        self.evaluations += 1;
        self.genes += path.len() as u64;
        self.evaluator
            .evaluate_prefix(&mut self.prefix, &path, &route.stop_genes())
    }

    /// The route after `change` scored (the same [`Evaluation`] as scoring its path
    /// whole), with the new legs; `None` if a leg cannot be descended.
    fn try_change(
        &mut self,
        route: &Route<'_>,
        change: Change,
    ) -> Option<(Evaluation, Vec<Vec<Cell>>)> {
        let (kept_to, new) = route.new_legs(change)?;
        self.tail.clear();
        for leg in new.iter().chain(route.kept_legs(change)) {
            self.tail.extend_from_slice(leg);
        }
        self.evaluations += 1;
        self.genes += (self.prefix.path().len() + self.tail.len()) as u64;
        let e = self
            .evaluator
            .evaluate_after(&self.prefix, kept_to, &self.tail)?;
        Some((e, new))
    }
}

/// The candidates of step 1, most informative first.
fn candidates(problem: &GreedyProblem<'_>, start_field: &[u32]) -> Vec<Cell> {
    let world = problem.world;
    let window = problem.params.window();
    let side = window
        .iter()
        .map(|&(x, _)| x)
        .max()
        .zip(window.iter().map(|&(x, _)| x).min())
        .map_or(1, |(hi, lo)| (hi - lo + 1).max(1) as usize);
    let per_unit = problem.params.v_lin * world.meta.resolution / f64::from(STRAIGHT);
    let (w, h) = (world.width() as i32, world.height() as i32);
    let mut found: Vec<(u64, Cell)> = Vec::new();
    for y in (side / 2..world.height()).step_by(side) {
        for x in (side / 2..world.width()).step_by(side) {
            let c = world.cell(x, y);
            let (s, g) = (start_field[c as usize], problem.goal_field[c as usize]);
            if !world.is_traversable(c) || s == u32::MAX || g == u32::MAX {
                continue;
            }
            if (f64::from(s) + f64::from(g)) * per_unit > problem.t_exec {
                continue;
            }
            let value: u64 = window
                .iter()
                .filter_map(|&(dx, dy)| {
                    let (nx, ny) = (x as i32 + dx, y as i32 + dy);
                    (nx >= 0 && ny >= 0 && nx < w && ny < h)
                        .then(|| u64::from(world.information[(ny * w + nx) as usize]))
                })
                .sum();
            if value > 0 && c != problem.start && c != problem.goal {
                found.push((value, c));
            }
        }
    }
    found.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
    found.truncate(MAX_CANDIDATES);
    found.into_iter().map(|(_, c)| c).collect()
}

/// Plans (see the module doc) until nothing improves, `deadline`, or `cancel`.
pub fn run(problem: &GreedyProblem<'_>, deadline: Instant, cancel: &AtomicBool) -> GreedyResult {
    let world = problem.world;
    let mut scorer = Scorer {
        evaluator: Evaluator::new(
            world,
            problem.params,
            Model::Novelty,
            problem.goal,
            problem.t_exec,
        ),
        prefix: Prefix::default(),
        tail: Vec::new(),
        evaluations: 0,
        genes: 0,
    };
    let floor = problem.floor.to_vec();
    let mut best_eval = scorer.evaluate(&floor);
    let mut best_path = floor;
    let stop = || cancel.load(Ordering::Relaxed) || Instant::now() >= deadline;
    let start_field = std::rc::Rc::new(distance_field(world, problem.start));
    let goal_field = std::rc::Rc::new(problem.goal_field.to_vec());
    let pool = candidates(problem, &start_field);
    let max_vias = MAX_VIAS.min((MAX_FIELD_ENTRIES / world.cell_count().max(1)).saturating_sub(2));
    // The route as routed (its legs are shortest paths, not the floor path itself).
    let Some(mut route) = Route::new(
        world,
        vec![problem.start, problem.goal],
        vec![start_field, goal_field],
    ) else {
        return GreedyResult {
            path: best_path,
            evaluation: best_eval,
            rounds: 0,
            evaluations: scorer.evaluations,
            evaluated_genes: scorer.genes,
            interrupted: false,
        };
    };
    let mut current = scorer.settle(&route);
    let mut used = vec![false; pool.len()];
    let mut rounds = 0u32;
    let mut interrupted = false;
    let fits = |e: &Evaluation| e.t_eta <= problem.t_exec && e.reaches_goal;
    // Step 2: insertion by information per second.
    while route.stops.len() - 2 < max_vias {
        if stop() {
            interrupted = true;
            break;
        }
        rounds += 1;
        let mut pick: Option<(f64, usize, Change, Vec<Vec<Cell>>)> = None;
        for (k, &v) in pool.iter().enumerate() {
            if used[k] || route.stops.contains(&v) {
                continue;
            }
            let Some((at, _)) = route.cheapest_place(v) else {
                continue;
            };
            let change = Change::Insert { at, v };
            let Some((e, legs)) = scorer.try_change(&route, change) else {
                continue;
            };
            let gained = e.model_information - current.model_information;
            if !fits(&e) || gained <= 0.0 {
                continue;
            }
            let seconds = (e.t_eta - current.t_eta).max(1e-6);
            let rate = gained / seconds;
            if pick.as_ref().is_none_or(|p| rate > p.0) {
                pick = Some((rate, k, change, legs));
            }
        }
        let Some((_, k, change, legs)) = pick else {
            break;
        };
        used[k] = true;
        route.apply(change, legs);
        current = scorer.settle(&route);
    }
    // Step 3: remove each via-point and put back the fittest replacement, or none.
    let mut improved = true;
    while improved && !interrupted {
        improved = false;
        let mut i = 1;
        while i + 1 < route.stops.len() {
            if stop() {
                interrupted = true;
                break;
            }
            rounds += 1;
            let mut best: Option<(f64, Option<usize>, Vec<Vec<Cell>>)> = None;
            let removal = Change::Replace { i, v: None };
            if let Some((e, legs)) = scorer.try_change(&route, removal) {
                if fits(&e) {
                    best = Some((e.fitness.total, None, legs));
                }
            }
            for (k, &v) in pool.iter().enumerate() {
                if used[k] || route.stops.contains(&v) {
                    continue;
                }
                let change = Change::Replace { i, v: Some(v) };
                let Some((e, legs)) = scorer.try_change(&route, change) else {
                    continue;
                };
                if fits(&e) && best.as_ref().is_none_or(|b| e.fitness.total > b.0) {
                    best = Some((e.fitness.total, Some(k), legs));
                }
            }
            match best {
                Some((total, replacement, legs)) if total > current.fitness.total => {
                    let removed = route.stops[i];
                    if let Some(k) = pool.iter().position(|&c| c == removed) {
                        used[k] = false;
                    }
                    if let Some(k) = replacement {
                        used[k] = true;
                    }
                    let v = replacement.map(|k| pool[k]);
                    route.apply(Change::Replace { i, v }, legs);
                    if v.is_some() {
                        i += 1;
                    }
                    current = scorer.settle(&route);
                    improved = true;
                }
                _ => i += 1,
            }
        }
    }
    if fits(&current) && current.fitness.total > best_eval.fitness.total {
        best_eval = current;
        best_path = scorer.prefix.path().to_vec();
    }
    GreedyResult {
        path: best_path,
        evaluation: best_eval,
        rounds,
        evaluations: scorer.evaluations,
        evaluated_genes: scorer.genes,
        interrupted,
    }
}
