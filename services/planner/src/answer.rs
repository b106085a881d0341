//! A plan request answered in process, as the planner service answers it but without
//! its queue, its CPU budget or a wall-clock deadline: the batch experiments ask this
//! with the very [`PlanRequest`] the mission executive sends over Zenoh, and get the
//! [`Plan`] message the service would reply (the same checks, the same [`plan`], the
//! same [`to_message`]). The GA ends at its generations, not at the request's
//! deadline, so an answer repeats bit for bit whatever the machine.

use std::sync::atomic::AtomicBool;

use roam_proto::planner::{MapVersion, Plan, PlanRequest, ShortestPath};

use crate::limits::PlanLimits;
use crate::params::GaParams;
use crate::plan::{check_spec, plan, PlanError, PlanOutcome, PlanSpec, MAX_DEADLINE_S};
use crate::world::World;

/// The instance name a batch answer carries.
pub const BATCH_INSTANCE: &str = "batch";

/// `request` answered on `world` with `threads` evaluation threads (the result does not
/// depend on them).
pub fn answer(world: &World, request: &PlanRequest, threads: usize) -> Result<Plan, PlanError> {
    let spec = PlanSpec {
        start: request.start,
        goal: request.goal,
        t_exec_s: request.t_exec_s,
        deadline_s: MAX_DEADLINE_S,
        model: request.model,
        params: GaParams::with_overrides(&request.params)?,
        seed: request.seed,
        threads,
        limits: PlanLimits::default(),
        shortest: request.shortest,
        seed_route: request.seed_route.clone(),
    };
    check_spec(&spec)?;
    let outcome = plan(world, &spec, &AtomicBool::new(false), |_, _| {})?;
    let version = MapVersion {
        inflated: 0,
        information: 0,
        change: None,
        obstacles: None,
    };
    let id = request.request_id.clone().unwrap_or_default();
    Ok(to_message(
        world,
        request,
        id,
        version,
        BATCH_INSTANCE,
        outcome,
    ))
}

/// The reply message of an outcome.
pub fn to_message(
    world: &World,
    request: &PlanRequest,
    request_id: String,
    map_version: MapVersion,
    instance: &str,
    outcome: PlanOutcome,
) -> Plan {
    // Only when the request asked ([`plan`] measures it only then): a client from
    // before the field never sees it. The fastest path, as driven (map cells).
    let shortest = outcome.shortest.as_ref().map(|s| ShortestPath {
        cells: s.cells.clone(),
        points: s.points.clone(),
        t_eta_s: s.t_eta_s,
        distinct_information: s.metrics.distinct_information,
    });
    Plan {
        request_id,
        model: outcome.model,
        cells: outcome.cells,
        points: outcome.points,
        planning_resolution_m: Some(world.meta.resolution),
        t_eta_s: outcome.t_eta_s,
        reaches_goal: outcome.reaches_goal,
        within_budget: outcome.within_budget,
        fitness: outcome.fitness,
        u_ges: outcome.metrics.u_ges,
        density: outcome.metrics.density,
        distinct_information: outcome.metrics.distinct_information,
        generations: outcome.generations,
        planning_ms: outcome.planning.as_secs_f64() * 1000.0,
        stop_reason: outcome.stop_reason,
        cpu_grant_s: None,
        seed: request.seed,
        map_version,
        instance: instance.to_owned(),
        shortest,
        found_by: Some(outcome.source.as_str().to_owned()),
        seed_route_used: outcome.seed_route_used,
    }
}
