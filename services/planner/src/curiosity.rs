//! The fitness of a path (paper 000 Eqs. 1, 3–7) under the three curiosity models
//! (Eqs. 8–10).
//!
//! Walking the path gene by gene, the evaluator perceives the window around each cell
//! (Eq. 3, see [`GaParams::window`]). A cell counts once per path: every model "holds
//! internal information maps, marking cells that have been visited ... as not
//! containing more useful information" (§II.B), so cells already perceived along the
//! same path are masked. The masking uses a stamp per cell, so evaluating a path costs
//! O(L · window) with no clearing between paths. After a move, only the cells that
//! enter the window need a look: every cell of the previous window is already stamped,
//! so for d = 3 a straight move checks 4 cells and a diagonal 7 instead of 16.
//!
//! - Model 0 (Eq. 8): I_0 per newly perceived cell, whatever its score.
//! - Model I (Eq. 9): `M = max(I · (1 − w_t / (t_s + 1) − w_n · (n_I − 1)), 0)`.
//!   Ambiguity: roam counts one experience of stimulus I per gene that newly perceives
//!   at least one cell of score I (not one per cell), n_I being the number of such
//!   genes so far including this one, and t_s the path time (Eq. 2) since the previous
//!   gene that experienced I (t_s = ∞ for the first, so the time term vanishes).
//!   Score 0 carries no stimulus. Stimuli are counted per score value in tables of
//!   `MAX_INFORMATION_SCORE + 1` entries; a [`World`] clamps its scores to that range
//!   (see [`crate::world::MAX_INFORMATION_SCORE`]) and the lookup clamps again, so no
//!   score can index past the tables.
//! - Model II (Eq. 10): `M = |H − I|` with H the mean of the cell's heuristic block.
//!   Both maps are updated along the path (§II.B.3): a perceived cell's I becomes 0 and
//!   its block's mean drops accordingly. The paper recomputed block averages, which
//!   made Model II slow; roam keeps each block's sum and count and updates the sum in
//!   O(1) per perceived cell, so Model II costs about what Model I does.

use roam_proto::planner::{FitnessTerms, PlannerModel};

use crate::eta::step_time;
use crate::params::GaParams;
use crate::world::{Cell, World, MAX_INFORMATION_SCORE, MOVES};

/// Entries of Model I's per-score tables: one per score 0..=MAX_INFORMATION_SCORE.
const SCORES: usize = MAX_INFORMATION_SCORE as usize + 1;

/// The curiosity model that scores information (the GA's F_1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Model {
    Coverage,
    Novelty,
    Heterogeneity,
}

impl Model {
    /// The model of a planner choice; `None` for the shortest-path baseline.
    pub fn of(choice: PlannerModel) -> Option<Model> {
        match choice {
            PlannerModel::Shortest => None,
            PlannerModel::Model0 => Some(Model::Coverage),
            PlannerModel::Model1 => Some(Model::Novelty),
            PlannerModel::Model2 => Some(Model::Heterogeneity),
            // The greedy planner scores with Model I (crate::greedy), and the anytime
            // portfolio with it (its GA runs Model I).
            PlannerModel::Greedy | PlannerModel::Anytime => Some(Model::Novelty),
        }
    }
}

/// What evaluating one path gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Evaluation {
    pub fitness: FitnessTerms,
    /// Σ M_n before the weight W_1.
    pub model_information: f64,
    pub t_eta: f64,
    pub reaches_goal: bool,
}

/// For each of the eight moves, the offsets `o` of `window` whose cell is new after
/// the move: `o + move` is not an offset of the window.
pub fn entering_offsets(window: &[(i32, i32)]) -> [Vec<(i32, i32)>; 8] {
    std::array::from_fn(|dir| {
        let (mx, my) = MOVES[dir];
        window
            .iter()
            .copied()
            .filter(|&(ox, oy)| !window.contains(&(ox + mx, oy + my)))
            .collect()
    })
}

