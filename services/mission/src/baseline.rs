//! The demo's baseline, a named configuration of the executive: **one plan per window**,
//! what the demo's report compares the shipped executive with ("against one plan per
//! window: static map, Table I time model").
//!
//! The one-plan executive plans each window once, from where the window began, with the
//! whole window as the budget, on the static information map, with Table I's v_lin and
//! v_ang, no PEB cost, and paper 000's own initialization (random walks that stop at the
//! goal, no via-point seeds), and never replans. This replays exactly that plan in
//! process ([`roam_planner::plan::plan`], seeded as the executive's) for each window of
//! the run. What it reports is the information that plan *promised*; a robot driving it
//! drives 84–89% of it (measured in the demo's windows), so the comparison is in the
//! baseline's favour.

use std::sync::atomic::AtomicBool;

use crate::window::WindowOutcome;
use roam_planner::plan::{plan, PlanSpec};
use roam_planner::world::World;
use roam_proto::planner::PlannerModel;
use roam_world::grid::Grid;
use serde::Serialize;

/// Table I's heuristic compression (the planner service's cached worlds).
const COMPRESSION: f64 = 0.25;

/// The one-plan executive's plan for one window.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BaselinePlan {
    /// 0 for the first window.
    pub window: usize,
    /// Information of the distinct cells the plan sees (paper 000 Eq. 3's window, the
    /// static map), as the report's other information figures.
    pub planned_information: f64,
    /// Its t_ETA on Table I's time model, seconds; `None` when refused.
    pub t_eta_s: Option<f64>,
    /// Why the baseline's plan was refused (e.g. the window, shortened by a late
    /// arrival, is below the shortest path's ETA on Table I's slower time model); its
    /// information is then 0.
    pub refused: Option<String>,
}

/// The one-plan executive's plan for each window that had a plan (`None` for a window
/// without a path), or the planner's refusal of it.
pub fn one_plan_per_window(
    inflated: &Grid<i8>,
    information: &Grid<u8>,
    outcomes: &[WindowOutcome],
    generations: u32,
    seed: u64,
) -> Vec<Option<BaselinePlan>> {
    let world = match World::new(inflated, information, COMPRESSION) {
        Ok(world) => world,
        Err(e) => {
            tracing::warn!("no comparison with one plan per window: {e}");
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
                Ok(p) => Some(BaselinePlan {
                    window: r.window,
                    planned_information: p.metrics.distinct_information,
                    t_eta_s: Some(p.t_eta_s),
                    refused: None,
                }),
                Err(e) => {
                    tracing::warn!(window = r.window, "the one-plan baseline is refused: {e}");
                    Some(BaselinePlan {
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
