//! Issue 16 through Zenoh: planning at 0.2 m on a 5 cm map (the depot scenario) gives
//! the in-process answer bit for bit and a path driven on the map's cells; the queue
//! answers a burst in order within deadlines, refuses at once what cannot make its
//! deadline, and lets a cancel reach a queued request; bad settings are refused
//! naming the limit. Real map server and planners in process, used only as a client.

use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use roam_planner::params::GaParams;
use roam_planner::plan::{plan, PlanSpec};
use roam_planner::world::World;
use roam_planner::PlannerConfig;
use roam_proto::planner::{
    GaOverrides, Plan, PlanProgress, PlanRequest, ShortestPathUse, StopReason,
};
use roam_proto::{decode, encode, keys, ErrorCode, ErrorReply};

use roam_runtime::ClientError;
use roam_tests::{repo_path, within, Harness};
use roam_world::layers::inflate;
use roam_world::DEFAULT_MAX_CELLS;

mod planner_client;
use planner_client::{ask, cancel, request, Running};

const DEPOT: &str = "config/scenarios/depot.yaml";

/// A map server on `map` (the built-in world when `None`) and one planner per config.
async fn boot(map: Option<&str>, planners: Vec<PlannerConfig>) -> Running {
    planner_client::boot_on(map, |harness| {
        planners
            .into_iter()
            .map(|mut config| {
                config.service.root = harness.root.clone();
                config
            })
            .collect()
    })
    .await
}

fn planner(name: &str) -> PlannerConfig {
    let mut config = PlannerConfig::default();
    config.service.instance = Some(name.to_owned());
    config
}

/// The depot is a 5 cm map; the planner plans at its default 0.2 m. Through Zenoh the
/// plan is the in-process plan on the same world bit for bit, twice; its cells are map
/// cells, free on the inflated layer, 8-connected without cut corners.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_coarse_plan_through_zenoh_equals_the_in_process_plan_bit_for_bit() {
    let running = boot(Some(DEPOT), vec![planner("coarse")]).await;
    let client = running.harness.client().await;
    let root = running.harness.root.clone();
    let req = request([3.0, 8.0], [20.0, 9.0], 80.0, 40);
    let remote = ask(&client, &root, &req).await.expect("plan");
    assert_eq!(remote.planning_resolution_m, Some(0.2));

    let scenario =
        roam_world::scenario::load(&repo_path(DEPOT), DEFAULT_MAX_CELLS).expect("scenario");
    let inflated = inflate(
        &scenario.occupancy,
        scenario.file.robot_radius_m.unwrap_or(0.2),
        65,
    );
    assert_eq!(inflated.meta.resolution, 0.05);
    let world = World::at_resolution(&inflated, &scenario.information, 0.25, 0.2).expect("world");
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
    assert_eq!(remote.cells, local.cells);
    assert_eq!(remote.t_eta_s.to_bits(), local.t_eta_s.to_bits());
    assert_eq!(
        remote.fitness.total.to_bits(),
        local.fitness.total.to_bits()
    );
    assert_eq!(remote.u_ges.to_bits(), local.metrics.u_ges.to_bits());
    assert!(remote.within_budget && remote.reaches_goal);

    let w = inflated.meta.width as i64;
    let free = |x: i64, y: i64| inflated.cells[(y * w + x) as usize] == 0;
    for pair in remote.cells.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        let (dx, dy) = (
            i64::from(b[0]) - i64::from(a[0]),
            i64::from(b[1]) - i64::from(a[1]),
        );
        assert!(dx.abs() <= 1 && dy.abs() <= 1 && (dx, dy) != (0, 0));
        assert!(free(i64::from(b[0]), i64::from(b[1])));
        if dx != 0 && dy != 0 {
            assert!(
                free(i64::from(a[0]) + dx, i64::from(a[1]))
                    && free(i64::from(a[0]), i64::from(a[1]) + dy)
            );
        }
    }
    let again = ask(&client, &root, &req).await.expect("plan");
    assert_eq!(again.cells, remote.cells);
    running.stop().await;
}

type Replies = zenoh::handlers::FifoChannelHandler<zenoh::query::Reply>;

/// Sends `request` on `instance`'s own key; returns once the query is out, so queries
/// sent one after another from one session arrive in that order.
async fn dispatch(
    session: &zenoh::Session,
    root: &str,
    instance: &str,
    request: &PlanRequest,
) -> Replies {
    within(
        "send",
        session
            .get(keys::planner_plan_at(root, instance))
            .payload(encode(request))
            .timeout(Duration::from_secs(120)),
    )
    .await
    .expect("query sent")
}

