//! The evaluation's fixed setup (paper 000 §III): the start and the two goals, the
//! t_plan / t_exec splits and the three models.

use roam_proto::planner::PlannerModel;

/// The start and the paper's two goals (Fig. 5).
pub const START: [f64; 2] = [-8.0, -8.0];
pub const GOALS: [(&str, [f64; 2]); 2] = [("goal1", [-2.0, 4.0]), ("goal2", [6.0, -7.0])];
/// t_plan / t_exec splits of T (§III.B).
pub const RATIOS: [(&str, f64); 3] = [("20/80", 0.2), ("40/60", 0.4), ("60/40", 0.6)];
pub const MODELS: [PlannerModel; 3] = [
    PlannerModel::Model0,
    PlannerModel::Model1,
    PlannerModel::Model2,
];
