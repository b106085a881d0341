//! The planner through Zenoh: plans, determinism against the in-process planner, the
//! shortest path attached, busy, the limits and the CPU budget, made-up request ids, and
//! two instances sharing load and surviving one's death; progress and cancel (only with
//! the requester's token, a robot's plans on its own keys) in `cancel.rs` (its refusals:
//! `planner_refusals.rs`; at scale and queued: `planner_scale.rs`). Real map server and
//! planners in process, used only as a Zenoh client.

use std::sync::atomic::AtomicBool;
use std::time::Duration;

use roam_map_server::map_file;
use roam_planner::client::PlannerClient;
use roam_planner::params::GaParams;
use roam_planner::plan::{plan, PlanSpec};
use roam_planner::world::World;
use roam_proto::planner::{
    GaOverrides, MapVersion, Plan, PlanProgress, PlanRequest, PlannerModel, ShortestPathUse,
    StopReason,
};
use roam_proto::{decode, keys, ErrorCode};
use roam_runtime::{ClientError, Requester};
use roam_tests::within;
use roam_world::layers::inflate;
use roam_world::DEFAULT_MAX_CELLS;

#[path = "../planner_client/mod.rs"]
mod planner_client;

mod cancel;
mod in_flight;
use in_flight::{planning, start_endless_plan, TOKEN_A};
use planner_client::{ask, boot, boot_with, cancel, refusal, request};

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_plan_through_zenoh_equals_the_in_process_plan_bit_for_bit() {
    let running = boot(&[("solo", 2)]).await;
    let client = running.harness.client().await;
    let req = request([-8.0, -8.0], [6.0, -7.0], 80.0, 80);
    let remote = ask(&client, &running.harness.root, &req)
        .await
        .expect("plan");
    // Reaching the goal on time is forced by the shortest-path seed (issue 18); what
    // is not forced is that 80 generations use the budget, as F5 asks (Eq. 7): the
    // shortest path drives about a third of it.
    assert!(
        remote.t_eta_s >= 0.75 * req.t_exec_s,
        "{} s of {} s",
        remote.t_eta_s,
        req.t_exec_s
    );
    assert_eq!(remote.generations, 80);
    assert_eq!(remote.stop_reason, StopReason::MaxGenerations);
    assert_eq!(
        remote.map_version,
        MapVersion {
            inflated: 1,
            information: 1,
            change: None,
            obstacles: None,
        }
    );
    assert_eq!(remote.points.len(), remote.cells.len());

    // The same request in process, on the same world built from the same scenario.
    let content = map_file::builtin(DEFAULT_MAX_CELLS).expect("builtin");
    let inflated = inflate(
        &content.occupancy,
        content.robot_radius_m.unwrap_or(0.2),
        65,
    );
    let world = World::new(&inflated, &content.information.expect("info"), 0.25).expect("world");
    let spec = PlanSpec {
        start: req.start,
        goal: req.goal,
        t_exec_s: req.t_exec_s,
        deadline_s: req.deadline_s,
        model: req.model,
        params: GaParams::with_overrides(&req.params).expect("params"),
        seed: req.seed,
        threads: roam_planner::ga::default_threads(),
        limits: roam_planner::limits::PlanLimits::default(),
        shortest: ShortestPathUse::Omit,
        seed_route: Vec::new(),
    };
    let local = plan(&world, &spec, &AtomicBool::new(false), |_, _| {}).expect("local plan");
    let local_cells = world.grid_cells(&local.path);
    assert_eq!(remote.cells, local_cells);
    assert_eq!(
        remote.fitness.total.to_bits(),
        local.fitness.total.to_bits()
    );
    assert_eq!(remote.u_ges.to_bits(), local.metrics.u_ges.to_bits());

    // And again through the service: the same answer.
    let again = ask(&client, &running.harness.root, &req)
        .await
        .expect("plan");
    assert_eq!(again.cells, remote.cells);

    // A replan a third of the way along, seeded with the route left: the
    // planner plans from it, and answers as in process, bit for bit.
    let from = remote.points.len() / 3;
    let replan = PlanRequest {
        start: remote.points[from],
        t_exec_s: 0.8 * req.t_exec_s,
        seed_route: remote.points[from..].to_vec(),
        ..req.clone()
    };
    let seeded = ask(&client, &running.harness.root, &replan)
        .await
        .expect("replan");
    assert_eq!(seeded.seed_route_used, Some(true));
    let local_spec = PlanSpec {
        start: replan.start,
        t_exec_s: replan.t_exec_s,
        seed_route: replan.seed_route.clone(),
        ..spec
    };
    let local = plan(&world, &local_spec, &AtomicBool::new(false), |_, _| {}).expect("replan");
    assert_eq!(seeded.cells, world.grid_cells(&local.path));
    assert_eq!(local.seed_route_used, Some(true));
    running.stop().await;
}