/// The answer in `replies`, and when it came.
async fn answer(replies: Replies) -> (Result<Plan, ErrorReply>, Instant) {
    let reply = tokio::time::timeout(Duration::from_secs(120), replies.recv_async())
        .await
        .expect("an answer within 120 s")
        .expect("a reply");
    let at = Instant::now();
    let result = match reply.result() {
        Ok(sample) => Ok(decode::<Plan>(&sample.payload().to_bytes()).expect("plan")),
        Err(error) => Err(decode::<ErrorReply>(&error.payload().to_bytes()).expect("error")),
    };
    (result, at)
}

const TOKEN: &str = "0123456789abcdef0123456789abcdef";

/// One plan at a time: behind a plan in progress, four requests with 60 s deadlines
/// wait in the queue and are answered in the order they arrived, each within its
/// deadline; a request whose deadline the queue cannot make is refused `busy` at once
/// with the expected wait; a cancel reaches a queued request, which is answered at once
/// (the fastest path, `stop_reason: cancelled`, no generations) while the plan ahead
/// of it still runs.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn queued_requests_are_answered_in_order_and_a_late_one_is_refused_at_once() {
    let running = boot(
        None,
        vec![PlannerConfig {
            max_concurrent_plans: 1,
            ..planner("one")
        }],
    )
    .await;
    let root = running.harness.root.clone();
    let session = running.harness.client().await.session().clone();
    // A plan that runs until it is cancelled (50,000 generations: a cost of 2e9, about
    // 20 s at the rate an instance assumes before it has measured one).
    let hog = PlanRequest {
        request_id: Some("hog".into()),
        cancel_token: Some(TOKEN.into()),
        params: GaOverrides {
            max_generations: Some(50_000),
            ..GaOverrides::default()
        },
        ..request([-8.0, -8.0], [6.0, -7.0], 80.0, 1)
    };
    let progress = within(
        "subscribe",
        session.declare_subscriber(keys::planner_progress(&root, "hog")),
    )
    .await
    .expect("subscriber");
    let hog_replies = dispatch(&session, &root, "one", &hog).await;
    within("the hog plans", progress.recv_async())
        .await
        .expect("progress");

    let sent = Instant::now();
    let mut queued = Vec::new();
    for k in 0..4 {
        let req = PlanRequest {
            request_id: Some(format!("queued-{k}")),
            seed: k,
            ..request([-8.0, -8.0], [-2.0, 4.0], 60.0, 30)
        };
        // Each answer is stamped as it arrives, whatever order they are read in.
        let replies = dispatch(&session, &root, "one", &req).await;
        queued.push(tokio::spawn(answer(replies)));
    }
    // Cannot make 2 s behind a plan expected to take 20 s: refused at once.
    let hurried = PlanRequest {
        request_id: Some("hurried".into()),
        deadline_s: 2.0,
        ..request([-8.0, -8.0], [-2.0, 4.0], 60.0, 30)
    };
    let asked = Instant::now();
    let (refused, at) = answer(dispatch(&session, &root, "one", &hurried).await).await;
    let refused = refused.expect_err("refused");
    assert_eq!(refused.code, ErrorCode::Busy, "{refused}");
    assert!(at - asked < Duration::from_secs(2), "refused at once");
    assert!(
        refused.expected_wait_s.is_some_and(|w| w > 2.0),
        "{refused}"
    );

    // A cancellable request, queued last, then cancelled: out of the queue at once.
    let doomed = PlanRequest {
        request_id: Some("doomed".into()),
        cancel_token: Some(TOKEN.into()),
        ..request([-8.0, -8.0], [6.0, -7.0], 80.0, 30)
    };
    let doomed_progress = within(
        "subscribe",
        session.declare_subscriber(keys::planner_progress(&root, "doomed")),
    )
    .await
    .expect("subscriber");
    let doomed_replies = dispatch(&session, &root, "one", &doomed).await;
    // A queued request's progress says so: an empty batch.
    let queued_note = within("queued", doomed_progress.recv_async())
        .await
        .expect("progress");
    let note: PlanProgress = decode(&queued_note.payload().to_bytes()).expect("progress");
    assert!(note.best_fitness.is_empty() && !note.done);
    cancel(&session, &root, "doomed", Some(TOKEN)).await;
    let (doomed, _) = answer(doomed_replies).await;
    let doomed = doomed.expect("a cancelled queued request gets its floor");
    assert_eq!(doomed.stop_reason, StopReason::Cancelled);
    assert_eq!(doomed.generations, 0);
    assert!(doomed.within_budget && doomed.reaches_goal);
    assert!(
        matches!(hog_replies.try_recv(), Ok(None)),
        "the plan ahead of it still runs"
    );

    cancel(&session, &root, "hog", Some(TOKEN)).await;
    let (hog, _) = answer(hog_replies).await;
    assert_eq!(hog.expect("hog").stop_reason, StopReason::Cancelled);
    let mut times = Vec::new();
    for (k, pending) in queued.into_iter().enumerate() {
        let (plan, at) = within("a queued answer", pending).await.expect("join");
        let plan = plan.unwrap_or_else(|e| panic!("queued-{k}: {e}"));
        assert_eq!(plan.request_id, format!("queued-{k}"));
        assert_eq!(plan.stop_reason, StopReason::MaxGenerations, "{k}");
        assert!(at - sent < Duration::from_secs(60), "within its deadline");
        times.push(at);
    }
    assert!(times.windows(2).all(|w| w[0] <= w[1]), "answered in order");
    running.stop().await;
}