/// Scores paths; holds the scratch state so that evaluating allocates nothing.
#[derive(Debug)]
pub struct Evaluator<'a> {
    world: &'a World,
    params: &'a GaParams,
    model: Model,
    goal: Cell,
    t_exec: f64,
    window: Vec<(i32, i32)>,
    /// Per move direction, the window offsets whose cells are new after that move.
    entering: [Vec<(i32, i32)>; 8],
    /// Eq. 2 time of a move, by previous direction (8: none) and direction.
    step_times: [[f64; 8]; 9],
    stamp: Vec<u32>,
    current: u32,
    // Model II: block sums as this path has changed them.
    block_sums: Vec<f64>,
}

/// The walk's running state after a gene: all that scoring the rest of a path needs
/// besides which cells are already perceived.
#[derive(Debug, Clone, Copy)]
pub struct WalkState {
    t: f64,
    /// The direction of the last move (8: none yet).
    prev_dir: usize,
    cx: usize,
    cy: usize,
    information: f64,
    localizability: f64,
    // Model I: per score value, experiences so far, time of the last, gene of the last.
    experiences: [u32; SCORES],
    last_time: [f64; SCORES],
    last_gene: [u32; SCORES],
    factor: [f64; SCORES],
}

impl WalkState {
    fn at(world: &World, first: Option<&Cell>) -> Self {
        let (cx, cy) = first.map_or((0, 0), |&c| world.xy(c));
        WalkState {
            t: 0.0,
            prev_dir: 8,
            cx,
            cy,
            information: 0.0,
            localizability: 0.0,
            experiences: [0; SCORES],
            last_time: [f64::NEG_INFINITY; SCORES],
            last_gene: [u32::MAX; SCORES],
            factor: [0.0; SCORES],
        }
    }
}

/// A path scored once, kept so that paths sharing its start can be scored from one of
/// its marked genes onward ([`Evaluator::evaluate_after`]): the gene at which it first
/// perceived each cell, and the walk's state after each mark. The greedy planner tries
/// hundreds of routes a round that differ from the current one only after one stop;
/// scoring them from that stop gives the same [`Evaluation`], bit for bit, as scoring
/// them whole.
#[derive(Debug, Clone, Default)]
pub struct Prefix {
    path: Vec<Cell>,
    /// Per cell, the first gene that perceived it (`u32::MAX`: none).
    first_seen: Vec<u32>,
    /// (gene, the state after it), in the order of the marks.
    marks: Vec<(u32, WalkState)>,
}

impl Prefix {
    /// The path scored.
    pub fn path(&self) -> &[Cell] {
        &self.path
    }
}

impl<'a> Evaluator<'a> {
    pub fn new(
        world: &'a World,
        params: &'a GaParams,
        model: Model,
        goal: Cell,
        t_exec: f64,
    ) -> Self {
        Evaluator {
            world,
            params,
            model,
            goal,
            t_exec,
            window: params.window(),
            entering: entering_offsets(&params.window()),
            step_times: std::array::from_fn(|prev| {
                std::array::from_fn(|dir| step_time(world, params, (prev < 8).then_some(prev), dir))
            }),
            stamp: vec![0; world.cell_count()],
            current: 0,
            block_sums: Vec::new(),
        }
    }

    /// A new stamp (no cell perceived yet) and Model II's block sums as the world has them.
    fn start_path(&mut self) {
        self.current = self.current.wrapping_add(1);
        if self.current == 0 {
            self.stamp.fill(0);
            self.current = 1;
        }
        if self.model == Model::Heterogeneity {
            self.block_sums.clear();
            self.block_sums.extend_from_slice(&self.world.block_sums);
        }
    }

    /// The fitness of `path` (Eqs. 1–7).
    pub fn evaluate(&mut self, path: &[Cell]) -> Evaluation {
        self.start_path();
        let mut state = WalkState::at(self.world, path.first());
        self.walk(&mut state, None, path, 0, |_| false, |_, _| {}, |_, _| {});
        self.finish(&state, path.last())
    }

