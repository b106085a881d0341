//! The planner through Zenoh: plans, determinism against the in-process planner, the
//! shortest path attached, progress, cancel (only with the requester's token), busy, the
//! limits and the CPU budget, made-up request ids, a robot's plans on its own keys, and
//! two instances sharing load and surviving one's death (its refusals:
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

mod planner_client;
use planner_client::{ask, boot, boot_with, cancel, refusal, request};

type ProgressSubscriber =
    zenoh::pubsub::Subscriber<zenoh::handlers::FifoChannelHandler<zenoh::sample::Sample>>;

/// Sends `request` (which names its id) in the background, with a subscriber to its
/// progress declared first.
async fn start_plan(
    client: &Requester,
    root: &str,
    request: PlanRequest,
) -> (
    ProgressSubscriber,
    tokio::task::JoinHandle<Result<Plan, ClientError>>,
) {
    let id = request.request_id.clone().expect("a named request");
    let subscriber = within(
        "subscribe",
        client
            .session()
            .declare_subscriber(keys::planner_progress(root, &id)),
    )
    .await
    .expect("progress subscriber");
    // The plans started here take longer than a harness client's 5 s.
    let client = Requester::new(client.session().clone(), Duration::from_secs(60));
    let root = root.to_owned();
    let pending = tokio::spawn(async move {
        client
            .request::<PlanRequest, Plan>(&keys::planner_plan(&root), Some(&request))
            .await
    });
    (subscriber, pending)
}

/// A plan that runs until it is cancelled (50,000 generations: a cost of 2e9, inside
/// `max_plan_cost`; 30 s of the CPU budget), cancellable with `token`.
fn endless(id: &str, token: Option<&str>) -> PlanRequest {
    PlanRequest {
        request_id: Some(id.into()),
        cancel_token: token.map(str::to_owned),
        params: GaOverrides {
            max_generations: Some(50_000),
            ..GaOverrides::default()
        },
        ..request([-8.0, -8.0], [6.0, -7.0], 80.0, 1)
    }
}

/// Starts [`endless`], with a subscriber to its progress.
async fn start_endless_plan(
    client: &Requester,
    root: &str,
    id: &str,
    token: Option<&str>,
) -> (
    ProgressSubscriber,
    tokio::task::JoinHandle<Result<Plan, ClientError>>,
) {
    start_plan(client, root, endless(id, token)).await
}

/// How long a plan may take to report its first progress. Three plans start at once on
/// three workers in a debug build; beside the rest of the test suite on two cores the
/// first report once took longer than the harness's [`roam_tests::STEP`]. What these
/// tests check is what a cancel does, not how fast a plan starts.
const FIRST_PROGRESS: Duration = Duration::from_secs(60);

/// Waits for the first progress message of a plan: it is planning.
async fn planning(subscriber: &ProgressSubscriber) {
    tokio::time::timeout(FIRST_PROGRESS, subscriber.recv_async())
        .await
        .expect("no progress from the plan within FIRST_PROGRESS")
        .expect("the plan is planning");
}

