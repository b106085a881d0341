//! Paper 000's equations against values computed by hand on a 4 × 4 grid: the
//! curiosity models (Eqs. 8–10) and the fitness terms F1–F5 (Eqs. 3–7), with t_ETA
//! from Eq. 2. Each figure below is worked out in its comment, so a change to how the
//! evaluator counts (the window, the stimulus bookkeeping, the block update, a
//! weight's sign) shows here as a number that moved.
//!
//! The grid (x to the right, y up the rows; 0.2 m cells, all free), scores I_xy:
//!
//! ```text
//! y=3:  50 50 50 50   never perceived: the window ends at y + 1 = 2
//! y=2:   0  0 10 10
//! y=1:   0  0  0 20   the path: (0,1) → (1,1) → (2,1) → (3,1), east, no turn
//! y=0:  10  0 10  0
//! ```
//!
//! Table I's parameters: d = 3, so the window is x−2..=x+1 × y−2..=y+1 (Eq. 3 with
//! floor brackets, `GaParams::window`), v_lin = 2 s/m, W1 = 3, W2 = 500,000,
//! W3 = 1,000,000, W4 = 200, W5 = 10, w_t = 0.4, w_n = 0.01, I_0 = 1.
//!
//! Eq. 2: three straight moves of 0.2 m, no turn: t_ETA = 2 · 0.6 = 1.2 s; the genes
//! are at t = 0, 0.4, 0.8, 1.2 s.
//!
//! Perception (Eq. 3, each cell once per path): gene 0 at (0,1) sees x 0..=1, y 0..=2
//! (6 cells); gene 1 adds column x = 2, gene 2 column x = 3 (3 cells each); gene 3 at
//! (3,1) adds nothing (x = 4 is off the grid). 12 cells, rows 0..=2.

use roam_planner::curiosity::{Evaluation, Evaluator, Model};
use roam_planner::params::GaParams;
use roam_planner::world::World;
use roam_proto::map::{GridMeta, Origin};
use roam_world::grid::Grid;

/// Row-major from y = 0.
const SCORES: [u8; 16] = [
    10, 0, 10, 0, //
    0, 0, 0, 20, //
    0, 0, 10, 10, //
    50, 50, 50, 50,
];

fn world(compression: f64) -> World {
    let meta = GridMeta {
        width: 4,
        height: 4,
        resolution: 0.2,
        origin: Origin::default(),
    };
    let information = Grid {
        meta,
        cells: SCORES.to_vec(),
    };
    World::new(&Grid::filled(meta, 0i8), &information, compression).expect("world")
}

/// (0,1) → (3,1).
const PATH: [u32; 4] = [4, 5, 6, 7];

