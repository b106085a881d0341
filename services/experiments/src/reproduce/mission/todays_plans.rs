//! What today's executive would have planned in the demo's windows: issue 14's
//! comparison "against today's executive (static map, Table I time model)".
//!
//! Today's executive (before issue 14) planned each window once, from where the window
//! began, with the whole window as the budget, on the static information map, with
//! Table I's v_lin and v_ang, no PEB cost, and paper 000's own initialization (random
//! walks that stop at the goal, no via-point seeds). This replays exactly that plan in
//! process ([`roam_planner::plan::plan`], seeded as the executive's) for each window of
//! the run. What it reports is the information that plan *promised*; today's robot
//! drove 84–89% of it (issue 14), so the comparison is in today's favour.

use std::sync::atomic::AtomicBool;

use roam_mission::executive::WindowOutcome;
use roam_planner::plan::{plan, PlanSpec};
use roam_planner::world::World;
use roam_proto::planner::PlannerModel;
use roam_world::grid::Grid;
use serde::Serialize;

/// Table I's heuristic compression (the planner service's cached worlds).
const COMPRESSION: f64 = 0.25;

/// Today's plan for one window.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TodaysPlan {
    /// 0 for the first window.
    pub window: usize,
    /// Information of the distinct cells the plan sees (paper 000 Eq. 3's window, the
    /// static map), as the report's other information figures.
    pub planned_information: f64,
    /// Its t_ETA on Table I's time model, seconds; `None` when refused.
    pub t_eta_s: Option<f64>,
    /// Why today's planner refused the window (e.g. the window, shortened by a late
    /// arrival, is below the shortest path's ETA on Table I's slower time model); its
    /// information is then 0.
    pub refused: Option<String>,
}

/// Today's plan for each window that had a plan (`None` for a window without a path),
/// or today's planner's refusal.
pub fn todays_plans(
    inflated: &Grid<i8>,
    information: &Grid<u8>,
    outcomes: &[WindowOutcome],
    generations: u32,
    seed: u64,
) -> Vec<Option<TodaysPlan>> {
    let world = match World::new(inflated, information, COMPRESSION) {
        Ok(world) => world,
        Err(e) => {
            tracing::warn!("no comparison with today's executive: {e}");
            return vec![None; outcomes.len()];
        }
    };
    let never = AtomicBool::new(false);
    outcomes
        .iter()
        .map(|o| {
            let (Some(from), Some(to)) = (o.shortest.first(), o.shortest.last()) else {
                return None;
            };
            let r = &o.report;
            let mut spec = PlanSpec::batch(
                *from,
                *to,
                r.task_start_s - r.began_s,
                PlannerModel::Model1,
                generations,
                seed,
            );
            spec.params = spec.params.with_paper_initialization();
            spec.threads = 1;
            match plan(&world, &spec, &never, |_, _| {}) {
                Ok(p) => Some(TodaysPlan {
                    window: r.window,
                    planned_information: p.metrics.distinct_information,
                    t_eta_s: Some(p.t_eta_s),
                    refused: None,
                }),
                Err(e) => {
                    tracing::warn!(window = r.window, "today's planner refuses: {e}");
                    Some(TodaysPlan {
                        window: r.window,
                        planned_information: 0.0,
                        t_eta_s: None,
                        refused: Some(e.to_string()),
                    })
                }
            }
        })
        .collect()
}
