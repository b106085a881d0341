//! What a fleet batch runs: days, seed, the curious variants' planner and its costs,
//! the variants, the threads.

use roam_proto::planner::PlannerModel;

use super::variant::FleetVariant;

/// What to run.
#[derive(Debug, Clone, PartialEq)]
pub struct FleetOptions {
    pub days: usize,
    pub seed: u64,
    /// The planner's model for curious plans: `greedy` by default (roam's peer of
    /// paper 000's GA: more information in a twentieth of the time, planner README
    /// "The peer"; ten robots replanning every few seconds need plans in tens of
    /// milliseconds), `model1` for paper 000's.
    pub model: PlannerModel,
    /// GA generations per curious plan (the GA models only).
    pub generations: u32,
    /// W_loc of the PEB cost for the curious variants.
    pub w_loc: f64,
    /// The PEB (m) that cost forgives (the planner's `peb_free_m`). 0 by default: every
    /// decimetre costs. Measured (README "The fleet's week"): forgiving 0.3 or 0.5 m
    /// sends the news into the anchor gaps, where the controller holds the robots, and
    /// 35–42 windows of 114 end late.
    pub peb_free_m: f64,
    /// Every plan (tasks, patrol and curious alike) goes around what the fleet believes
    /// occupied where the static map is free ([`super::seen`]), as `roam demo --fleet`'s
    /// planners do; `false`: on the static map only (`--static-map`).
    pub avoid_seen: bool,
    /// What a curious plan costs, wall seconds, before its deadline cuts it.
    pub plan_wall_s: f64,
    /// The clock's rate the executives assume, mission seconds per wall second.
    pub rate: f64,
    pub variants: Vec<FleetVariant>,
    pub jobs: usize,
}

impl Default for FleetOptions {
    fn default() -> Self {
        FleetOptions {
            days: 7,
            seed: 0,
            model: PlannerModel::Greedy,
            generations: 200,
            w_loc: 2000.0,
            peb_free_m: 0.0,
            avoid_seen: true,
            plan_wall_s: 0.2,
            // A fleet runs on the wall clock: a plan's computing time is its cost.
            rate: 1.0,
            variants: FleetVariant::DEFAULT.to_vec(),
            jobs: std::thread::available_parallelism().map_or(1, |n| n.get()),
        }
    }
}
