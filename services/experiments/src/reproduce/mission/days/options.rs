//! What a days batch runs: days, seed, the curious plans' generations and costs, the
//! clock, the variants, the threads and the site.

use roam_mission::site::Site;

use super::variant::Variant;

/// What to run.
#[derive(Debug, Clone, PartialEq)]
pub struct DaysOptions {
    pub days: usize,
    pub seed: u64,
    /// GA generations per curious plan (the executive's `max_generations`).
    pub generations: u32,
    /// W_loc of the PEB cost (as `roam reproduce mission`: 2000).
    pub w_loc: f64,
    /// What a curious plan costs, wall seconds, before its deadline cuts it (measured
    /// in the demo: see services/mission/README.md).
    pub plan_wall_s: f64,
    /// What a replan seeded with the route left costs, wall seconds (the executive's
    /// `replan_generations`; `roam bench planner --replans` measures it: p99 48 ms).
    pub replan_wall_s: f64,
    /// The clock's rate, mission seconds per wall second (the demo's 20×).
    pub rate: f64,
    pub variants: Vec<Variant>,
    /// Threads the days run on (the report does not depend on it).
    pub jobs: usize,
    /// The world and the day's tasks: the demo's day, or a user's map and day file.
    pub site: Site,
}

impl Default for DaysOptions {
    fn default() -> Self {
        DaysOptions {
            days: 50,
            seed: 0,
            generations: 1000,
            w_loc: 2000.0,
            plan_wall_s: 0.4,
            replan_wall_s: 0.05,
            rate: 20.0,
            variants: Variant::DEFAULT.to_vec(),
            jobs: std::thread::available_parallelism().map_or(1, |n| n.get()),
            site: Site::builtin_day(),
        }
    }
}