const TOKEN_A: &str = "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa";
const TOKEN_B: &str = "bbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbb";
const TOKEN_C: &str = "cccccccccccccccccccccccccccccccc";
/// Right length, right alphabet, wrong secret.
const GUESS: &str = "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaab";

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
        };
        let local = plan(&world, &spec, &AtomicBool::new(false), |_, _| {}).expect("local");
        assert_eq!(remote.cells, world.grid_cells(&local.path));
    }
    running.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn progress_is_published_and_a_plan_can_be_cancelled() {
    let running = boot(&[("solo", 2)]).await;
    let client = running.harness.client().await;
    let root = running.harness.root.clone();
    let id = "long-plan";
    let (subscriber, pending) = start_endless_plan(&client, &root, id, Some(TOKEN_A)).await;
    // Progress arrives while it plans: generations in order, best fitness never worse.
    let mut seen: Vec<(u32, f64)> = Vec::new();
    while seen.len() < 5 {
        let sample = within("progress", subscriber.recv_async())
            .await
            .expect("sample");
        let progress: PlanProgress = decode(&sample.payload().to_bytes()).expect("progress");
        assert_eq!(progress.request_id, id);
        seen.extend(progress.best_fitness);
    }
    assert!(
        seen.windows(2)
            .all(|w| w[1].0 == w[0].0 + 1 && w[1].1 >= w[0].1),
        "{seen:?}"
    );

    cancel(client.session(), &root, id, Some(TOKEN_A)).await;
    let plan = within("cancelled plan", pending)
        .await
        .expect("join")
        .expect("plan");
    assert_eq!(plan.stop_reason, StopReason::Cancelled);
    assert!(plan.generations < 50_000);
    // Progress runs until a message says done; the last generation it reports is the
    // plan's, with the plan's fitness: the best path so far is what was returned.
    loop {
        let sample = within("final progress", subscriber.recv_async())
            .await
            .expect("sample");
        let progress: PlanProgress = decode(&sample.payload().to_bytes()).expect("progress");
        seen.extend(progress.best_fitness);
        if progress.done {
            break;
        }
    }
    let (last_generation, last_best) = *seen.last().expect("progress");
    assert_eq!(last_generation, plan.generations, "{seen:?}");
    assert_eq!(
        last_best.to_bits(),
        plan.fitness.total.to_bits(),
        "{plan:?}"
    );
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

/// Issue 19: anyone sees request ids (progress keys are public), so an id is not enough
/// to cancel. A stranger's cancels, with a guessed token or none, do nothing; the
/// requester's token ends the plan.
///
/// Ordering makes it certain the stranger's cancels were handled while both plans ran:
/// the stranger cancels its own plan C last, from the same session, and the planner
/// handles one session's cancels in order. When C's cancelled reply arrives, A and B are
/// still planning; then A runs to its last generation and B ends at its requester's
/// cancel.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_strangers_cancel_does_nothing_and_the_requesters_cancel_ends_the_plan() {
    let running = boot_with(&[("solo", 3)], |config| roam_planner::PlannerConfig {
        plan_seconds_burst: 300.0,
        ..config
    })
    .await;
    let root = running.harness.root.clone();
    let requester = running.harness.client().await;
    let stranger = running.harness.client().await;
    // Long enough that A cannot finish before the stranger's cancels are handled on a
    // loaded machine (2,500 did once in a full run), short enough to wait for after.
    let generations = 10_000;
    let finite = PlanRequest {
        request_id: Some("plan-a".into()),
        cancel_token: Some(TOKEN_A.into()),
        ..request([-8.0, -8.0], [6.0, -7.0], 80.0, generations)
    };
    let (a_progress, a) = start_plan(&requester, &root, finite).await;
    let (b_progress, b) = start_endless_plan(&requester, &root, "plan-b", Some(TOKEN_B)).await;
    let (c_progress, c) = start_endless_plan(&stranger, &root, "plan-c", Some(TOKEN_C)).await;
    for progress in [&a_progress, &b_progress, &c_progress] {
        planning(progress).await;
    }
    for id in ["plan-a", "plan-b"] {
        cancel(stranger.session(), &root, id, Some(GUESS)).await;
        cancel(stranger.session(), &root, id, None).await;
        cancel(stranger.session(), &root, id, Some(TOKEN_C)).await;
    }
    cancel(stranger.session(), &root, "plan-c", Some(TOKEN_C)).await;
    let c = within("the stranger's own plan", c)
        .await
        .expect("join")
        .expect("plan");
    assert_eq!(c.stop_reason, StopReason::Cancelled);
    assert!(
        !a.is_finished() && !b.is_finished(),
        "A and B must still be planning when the stranger's cancels have been handled"
    );

    cancel(requester.session(), &root, "plan-b", Some(TOKEN_B)).await;
    let b = within("the requester's cancel", b)
        .await
        .expect("join")
        .expect("plan");
    assert_eq!(b.stop_reason, StopReason::Cancelled);
    assert!(b.generations < 50_000);

    let a = tokio::time::timeout(Duration::from_secs(60), a)
        .await
        .expect("plan A completes")
        .expect("join")
        .expect("plan");
    assert_eq!(a.stop_reason, StopReason::MaxGenerations);
    assert_eq!(a.generations, generations);
    running.stop().await;
}

