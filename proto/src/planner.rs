//! Messages of the GA planner (paper 000): plan requests, plans, progress.

use serde::{Deserialize, Serialize};

use crate::codec::Message;

/// Which planner answers: the curious GA with one of the paper's models, or a baseline.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlannerModel {
    /// The fastest path by Eq. 2 (distance and turns): the information-blind baseline,
    /// and the floor every budget is checked against.
    Shortest,
    /// GA with Model 0, coverage: a constant gain per newly perceived cell (Eq. 8).
    Model0,
    /// GA with Model I, novelty of stimuli with time and amount decay (Eq. 9).
    Model1,
    /// GA with Model II, heterogeneity |H − I| against the heuristic map (Eq. 10).
    Model2,
    /// Not a GA: greedy insertion of informative via-points by information per second,
    /// with local improvement, within the budget; scored with Model I (Eq. 9). roam's
    /// peer for the GA (issue 16), not paper 000's.
    Greedy,
    /// Anytime: the greedy planner's answer at once (milliseconds), then the GA with
    /// Model I, its first population seeded with that answer, until the deadline or its
    /// generations; the fitter of the two by Model I's fitness (Eq. 1), reported in
    /// [`Plan::found_by`]. roam's, not paper 000's: the greedy answer alone leaves about
    /// a sixth of the best possible information on small instances (`roam bench planner
    /// --optimality`), the GA alone needs its time to start well.
    Anytime,
}

impl PlannerModel {
    pub fn as_str(self) -> &'static str {
        match self {
            PlannerModel::Shortest => "shortest",
            PlannerModel::Model0 => "model0",
            PlannerModel::Model1 => "model1",
            PlannerModel::Model2 => "model2",
            PlannerModel::Greedy => "greedy",
            PlannerModel::Anytime => "anytime",
        }
    }
}

/// The map a plan was made on: the versions of the layers the planner reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapVersion {
    pub inflated: u64,
    pub information: u64,
    /// The change layer's version, on a planner that couples one (its `change_layer`)
    /// and once it has one; absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub change: Option<u64>,
    /// The layer of what the fleet has seen that the plan went around (the planner's
    /// `obstacles_layer`, the mapper's `occupied_now`), on a planner that follows one and
    /// once it has one; absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub obstacles: Option<u64>,
}

/// Overrides of the GA parameters (paper 000 Table I); every field is optional.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GaOverrides {
    pub population: Option<u32>,
    pub max_generations: Option<u32>,
    pub crossover_ratio: Option<f64>,
    pub mutation_ratio: Option<f64>,
    pub mutation_percentage: Option<f64>,
    pub v_lin: Option<f64>,
    pub v_ang: Option<f64>,
    pub w1: Option<f64>,
    pub w2: Option<f64>,
    pub w3: Option<f64>,
    pub w4: Option<f64>,
    pub w5: Option<f64>,
    pub w_t: Option<f64>,
    pub w_n: Option<f64>,
    pub heuristic_compression: Option<f64>,
    pub perception_diameter: Option<u32>,
    pub coverage_gain: Option<f64>,
    /// W_loc: weight of the localizability cost (roam, not paper 000).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub w_loc: Option<f64>,
    /// The PEB (m) the localizability cost forgives: each cell costs
    /// W_loc · max(0, PEB − peb_free_m) (roam, not paper 000); default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peb_free_m: Option<f64>,
    /// Share of the first population built through via-points drawn from the
    /// information layer (roam, not paper 000); 0..=1, default 0.25.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub via_share: Option<f64>,
    /// Share of t_exec a random walk of the first population uses before it may end at
    /// the goal (roam's round-trip rule); 0..=1, default 0.5. Both 0: paper 000's own
    /// initialization.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub walk_end_share: Option<f64>,
}