/// The shortest path rides with the plan when asked (the executive's one request per
/// plan): attached exactly as `model: shortest` answers it, and with `fallback` a budget
/// it does not fit is answered with it instead of a refusal.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn the_shortest_path_comes_with_the_plan_when_asked() {
    let running = boot(&[("solo", 2)]).await;
    let client = running.harness.client().await;
    let root = running.harness.root.clone();
    let curious = PlanRequest {
        shortest: ShortestPathUse::Attach,
        ..request([-8.0, -8.0], [6.0, -7.0], 80.0, 20)
    };
    let plan = ask(&client, &root, &curious).await.expect("plan");
    let alone = ask(
        &client,
        &root,
        &PlanRequest {
            model: PlannerModel::Shortest,
            shortest: ShortestPathUse::Omit,
            ..curious.clone()
        },
    )
    .await
    .expect("the shortest path");
    assert!(alone.shortest.is_none(), "not asked for, not sent");
    assert_eq!(plan.model, PlannerModel::Model1);
    let attached = plan.shortest.expect("attached");
    assert_eq!(attached.cells, alone.cells);
    assert_eq!(attached.points, alone.points);
    assert_eq!(attached.t_eta_s.to_bits(), alone.t_eta_s.to_bits());
    assert_eq!(
        attached.distinct_information.to_bits(),
        alone.distinct_information.to_bits()
    );

    // Half the shortest path's ETA: refused when only attached, the shortest path
    // itself with the fallback.
    let short = 0.5 * alone.t_eta_s;
    let refused = refusal(
        &client,
        &root,
        &PlanRequest {
            t_exec_s: short,
            ..curious.clone()
        },
    )
    .await;
    assert!(
        refused
            .message
            .contains("shorter than the fastest path's ETA"),
        "{}",
        refused.message
    );
    let fallback = ask(
        &client,
        &root,
        &PlanRequest {
            t_exec_s: short,
            shortest: ShortestPathUse::Fallback,
            ..curious.clone()
        },
    )
    .await
    .expect("the fallback");
    assert_eq!(fallback.model, PlannerModel::Shortest);
    assert!(fallback.reaches_goal && !fallback.within_budget);
    assert_eq!(fallback.stop_reason, StopReason::Complete);
    assert_eq!(fallback.cells, alone.cells);
    assert_eq!(fallback.shortest.expect("attached").cells, alone.cells);
    running.stop().await;
}

/// Issue 14: a robot whose next task is where it stands (start = goal), or a cell away,
/// gets a loop through Zenoh that uses at least 80% of its budget and ends on time at
/// the goal, the same loop bit for bit as the in-process planner's.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_round_trip_through_zenoh_uses_the_budget() {
    let running = boot(&[("solo", 2)]).await;
    let client = running.harness.client().await;
    let content = map_file::builtin(DEFAULT_MAX_CELLS).expect("builtin");
    let inflated = inflate(
        &content.occupancy,
        content.robot_radius_m.unwrap_or(0.2),
        65,
    );
    let world = World::new(&inflated, &content.information.expect("info"), 0.25).expect("world");
    for goal in [[-8.0, -8.0], [-7.8, -8.0]] {
        let req = request([-8.0, -8.0], goal, 40.0, 200);
        let remote = ask(&client, &running.harness.root, &req)
            .await
            .expect("plan");
        // A loop that uses the budget: the lower bound is what can fail (standing
        // still, the paper's rule, drives 0 s); the shortest-path seed already forces
        // the end at S and the upper bound.
        assert!(
            remote.t_eta_s >= 0.8 * req.t_exec_s && remote.t_eta_s <= req.t_exec_s,
            "{goal:?}: {} s of {} s",
            remote.t_eta_s,
            req.t_exec_s
        );
        assert!(remote.cells.len() > 20, "{} cells", remote.cells.len());
        let spec = PlanSpec {
            start: req.start,
            goal: req.goal,
            t_exec_s: req.t_exec_s,
            deadline_s: req.deadline_s,
            model: req.model,
            params: GaParams::with_overrides(&req.params).expect("params"),
            seed: req.seed,
            threads: roam_planner::ga::default_threads(),
            limits: roam_planner::limits::PlanLimits::default(),
            shortest: ShortestPathUse::Omit,
            seed_route: Vec::new(),
        };
        let local = plan(&world, &spec, &AtomicBool::new(false), |_, _| {}).expect("local");
        assert_eq!(remote.cells, world.grid_cells(&local.path));
    }
    running.stop().await;
}