    /// Scores `path` as [`Evaluator::evaluate`] does and keeps it in `prefix`, with the
    /// walk's state after each gene of `marks` (ascending).
    pub fn evaluate_prefix(
        &mut self,
        prefix: &mut Prefix,
        path: &[Cell],
        marks: &[usize],
    ) -> Evaluation {
        self.start_path();
        prefix.path.clear();
        prefix.path.extend_from_slice(path);
        prefix.first_seen.clear();
        prefix.first_seen.resize(self.world.cell_count(), u32::MAX);
        prefix.marks.clear();
        let mut state = WalkState::at(self.world, path.first());
        let (first_seen, kept) = (&mut prefix.first_seen, &mut prefix.marks);
        let mut next = 0;
        self.walk(
            &mut state,
            None,
            path,
            0,
            |_| false,
            |idx, gene| first_seen[idx] = gene,
            |gene, s| {
                while marks.get(next).is_some_and(|&m| m as u32 == gene) {
                    kept.push((gene, *s));
                    next += 1;
                }
            },
        );
        self.finish(&state, path.last())
    }

    /// The fitness of `prefix`'s path up to its `mark`-th marked gene followed by
    /// `tail`: equal to [`Evaluator::evaluate`] of that whole path, at the cost of the
    /// tail alone. `None` if there is no such mark.
    pub fn evaluate_after(
        &mut self,
        prefix: &Prefix,
        mark: usize,
        tail: &[Cell],
    ) -> Option<Evaluation> {
        let &(gene, state) = prefix.marks.get(mark)?;
        let cut = prefix.path.get(..=gene as usize)?;
        if self.model == Model::Heterogeneity {
            // Model II's block sums are not kept per mark: score the whole path.
            let whole: Vec<Cell> = cut.iter().chain(tail).copied().collect();
            return Some(self.evaluate(&whole));
        }
        self.start_path();
        let mut state = state;
        let first_seen = &prefix.first_seen;
        self.walk(
            &mut state,
            cut.last().copied(),
            tail,
            gene + 1,
            |idx| first_seen[idx] <= gene,
            |_, _| {},
            |_, _| {},
        );
        Some(self.finish(&state, tail.last().or(cut.last())))
    }