/// Ask for a plan: from `start` to `goal` (world metres) within `t_exec_s` seconds of
/// driving, planned within `deadline_s` seconds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanRequest {
    /// Names the plan's progress key (`<root>/planner/progress/<request_id>`) and its
    /// cancel key; 1 to 64 characters a-z, A-Z, 0-9, '_' and '-'. Not a secret: anyone
    /// subscribed to the progress keys sees it. When absent the planner makes up an
    /// unguessable one (32 hex characters, 128 random bits) and returns it in the plan.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub request_id: Option<String>,
    /// The secret that proves a [`CancelPlan`] comes from the requester: 16 to 128
    /// characters from a-z, A-Z, 0-9, '-' and '_' (e.g. 32 hex characters of 16 random
    /// bytes, fresh for each request). The planner never logs it or sends it back. A
    /// request without one cannot be cancelled: it ends at its generations or its
    /// deadline.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cancel_token: Option<String>,
    pub start: [f64; 2],
    pub goal: [f64; 2],
    /// Seconds the robot has to drive (paper 000: t_exec).
    pub t_exec_s: f64,
    /// Seconds the planner may take (paper 000: t_plan); the best path so far is returned.
    pub deadline_s: f64,
    pub model: PlannerModel,
    #[serde(default)]
    pub params: GaOverrides,
    #[serde(default)]
    pub seed: u64,
    /// Plan on this map version; refused when the planner no longer has it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub map_version: Option<MapVersion>,
    /// What the reply carries of the shortest path, which the planner finds for every
    /// request anyway; absent: [`ShortestPathUse::Omit`], what requests before the field
    /// got.
    #[serde(default, skip_serializing_if = "ShortestPathUse::is_omit")]
    pub shortest: ShortestPathUse,
    /// A replan's warm start (roam, not paper 000): the route the robot is driving now,
    /// world metres from about `start` to about `goal`, at most
    /// [`MAX_SEED_ROUTE_POINTS`] points (more is refused, naming the limit). The planner
    /// puts it, on its planning cells, in the GA's first population (Models I and II,
    /// anytime) and ranks it with the plans it found, so the answer is never less fit
    /// than driving on. A route it cannot join to the planning grid (off the map,
    /// blocked, gaps) is not used and the reply's `seed_route_used` says so; the request
    /// is answered either way. Absent or empty: planned from scratch.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub seed_route: Vec<[f64; 2]>,
}

/// The most points [`PlanRequest::seed_route`] may have: 65,536 (1 MiB of JSON at most;
/// a 3 km route at 5 cm).
pub const MAX_SEED_ROUTE_POINTS: usize = 65_536;

/// What a plan request wants of the shortest path (roam, not paper 000). The planner
/// finds it before any curious planning (to refuse a budget it does not fit, and to
/// seed the GA), so attaching it costs a copy, not a second request.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ShortestPathUse {
    /// Nothing: the reply has no `shortest`, and a budget below the shortest path's ETA
    /// is refused (`invalid_request`, "give at least N s").
    #[default]
    Omit,
    /// The reply carries the shortest path as [`Plan::shortest`]; a budget below its ETA
    /// is still refused.
    Attach,
    /// As `attach`, and a budget below the shortest path's ETA is answered with the
    /// shortest path itself as the plan (`model: shortest`, `within_budget: false`,
    /// `stop_reason: complete`) instead of a refusal: a client that drives whatever
    /// comes back (the mission executive, when a window is shorter than its task is
    /// far) needs one request per plan.
    Fallback,
}

impl ShortestPathUse {
    pub fn is_omit(&self) -> bool {
        *self == ShortestPathUse::Omit
    }
}

impl Message for PlanRequest {
    const KIND: &'static str = "plan_request";
}

/// The fitness terms of paper 000 Eqs. 1 and 3–7 for the returned path.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitnessTerms {
    pub f1_information: f64,
    pub f2_on_time: f64,
    pub f3_goal: f64,
    pub f4_overtime: f64,
    pub f5_idle: f64,
    /// roam's localizability cost: −W_loc · Σ PEB over the path's cells (0 unless the
    /// planner has a PEB layer and W_loc > 0).
    #[serde(default)]
    pub f6_localizability: f64,
    pub total: f64,
}

/// Why the GA stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    MaxGenerations,
    Deadline,
    Cancelled,
    /// The planner's CPU budget granted less wall time than `deadline_s` (its
    /// `max_plan_seconds`, or what its plan-seconds bucket held) and the plan used it
    /// all: the path is the best found in [`Plan::cpu_grant_s`] seconds. On the wire
    /// `cpu_grant` (`budget` is read too: "budget" alone is the driving budget,
    /// `t_exec_s`, everywhere else).
    #[serde(alias = "budget")]
    CpuGrant,
    /// Baselines that are not iterative.
    Complete,
}

