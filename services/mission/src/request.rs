//! The planner request of a window's [`PlanAsk`]: one function for the live executive
//! (which sends it over Zenoh) and the batch of days (which answers it in process with
//! the planner's own code), so both ask for the same plan.

use roam_proto::planner::{GaOverrides, PlanRequest, PlannerModel, ShortestPathUse};

use crate::calibration::TimeModel;
use crate::config::ExecutiveConfig;
use crate::window::PlanAsk;

/// The request for `ask` under `config`, planned with `time_model` (paper 000 Eq. 2's
/// v_lin and v_ang), the shortest path attached as the fallback ([`crate::window`]'s
/// one-request rule). A replan (an ask with a seed route) runs `replan_generations`.
pub fn plan_request(config: &ExecutiveConfig, ask: &PlanAsk, time_model: TimeModel) -> PlanRequest {
    PlanRequest {
        request_id: None,
        cancel_token: None,
        start: ask.from,
        goal: ask.to,
        t_exec_s: ask.t_exec_s,
        deadline_s: ask.deadline_s,
        model: match (ask.curious, config.model) {
            (false, _) => PlannerModel::Shortest,
            // A seeded replan is the GA's, warm-started with the route left
            // (`ExecutiveConfig::model`).
            (true, PlannerModel::Anytime) if !ask.seed_route.is_empty() => PlannerModel::Model1,
            (true, model) => model,
        },
        params: GaOverrides {
            max_generations: if ask.seed_route.is_empty() {
                config.max_generations
            } else {
                config.replan_generations()
            },
            w_loc: config.w_loc,
            peb_free_m: config.peb_free_m,
            ..time_model.overrides()
        },
        seed: config.seed,
        map_version: None,
        shortest: ShortestPathUse::Fallback,
        seed_route: ask.seed_route.clone(),
    }
}