/// A request that cannot make its deadline behind the plan in progress is refused
/// `busy` at once, with the instance's expected wait (issue 16: what can wait is
/// queued; `tests/planner_scale.rs`).
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_full_planner_refuses_at_once_with_busy() {
    let running = boot(&[("tiny", 1)]).await;
    let client = running.harness.client().await;
    let root = running.harness.root.clone();
    let id = "hog";
    let (subscriber, pending) = start_endless_plan(&client, &root, id, Some(TOKEN_A)).await;
    planning(&subscriber).await;
    let started = std::time::Instant::now();
    let hurried = PlanRequest {
        deadline_s: 2.0,
        ..request([-8.0, -8.0], [6.0, -7.0], 80.0, 5)
    };
    let busy = refusal(&client, &root, &hurried).await;
    assert_eq!(busy.code, ErrorCode::Busy);
    assert!(
        started.elapsed() < Duration::from_secs(2),
        "refused at once, not queued"
    );
    let wait = busy
        .expected_wait_s
        .expect("the expected wait is in the error");
    assert!(wait > 2.0, "{busy}");
    assert!(busy.message.contains("deadline_s"), "{}", busy.message);
    cancel(client.session(), &root, id, Some(TOKEN_A)).await;
    within("hog", pending).await.expect("join").expect("plan");
    running.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn two_instances_share_the_load_and_survive_one_death() {
    let mut running = boot(&[("alpha", 2), ("beta", 2)]).await;
    let session = running.harness.client().await.session().clone();
    let planner = PlannerClient::new(session, &running.harness.root);
    assert_eq!(
        within("instances", planner.live_instances())
            .await
            .expect("live"),
        ["alpha", "beta"]
    );
    let mut answered_by = Vec::new();
    for _ in 0..4 {
        let plan = within(
            "plan",
            planner.plan(&request([-8.0, -8.0], [-2.0, 4.0], 60.0, 10)),
        )
        .await
        .expect("plan");
        answered_by.push(plan.instance);
    }
    assert!(
        answered_by.contains(&"alpha".to_owned()) && answered_by.contains(&"beta".to_owned()),
        "{answered_by:?}"
    );

    // Kill alpha: plans keep coming, from beta.
    let alpha = running.planners.remove(0);
    alpha.stop().await.1.expect("alpha stops");
    for _ in 0..3 {
        let plan = within(
            "plan",
            planner.plan(&request([-8.0, -8.0], [-2.0, 4.0], 60.0, 10)),
        )
        .await
        .expect("plan after a death");
        assert_eq!(plan.instance, "beta");
    }
    running.stop().await;
}

/// Issue 20: the planner's work has limits named in the error, and its wall time a
/// budget. The attack's request (population 2000, 100,000 generations) is refused at
/// once by its cost; the largest requests the cost cap admits are cut at the CPU budget
/// (here `max_plan_seconds` 2 and a bucket of 3 plan-seconds: one gets 2 s, the next
/// what is left, about 1 s) and the third is refused `busy` with the bucket's name.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn maximal_requests_are_cut_at_the_cpu_budget_or_refused() {
    const MAX_PLAN_SECONDS: f64 = 2.0;
    let running = boot_with(&[("solo", 3)], |config| roam_planner::PlannerConfig {
        max_plan_seconds: MAX_PLAN_SECONDS,
        plan_seconds_burst: 3.0,
        ..config
    })
    .await;
    let root = running.harness.root.clone();
    let client = running.harness.client().await;
    let maximal = |id: &str, generations: u32| PlanRequest {
        request_id: Some(id.into()),
        deadline_s: 600.0,
        params: GaOverrides {
            population: Some(2000),
            max_generations: Some(generations),
            ..GaOverrides::default()
        },
        ..request([-8.0, -8.0], [6.0, -7.0], 80.0, 1)
    };

    let started = std::time::Instant::now();
    let attack = refusal(&client, &root, &maximal("attack", 100_000)).await;
    assert_eq!(attack.code, ErrorCode::LimitExceeded);
    let limit = attack.limit.expect("the limit is named");
    assert_eq!(limit.name, "max_plan_cost");
    // 80 s at 0.4 s per cell: paths of at most 201 cells.
    assert_eq!(limit.actual, 2000 * 100_000 * 201);
    assert!(limit.actual > limit.max);
    assert!(
        started.elapsed() < Duration::from_secs(2),
        "refused before any work"
    );

    // 2000 × 9000 × 201 = 3.6e9: inside the cost cap, far beyond any budget.
    let started = std::time::Instant::now();
    let asks: Vec<_> = ["big-1", "big-2", "big-3"]
        .into_iter()
        .map(|id| {
            let (client, root, request) = (client.clone(), root.clone(), maximal(id, 9000));
            tokio::spawn(async move {
                client
                    .request::<PlanRequest, Plan>(&keys::planner_plan(&root), Some(&request))
                    .await
            })
        })
        .collect();
    let mut cut = Vec::new();
    let mut busy = Vec::new();
    for ask in asks {
        match within("a maximal plan", ask).await.expect("join") {
            Ok(plan) => cut.push(plan),
            Err(ClientError::Refused(reply)) => busy.push(reply),
            Err(e) => panic!("{e}"),
        }
    }
    let wall = started.elapsed();
    // A correct planner ends them at 2 s plus the generation in progress; 10 s of
    // margin for a debug build on a loaded machine, against the 600 s they asked for.
    assert!(
        wall < Duration::from_secs_f64(MAX_PLAN_SECONDS + 10.0),
        "{wall:?}"
    );
    assert_eq!((cut.len(), busy.len()), (2, 1), "{cut:?} {busy:?}");
    let mut granted: Vec<f64> = cut
        .iter()
        .map(|plan| {
            assert_eq!(plan.stop_reason, StopReason::CpuGrant, "{plan:?}");
            // Cut, not refused: it ran generations before the grant ended it.
            assert!((1..9000).contains(&plan.generations), "{plan:?}");
            plan.cpu_grant_s.expect("the grant is in the reply")
        })
        .collect();
    granted.sort_by(f64::total_cmp);
    // The second gets what the bucket held when it started: about 1 s when both start
    // at once, more when a loaded machine starts it later (the bucket refills 0.5
    // plan-seconds a second), never more than the bucket could have held by then.
    assert!(
        (0.9..=MAX_PLAN_SECONDS).contains(&granted[0]),
        "{granted:?}"
    );
    let refill = 0.5 * wall.as_secs_f64();
    assert!(
        granted.iter().sum::<f64>() <= 3.0 + refill + 1e-9,
        "{granted:?} in {wall:?}"
    );
    assert_eq!(granted[1], MAX_PLAN_SECONDS);
    assert_eq!(busy[0].code, ErrorCode::Busy);
    assert_eq!(
        busy[0].limit.as_ref().map(|l| l.name.as_str()),
        Some("plan_seconds_burst")
    );
    assert!(busy[0].message.contains("retry in"), "{}", busy[0].message);
    running.stop().await;
}