/// A plan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Plan {
    pub request_id: String,
    /// The model that answered: the request's, or `shortest` when the request asked for
    /// the shortest path as its fallback (`shortest: fallback`) and the budget did not
    /// fit it.
    pub model: PlannerModel,
    /// Map cells `[x, y]` (the `inflated` layer's grid) from start to end, 8-connected
    /// without cutting corners, every one free: the path the robot drives, also when
    /// the planner plans at a coarser resolution (`planning_resolution_m`).
    pub cells: Vec<[u32; 2]>,
    /// The cells' centres in world metres.
    pub points: Vec<[f64; 2]>,
    /// Estimated driving time (paper 000 Eq. 2), seconds.
    pub t_eta_s: f64,
    pub reaches_goal: bool,
    pub within_budget: bool,
    pub fitness: FitnessTerms,
    /// Unbiased information U_ges (Eq. 11): window sums along the path, cells counted
    /// each time they are in view.
    pub u_ges: f64,
    /// Information density D = U_ges / L (Eq. 12).
    pub density: f64,
    /// Information of the distinct cells seen along the path.
    pub distinct_information: f64,
    pub generations: u32,
    pub planning_ms: f64,
    pub stop_reason: StopReason,
    /// The resolution the plan was made at, metres: paper 000's 0.2 by default, or the
    /// map's where that is coarser. `cells` are map cells whatever this is.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub planning_resolution_m: Option<f64>,
    /// With `stop_reason: cpu_grant`: the wall seconds the planner's CPU budget granted
    /// (`budget_s` is read too).
    #[serde(default, alias = "budget_s", skip_serializing_if = "Option::is_none")]
    pub cpu_grant_s: Option<f64>,
    pub seed: u64,
    pub map_version: MapVersion,
    /// The planner instance that answered.
    pub instance: String,
    /// The shortest path from the start's cell to the goal's, when the request asked for
    /// it (`shortest: attach` or `fallback`); absent otherwise, so a client that did not
    /// ask never sees the field.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shortest: Option<ShortestPath>,
    /// What produced the returned path, of what the planner tried: `ga`, `greedy`,
    /// `shortest` (the fastest path, unchanged), `via_seed` (a via-point seed,
    /// unchanged) or `remainder` (the request's `seed_route`, unchanged). Absent from
    /// planners that do not know the field.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub found_by: Option<String>,
    /// With a request's `seed_route`: whether it was in the first population (`false`:
    /// it could not be joined to the planning grid, or the model has no population).
    /// `found_by: remainder` says it was also the fittest. Absent without a seed route.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed_route_used: Option<bool>,
}

/// The shortest path a plan reply carries ([`Plan::shortest`]): what `model: shortest`
/// would have answered for the same request.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShortestPath {
    /// Grid cells `[x, y]` from start to end, 8-connected.
    pub cells: Vec<[u32; 2]>,
    /// The cells' centres in world metres.
    pub points: Vec<[f64; 2]>,
    /// Its driving time under the request's time model (paper 000 Eq. 2), seconds.
    pub t_eta_s: f64,
    /// Information of the distinct cells seen along it (as [`Plan::distinct_information`]).
    pub distinct_information: f64,
}

impl Message for Plan {
    const KIND: &'static str = "plan";
}

/// Progress of a plan in flight, published on `<root>/planner/progress/<request_id>`:
/// the best fitness of each generation since the previous message.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanProgress {
    pub request_id: String,
    /// `[generation, best fitness]` pairs, in order.
    pub best_fitness: Vec<(u32, f64)>,
    pub done: bool,
}

impl Message for PlanProgress {
    const KIND: &'static str = "plan_progress";
}

/// Cancel a plan in flight: put on `<root>/planner/cancel/<request_id>`. Honoured only
/// when `token` is the request's `cancel_token` (compared in constant time): the planner
/// then stops and replies with the best path found so far (`stop_reason: cancelled`). A
/// cancel with another token or none (as every cancel before tokens) is ignored and
/// logged, rate-limited.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CancelPlan {
    pub request_id: String,
    /// The plan request's `cancel_token`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub token: Option<String>,
}

impl Message for CancelPlan {
    const KIND: &'static str = "cancel_plan";
}