    /// Walks `cells` (genes `first_gene`…, after the cell `prev` if any), perceiving the
    /// window around each (Eq. 3). A cell counts if neither `seen_before` nor this walk
    /// has perceived it; `on_new` hears of each such cell, `on_gene` of the state after
    /// each gene.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn walk(
        &mut self,
        state: &mut WalkState,
        mut prev: Option<Cell>,
        cells: &[Cell],
        first_gene: u32,
        seen_before: impl Fn(usize) -> bool,
        mut on_new: impl FnMut(usize, u32),
        mut on_gene: impl FnMut(u32, &WalkState),
    ) {
        let (w, h) = (self.world.width() as i32, self.world.height() as i32);
        let costed = self.params.w_loc > 0.0 && !self.world.localizability.is_empty();
        for (j, &cell) in cells.iter().enumerate() {
            let gene = first_gene + j as u32;
            let mut moved = None;
            // The position is tracked move by move: no division per gene.
            if let Some(p) = prev {
                match self.world.move_between(p, cell, state.cx, state.cy) {
                    Some(dir) => {
                        state.t += self.step_times[state.prev_dir][dir];
                        state.prev_dir = dir;
                        moved = Some(dir);
                        state.cx = (state.cx as i64 + i64::from(MOVES[dir].0)) as usize;
                        state.cy = (state.cy as i64 + i64::from(MOVES[dir].1)) as usize;
                    }
                    None => (state.cx, state.cy) = self.world.xy(cell),
                }
            }
            prev = Some(cell);
            let (x, y) = (state.cx as i32, state.cy as i32);
            if costed {
                let peb =
                    f64::from(self.world.localizability[state.cy * self.world.width() + state.cx]);
                state.localizability += (peb - self.params.peb_free_m).max(0.0);
            }
            let count = moved.map_or(self.window.len(), |dir| self.entering[dir].len());
            for k in 0..count {
                let (dx, dy) = match moved {
                    Some(dir) => self.entering[dir][k],
                    None => self.window[k],
                };
                let (nx, ny) = (x + dx, y + dy);
                if nx < 0 || ny < 0 || nx >= w || ny >= h {
                    continue;
                }
                let idx = (ny * w + nx) as usize;
                if self.stamp[idx] == self.current || seen_before(idx) {
                    continue;
                }
                self.stamp[idx] = self.current;
                on_new(idx, gene);
                let t = state.t;
                state.information += self.gain(state, idx, gene, t);
            }
            on_gene(gene, state);
        }
    }

    /// The fitness terms of a walked path ending at `last` (Eqs. 1, 4–7).
    fn finish(&self, state: &WalkState, last: Option<&Cell>) -> Evaluation {
        let (t, information) = (state.t, state.information);
        let reaches_goal = last == Some(&self.goal);
        let p = self.params;
        let f1 = p.w1 * information;
        let f2 = if t < self.t_exec { p.w2 } else { 0.0 };
        let f3 = if reaches_goal { p.w3 } else { 0.0 };
        let f4 = -p.w4 * (t - self.t_exec).max(0.0);
        let f5 = -p.w5 * (self.t_exec - t).max(0.0);
        // roam's localizability cost (GaParams::w_loc, peb_free_m), not paper 000's.
        let f6 = -p.w_loc * state.localizability;
        Evaluation {
            fitness: FitnessTerms {
                f1_information: f1,
                f2_on_time: f2,
                f3_goal: f3,
                f4_overtime: f4,
                f5_idle: f5,
                f6_localizability: f6,
                total: f1 + f2 + f3 + f4 + f5 + f6,
            },
            model_information: information,
            t_eta: t,
            reaches_goal,
        }
    }

    /// M_xy of a newly perceived cell (Eqs. 8–10).
    #[inline(always)]
    fn gain(&mut self, state: &mut WalkState, idx: usize, gene: u32, t: f64) -> f64 {
        match self.model {
            Model::Coverage => self.params.coverage_gain,
            Model::Novelty => {
                // `information` is public: clamp again rather than trust every writer.
                let score = usize::from(self.world.information[idx].min(MAX_INFORMATION_SCORE));
                if score == 0 {
                    return 0.0;
                }
                if state.last_gene[score] != gene {
                    // A new experience of stimulus `score` at this gene (Eq. 9).
                    state.experiences[score] += 1;
                    let t_s = t - state.last_time[score];
                    let n = f64::from(state.experiences[score]);
                    let time_term = if t_s.is_finite() {
                        self.params.w_t / (t_s + 1.0)
                    } else {
                        0.0
                    };
                    state.factor[score] = (1.0 - time_term - self.params.w_n * (n - 1.0)).max(0.0);
                    state.last_time[score] = t;
                    state.last_gene[score] = gene;
                }
                score as f64 * state.factor[score]
            }
            Model::Heterogeneity => {
                let score = f64::from(self.world.information[idx]);
                let block = self.world.block_of[idx] as usize;
                let mean = self.block_sums[block] / f64::from(self.world.block_cells[block]);
                // Perceiving the cell sets its I to 0 in both maps (§II.B.3).
                self.block_sums[block] -= score;
                (mean - score).abs()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_proto::map::{GridMeta, Origin};
    use roam_world::grid::Grid;

    fn world_with_scores(scores: &[u8], width: u32) -> World {
        let meta = GridMeta {
            width,
            height: scores.len() as u32 / width,
            resolution: 0.2,
            origin: Origin::default(),
        };
        let information = Grid {
            meta,
            cells: scores.to_vec(),
        };
        World::new(&Grid::filled(meta, 0i8), &information, 0.25).expect("world")
    }

    /// Any u8 layer can be the information map, and a score above 100 would index past
    /// Model I's tables. A world clamps it to 100, so a 255 cell counts as a 100
    /// cell, and the clamping is reported.
    #[test]
    fn a_score_of_255_is_clamped_to_100_and_model_one_does_not_panic() {
        let mut scores = vec![0u8; 64];
        scores[8 * 3 + 4] = 255;
        scores[8 * 5 + 2] = 101;
        let loud = world_with_scores(&scores, 8);
        assert_eq!(
            loud.clamped,
            Some(crate::world::Clamped {
                cells: 2,
                first: (4, 3, 255)
            })
        );
        assert_eq!(loud.information[8 * 3 + 4], 100);
        scores[8 * 3 + 4] = 100;
        scores[8 * 5 + 2] = 100;
        let capped = world_with_scores(&scores, 8);
        assert_eq!(capped.clamped, None);
        let params = GaParams::default();
        let path: Vec<Cell> = (0..8).map(|x| 8 * 4 + x).collect();
        let goal = *path.last().expect("cells");
        for model in [Model::Coverage, Model::Novelty, Model::Heterogeneity] {
            let a = Evaluator::new(&loud, &params, model, goal, 60.0).evaluate(&path);
            let b = Evaluator::new(&capped, &params, model, goal, 60.0).evaluate(&path);
            assert_eq!(a, b, "{model:?}");
        }
        // A score written into the public field after the world was built is clamped
        // at the lookup too.
        let mut written = capped.clone();
        written.information[8 * 3 + 4] = 255;
        let c = Evaluator::new(&written, &params, Model::Novelty, goal, 60.0).evaluate(&path);
        let d = Evaluator::new(&capped, &params, Model::Novelty, goal, 60.0).evaluate(&path);
        assert_eq!(c, d);
        assert!(c.model_information > 0.0);
    }

    #[test]
    fn a_straight_move_brings_4_new_cells_and_a_diagonal_7_for_d3() {
        let entering = entering_offsets(&GaParams::default().window());
        for (dir, offsets) in entering.iter().enumerate() {
            assert_eq!(
                offsets.len(),
                if dir % 2 == 0 { 4 } else { 7 },
                "direction {dir}"
            );
        }
    }

    /// A walk of `steps` legal moves from `start`, each direction drawn from `moves`,
    /// staying on the grid.
    fn walk_from(world: &World, start: Cell, moves: &[u8]) -> Vec<Cell> {
        let mut path = vec![start];
        for &m in moves {
            let last = *path.last().expect("a start");
            if let Some(next) = world.step(last, usize::from(m % 8)) {
                path.push(next);
            }
        }
        path
    }

    proptest::proptest! {
        /// Scoring from a mark gives what scoring the whole path gives, bit for bit,
        /// for every model, with and without the localizability cost.
        #[test]
        fn scoring_after_a_mark_equals_scoring_the_whole_path(
            scores in proptest::collection::vec(0u8..=100, 24 * 16),
            base_moves in proptest::collection::vec(0u8..8, 1..60),
            tail_moves in proptest::collection::vec(0u8..8, 0..60),
            cut in 0usize..60,
            w_loc in proptest::prop_oneof![proptest::strategy::Just(0.0), 0.1f64..5.0],
        ) {
            let mut world = world_with_scores(&scores, 24);
            world.localizability = scores.iter().map(|&s| f32::from(s) / 50.0).collect();
            let params = GaParams { w_loc, ..GaParams::default() };
            let base = walk_from(&world, world.cell(12, 8), &base_moves);
            let cut = cut % base.len();
            let tail = walk_from(&world, base[cut], &tail_moves);
            let whole: Vec<Cell> = base[..=cut].iter().chain(&tail[1..]).copied().collect();
            let goal = *whole.last().expect("cells");
            for model in [Model::Coverage, Model::Novelty, Model::Heterogeneity] {
                let mut evaluator = Evaluator::new(&world, &params, model, goal, 30.0);
                let mut prefix = Prefix::default();
                let scored = evaluator.evaluate_prefix(&mut prefix, &base, &[0, cut]);
                proptest::prop_assert_eq!(scored, evaluator.evaluate(&base));
                let resumed = evaluator.evaluate_after(&prefix, 1, &tail[1..]);
                proptest::prop_assert_eq!(resumed, Some(evaluator.evaluate(&whole)), "{:?}", model);
                proptest::prop_assert_eq!(evaluator.evaluate_after(&prefix, 2, &tail), None);
            }
        }
    }
}