/// Ids the planner makes up are 128 random bits in hex, distinct from each other.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn made_up_request_ids_are_distinct_and_32_hex_characters() {
    let running = boot(&[("solo", 2)]).await;
    let client = running.harness.client().await;
    let mut ids = std::collections::BTreeSet::new();
    for _ in 0..3 {
        let plan = ask(
            &client,
            &running.harness.root,
            &PlanRequest {
                model: PlannerModel::Shortest,
                ..request([-8.0, -8.0], [6.0, -7.0], 80.0, 1)
            },
        )
        .await
        .expect("plan");
        assert_eq!(plan.request_id.len(), 32, "{}", plan.request_id);
        assert!(
            plan.request_id
                .bytes()
                .all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b)),
            "{}",
            plan.request_id
        );
        ids.insert(plan.request_id);
    }
    assert_eq!(ids.len(), 3);
    running.stop().await;
}

/// `model: anytime` through the service: the greedy answer, then the GA seeded with it;
/// the reply names what found its path, as every reply does, and it is never less fit
/// than the greedy planner's own answer to the same request.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn an_anytime_plan_is_at_least_the_greedy_one_and_names_its_source() {
    let running = boot(&[("solo", 2)]).await;
    let client = running.harness.client().await;
    let root = &running.harness.root;
    let anytime = PlanRequest {
        model: PlannerModel::Anytime,
        ..request([-8.0, -8.0], [6.0, -7.0], 70.0, 100)
    };
    let greedy = PlanRequest {
        model: PlannerModel::Greedy,
        ..anytime.clone()
    };
    let a = ask(&client, root, &anytime).await.expect("an anytime plan");
    let g = ask(&client, root, &greedy).await.expect("a greedy plan");
    assert_eq!(a.model, PlannerModel::Anytime);
    assert!(a.within_budget && a.reaches_goal, "{a:?}");
    assert!(
        a.fitness.total >= g.fitness.total,
        "anytime {} below greedy {}",
        a.fitness.total,
        g.fitness.total
    );
    assert_eq!(g.found_by.as_deref(), Some("greedy"));
    let source = a.found_by.as_deref().expect("found_by");
    assert!(
        ["ga", "greedy", "via_seed", "shortest"].contains(&source),
        "{source}"
    );
    running.stop().await;
}