fn evaluate(model: Model, compression: f64, goal: u32, t_exec: f64) -> Evaluation {
    let world = world(compression);
    let params = GaParams {
        heuristic_compression: compression,
        ..GaParams::default()
    };
    Evaluator::new(&world, &params, model, goal, t_exec).evaluate(&PATH)
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

#[test]
fn eq_2_three_straight_moves_take_1_2_s() {
    let e = evaluate(Model::Coverage, 0.25, 7, 2.0);
    assert!(close(e.t_eta, 1.2), "{}", e.t_eta);
}

/// Eq. 8: I_0 per newly perceived cell, whatever its score: 12 cells, Σ M = 12.
#[test]
fn eq_8_model_0_counts_each_perceived_cell_once() {
    let e = evaluate(Model::Coverage, 0.25, 7, 2.0);
    assert!(close(e.model_information, 12.0), "{}", e.model_information);
}

/// Eq. 9, M = max(I · (1 − w_t / (t_s + 1) − w_n · (n_I − 1)), 0), one experience of a
/// stimulus per gene (see `roam_planner::curiosity`):
/// - gene 0 (t = 0): (0,0) = 10, first experience of 10 (n = 1, t_s = ∞): 10 · 1 = 10.
/// - gene 1 (t = 0.4): (2,0) = 10 and (2,2) = 10, the second experience of 10
///   (n = 2, t_s = 0.4): factor 1 − 0.4/1.4 − 0.01 = 0.704285714…, 2 · 10 · that
///   = 14.0857142857.
/// - gene 2 (t = 0.8): (3,1) = 20, first of 20: 20; (3,2) = 10, third of 10 (n = 3,
///   t_s = 0.4): 10 · (1 − 0.4/1.4 − 0.02) = 6.9428571429.
/// - Σ M = 10 + 14.0857142857 + 20 + 6.9428571429 = 51.0285714286.
#[test]
fn eq_9_model_1_decays_with_repeats_and_recovers_with_time() {
    let e = evaluate(Model::Novelty, 0.25, 7, 2.0);
    let expected = 10.0 + 20.0 * (1.0 - 0.4 / 1.4 - 0.01) + 20.0 + 10.0 * (1.0 - 0.4 / 1.4 - 0.02);
    assert!(close(expected, 51.028_571_428_571), "{expected}");
    assert!(
        close(e.model_information, expected),
        "{}",
        e.model_information
    );
}

/// Eq. 10, M = |H − I|, with c_h = 0.5: 2 × 2 blocks of 2 × 2 cells, H the block's
/// mean as the path has left it (a perceived cell's I becomes 0 in both maps).
/// Blocks: B0 (x 0–1, y 0–1) sum 10, B1 (x 2–3, y 0–1) sum 30, B2 (x 0–1, y 2–3) 100,
/// B3 (x 2–3, y 2–3) 120. Cells in window order (rows up, then columns):
/// - gene 0: (0,0) 10: |10/4 − 10| = 7.5, B0 → 0; (1,0), (0,1), (1,1): 0 each;
///   (0,2) 0: |100/4 − 0| = 25; (1,2): 25. Gene total 57.5.
/// - gene 1: (2,0) 10: |30/4 − 10| = 2.5, B1 → 20; (2,1) 0: 20/4 = 5;
///   (2,2) 10: |120/4 − 10| = 20, B3 → 110. Gene total 27.5.
/// - gene 2: (3,0) 0: 5; (3,1) 20: |5 − 20| = 15, B1 → 0; (3,2) 10: |110/4 − 10|
///   = 17.5, B3 → 100. Gene total 37.5.
/// - Σ M = 57.5 + 27.5 + 37.5 = 122.5.
#[test]
fn eq_10_model_2_scores_the_distance_from_the_updated_heuristic() {
    let e = evaluate(Model::Heterogeneity, 0.5, 7, 2.0);
    assert!(close(e.model_information, 122.5), "{}", e.model_information);
}

/// Eqs. 3–7 with the goal at the path's end and t_exec = 2 s:
/// F1 = W1 · Σ M (Eq. 3), F2 = W2 since 1.2 < 2 (Eq. 4), F3 = W3 since g_L = G
/// (Eq. 5), F4 = −200 · max(1.2 − 2, 0) = 0 (Eq. 6), F5 = −10 · (2 − 1.2) = −8 (Eq. 7).
#[test]
fn eqs_3_to_7_on_time_at_the_goal() {
    for (model, compression, information) in [
        (Model::Coverage, 0.25, 12.0),
        (Model::Novelty, 0.25, 51.028_571_428_571_43),
        (Model::Heterogeneity, 0.5, 122.5),
    ] {
        let f = evaluate(model, compression, 7, 2.0).fitness;
        assert!(
            close(f.f1_information, 3.0 * information),
            "{model:?} {f:?}"
        );
        assert_eq!(f.f2_on_time, 500_000.0, "{model:?}");
        assert_eq!(f.f3_goal, 1_000_000.0, "{model:?}");
        assert_eq!(f.f4_overtime, 0.0, "{model:?}");
        assert!(close(f.f5_idle, -8.0), "{model:?} {f:?}");
        assert_eq!(f.f6_localizability, 0.0);
        assert!(
            close(f.total, 3.0 * information + 1_500_000.0 - 8.0),
            "{model:?} {f:?}"
        );
    }
}

/// The other branches with Model 0 (F1 = 36): goal (0,0), which the path does not end
/// at, and t_exec = 1 s: F2 = 0 (1.2 ≥ 1), F3 = 0, F4 = −200 · 0.2 = −40, F5 = 0;
/// total 36 − 40 = −4.
#[test]
fn eqs_4_to_7_late_and_off_the_goal() {
    let f = evaluate(Model::Coverage, 0.25, 0, 1.0).fitness;
    assert!(close(f.f1_information, 36.0), "{f:?}");
    assert_eq!(
        (f.f2_on_time, f.f3_goal, f.f5_idle),
        (0.0, 0.0, 0.0),
        "{f:?}"
    );
    assert!(close(f.f4_overtime, -40.0), "{f:?}");
    assert!(close(f.total, -4.0), "{f:?}");
}