/// A robot's plans live on the robot's keys (`roam_planner::scope`): the same request id
/// is planned at once for robot r1, robot r2 and on the shared key, with the same
/// token, and each plan is cancelled only by a cancel on its own key. r1's plan is asked
/// through `PlannerClient::for_robot` (an instance's robot key) and its progress comes
/// on r1's progress key. A query whose robot is a wildcard is refused.
///
/// Each cancel is followed by the reply of the plan it was for, so it had been handled
/// (the planner handles one subscription's samples in order, and only that plan ended)
/// when the other plans are checked to be still planning.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_robots_plan_is_cancelled_on_its_own_keys_only() {
    let running = boot_with(&[("solo", 3)], |config| roam_planner::PlannerConfig {
        plan_seconds_burst: 300.0,
        ..config
    })
    .await;
    let root = running.harness.root.clone();
    let client = running.harness.client().await;
    let id = "trip";

    let r1_progress = within(
        "subscribe",
        client
            .session()
            .declare_subscriber(keys::planner_robot_progress(&root, "r1", id)),
    )
    .await
    .expect("r1's progress subscriber");
    let r1_planner = std::sync::Arc::new(PlannerClient::for_robot(
        client.session().clone(),
        &root,
        "r1",
    ));
    let mut r1_request = endless(id, Some(TOKEN_A));
    let r1_ticket = roam_planner::client::PlanTicket::issue(&mut r1_request);
    let r1 = tokio::spawn({
        let planner = r1_planner.clone();
        async move { planner.plan(&r1_request).await }
    });
    planning(&r1_progress).await;

    let long = Requester::new(client.session().clone(), Duration::from_secs(60));
    let ask_on = |key: String| {
        let long = long.clone();
        tokio::spawn(async move {
            long.request::<PlanRequest, Plan>(&key, Some(&endless(id, Some(TOKEN_A))))
                .await
        })
    };
    let r2 = ask_on(keys::planner_robot_plan(&root, "r2"));
    let shared = ask_on(keys::planner_plan(&root));
    for progress in [
        keys::planner_robot_progress(&root, "r2", id),
        keys::planner_progress(&root, id),
    ] {
        let subscriber = within("subscribe", client.session().declare_subscriber(progress))
            .await
            .expect("progress subscriber");
        planning(&subscriber).await;
    }

    cancel(client.session(), &root, id, Some(TOKEN_A)).await;
    let shared = within("the shared plan", shared)
        .await
        .expect("join")
        .expect("plan");
    assert_eq!(shared.stop_reason, StopReason::Cancelled);
    assert!(
        !r1.is_finished() && !r2.is_finished(),
        "a cancel on the shared key must not stop a robot's plan"
    );

    within(
        "r2's cancel",
        client.session().put(
            keys::planner_robot_cancel(&root, "r2", id),
            roam_proto::encode(&r1_ticket.cancel_message()),
        ),
    )
    .await
    .expect("cancel put");
    let r2 = within("r2's plan", r2).await.expect("join").expect("plan");
    assert_eq!(r2.stop_reason, StopReason::Cancelled);
    assert!(
        !r1.is_finished(),
        "a cancel on r2's key must not stop r1's plan"
    );

    within("r1's cancel", r1_planner.cancel(&r1_ticket))
        .await
        .expect("cancel put");
    let r1 = within("r1's plan", r1).await.expect("join").expect("plan");
    assert_eq!(r1.stop_reason, StopReason::Cancelled);
    assert_eq!(r1.instance, "solo");

    let wildcard = within(
        "a plan for any robot",
        client.request::<PlanRequest, Plan>(
            &keys::planner_robot_plan(&root, "*"),
            Some(&request([-8.0, -8.0], [6.0, -7.0], 80.0, 5)),
        ),
    )
    .await;
    match wildcard {
        Err(ClientError::Refused(reply)) => {
            assert_eq!(reply.code, ErrorCode::InvalidRequest, "{reply}")
        }
        other => panic!("a wildcard robot must be refused, got {other:?}"),
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