/// A queue length of 0 or 10⁹ and an absurd planning resolution are refused at startup,
/// naming the setting and what is allowed.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn bad_queue_lengths_and_planning_resolutions_are_refused_naming_the_limit() {
    use roam_planner::service::{check_config, PlannerError};
    for (config, name) in [
        (
            PlannerConfig {
                max_queued_plans: 0,
                ..PlannerConfig::default()
            },
            "max_queued_plans",
        ),
        (
            PlannerConfig {
                max_queued_plans: 1_000_000_000,
                ..PlannerConfig::default()
            },
            "max_queued_plans",
        ),
        (
            PlannerConfig {
                planning_resolution_m: Some(50.0),
                ..PlannerConfig::default()
            },
            "planning_resolution_m",
        ),
        (
            PlannerConfig {
                planning_resolution_m: Some(0.0),
                ..PlannerConfig::default()
            },
            "planning_resolution_m",
        ),
    ] {
        match check_config(&config) {
            Err(PlannerError::Setting(e)) => {
                assert_eq!(e.name, name);
                assert!(
                    e.to_string().contains(name) && e.to_string().contains("use "),
                    "{e}"
                );
            }
            other => panic!("{name}: {other:?}"),
        }
        // The service refuses to start with it, before it opens a session.
        let harness = Harness::start().await;
        let outcome = within(
            "a refused start",
            roam_planner::run(
                config,
                harness.client_config(),
                tokio_util::sync::CancellationToken::new(),
            ),
        )
        .await;
        assert!(
            matches!(outcome, Err(PlannerError::Setting(_))),
            "{outcome:?}"
        );
        harness.close().await;
    }
    let limit = roam_planner::queue::MAX_QUEUED_PLANS;
    let edge = PlannerConfig {
        max_queued_plans: limit,
        ..PlannerConfig::default()
    };
    assert!(check_config(&edge).is_ok());
}

/// A planning resolution finer than the map's: the planner has no world to plan on, and
/// says why in every refusal, naming the setting and the map's resolution.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_planning_resolution_finer_than_the_map_is_refused_in_every_reply() {
    let harness = Harness::start().await;
    let map_server = harness
        .start_role(roam_map_server::MapServerConfig {
            map: Some(repo_path(DEPOT)),
            ..harness.map_server_config()
        })
        .await;
    let mut config = PlannerConfig {
        planning_resolution_m: Some(0.02),
        ..planner("fine")
    };
    config.service.root = harness.root.clone();
    let cancel = tokio_util::sync::CancellationToken::new();
    let service = tokio::spawn(roam_planner::run(
        config,
        harness.client_config(),
        cancel.clone(),
    ));
    let client = harness.client().await;
    // The planner answers on the shared key before it has a world; ask until it says why.
    let mut reason = None;
    for _ in 0..100 {
        match client
            .request::<PlanRequest, Plan>(
                &keys::planner_plan(&harness.root),
                Some(&request([3.0, 8.0], [20.0, 9.0], 80.0, 5)),
            )
            .await
        {
            Err(ClientError::Refused(e)) if e.message.contains("planning_resolution_m") => {
                reason = Some(e);
                break;
            }
            Err(_) => tokio::time::sleep(Duration::from_millis(100)).await,
            Ok(plan) => panic!("planned at {:?}", plan.planning_resolution_m),
        }
    }
    let reason = reason.expect("a refusal naming planning_resolution_m");
    assert_eq!(reason.code, ErrorCode::Unavailable);
    assert!(reason.message.contains("0.05 m"), "{}", reason.message);
    cancel.cancel();
    within("planner stops", service)
        .await
        .expect("join")
        .expect("stops");
    map_server.stop().await.1.expect("map server stops");
    harness.close().await;
}
