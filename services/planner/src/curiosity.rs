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
            // The greedy planner scores with Model I (crate::greedy).
            PlannerModel::Greedy => Some(Model::Novelty),
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
    // Model I: per score value, experiences so far, time of the last, gene of the last.
    experiences: [u32; SCORES],
    last_time: [f64; SCORES],
    last_gene: [u32; SCORES],
    factor: [f64; SCORES],
    // Model II: block sums as this path has changed them.
    block_sums: Vec<f64>,
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
            experiences: [0; SCORES],
            last_time: [f64::NEG_INFINITY; SCORES],
            last_gene: [u32::MAX; SCORES],
            factor: [0.0; SCORES],
            block_sums: Vec::new(),
        }
    }

    fn next_stamp(&mut self) {
        self.current = self.current.wrapping_add(1);
        if self.current == 0 {
            self.stamp.fill(0);
            self.current = 1;
        }
    }

    /// The fitness of `path` (Eqs. 1–7).
    pub fn evaluate(&mut self, path: &[Cell]) -> Evaluation {
        self.next_stamp();
        match self.model {
            Model::Novelty => {
                self.experiences = [0; SCORES];
                self.last_time = [f64::NEG_INFINITY; SCORES];
                self.last_gene = [u32::MAX; SCORES];
            }
            Model::Heterogeneity => {
                self.block_sums.clear();
                self.block_sums.extend_from_slice(&self.world.block_sums);
            }
            Model::Coverage => {}
        }
        let (w, h) = (self.world.width() as i32, self.world.height() as i32);
        let mut t = 0.0;
        let mut prev_dir = 8;
        let mut information = 0.0;
        let mut localizability = 0.0;
        let costed = self.params.w_loc > 0.0 && !self.world.localizability.is_empty();
        // The position is tracked move by move: no division per gene.
        let (mut cx, mut cy) = path.first().map_or((0, 0), |&c| self.world.xy(c));
        for (gene, &cell) in path.iter().enumerate() {
            let mut moved = None;
            if gene > 0 {
                match self.world.move_between(path[gene - 1], cell, cx, cy) {
                    Some(dir) => {
                        t += self.step_times[prev_dir][dir];
                        prev_dir = dir;
                        moved = Some(dir);
                        cx = (cx as i64 + i64::from(MOVES[dir].0)) as usize;
                        cy = (cy as i64 + i64::from(MOVES[dir].1)) as usize;
                    }
                    None => (cx, cy) = self.world.xy(cell),
                }
            }
            let (x, y) = (cx as i32, cy as i32);
            if costed {
                let peb = f64::from(self.world.localizability[cy * self.world.width() + cx]);
                localizability += (peb - self.params.peb_free_m).max(0.0);
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
                if self.stamp[idx] == self.current {
                    continue;
                }
                self.stamp[idx] = self.current;
                information += self.gain(idx, gene as u32, t);
            }
        }
        let reaches_goal = path.last() == Some(&self.goal);
        let p = self.params;
        let f1 = p.w1 * information;
        let f2 = if t < self.t_exec { p.w2 } else { 0.0 };
        let f3 = if reaches_goal { p.w3 } else { 0.0 };
        let f4 = -p.w4 * (t - self.t_exec).max(0.0);
        let f5 = -p.w5 * (self.t_exec - t).max(0.0);
        // roam's localizability cost (GaParams::w_loc, peb_free_m), not paper 000's.
        let f6 = -p.w_loc * localizability;
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
    #[inline]
    fn gain(&mut self, idx: usize, gene: u32, t: f64) -> f64 {
        match self.model {
            Model::Coverage => self.params.coverage_gain,
            Model::Novelty => {
                // `information` is public: clamp again rather than trust every writer.
                let score = usize::from(self.world.information[idx].min(MAX_INFORMATION_SCORE));
                if score == 0 {
                    return 0.0;
                }
                if self.last_gene[score] != gene {
                    // A new experience of stimulus `score` at this gene (Eq. 9).
                    self.experiences[score] += 1;
                    let t_s = t - self.last_time[score];
                    let n = f64::from(self.experiences[score]);
                    let time_term = if t_s.is_finite() {
                        self.params.w_t / (t_s + 1.0)
                    } else {
                        0.0
                    };
                    self.factor[score] = (1.0 - time_term - self.params.w_n * (n - 1.0)).max(0.0);
                    self.last_time[score] = t;
                    self.last_gene[score] = gene;
                }
                score as f64 * self.factor[score]
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

    /// Issue 18: any u8 layer can be the information map, and a score above 100 indexed
    /// past Model I's tables. A world clamps it to 100, so a 255 cell counts as a 100
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
}
