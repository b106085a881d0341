//! Per-robot credentials: robot r1's executive (`mission-r1`) and controller
//! (`controller-r1`) reach r1's keys only, each for its own job.
//!
//! Every refusal is observed where the message would arrive: sessions with the
//! receivers' credentials (the operator, who reads every publication; the sim, who
//! receives commands; r2's controller and executive) subscribed to the keys and getting
//! nothing, a real planner whose query gets no reply, and r2's plan that goes on
//! planning. Each sender ends with a message of its own job that does pass, and the
//! checks wait for it: a refused message sent before it would have arrived before it.

use roam_planner::client::{PlanTicket, PlannerClient};
use roam_planner::PlannerConfig;
use roam_proto::planner::{GaOverrides, Plan, PlanRequest, PlannerModel, StopReason};
use roam_proto::{encode, keys};
use roam_runtime::{ClientError, Requester};
use roam_tests::{within, Harness};

use crate::intrusion::DENIED_QUERY_WAIT;
use crate::observe::{drain, heard_until, put, subscribe, Spy, SETTLE};
use crate::site::secure_site;
use crate::ROOT;

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_robots_credentials_publish_and_hear_its_own_keys_only() {
    let (_secrets, harness) = secure_site().await;
    let operator = Spy::on(&harness, "operator", &format!("{ROOT}/robot/**")).await;
    let sim = Spy::on(&harness, "sim", &keys::robot_command_any(ROOT)).await;
    let mut r2_receivers = Vec::new();
    for (user, leaves) in [
        ("controller-r2", ["mission", "estimate"]),
        ("mission-r2", ["estimate", "controller"]),
    ] {
        for leaf in leaves {
            let key = format!("{ROOT}/robot/r2/{leaf}");
            r2_receivers.push(Spy::on(&harness, user, &key).await);
        }
    }
    let r1_controller = Spy::on(&harness, "controller-r1", &keys::robot_mission(ROOT, "r1")).await;
    let r1_executive = Spy::on(&harness, "mission-r1", &keys::robot_controller(ROOT, "r1")).await;

    let forged = || b"forged".to_vec();
    let r2_keys = [
        keys::robot_mission(ROOT, "r2"),
        keys::robot_command(ROOT, "r2"),
        keys::robot_estimate(ROOT, "r2"),
        keys::robot_controller(ROOT, "r2"),
        keys::robot_command_any(ROOT),
        format!("{ROOT}/robot/**"),
    ];

    // r1's executive: none of r2's keys, nor r1's command or estimate (not its job); then
    // r1's mission, which r1's controller and the operator receive.
    let executive = harness.client_as("mission-r1").await;
    for key in r2_keys.iter().cloned().chain([
        keys::robot_command(ROOT, "r1"),
        keys::robot_estimate(ROOT, "r1"),
    ]) {
        put(&executive, &key, forged()).await;
    }
    let r1_mission = keys::robot_mission(ROOT, "r1");
    put(&executive, &r1_mission, forged()).await;
    assert_eq!(
        heard_until(&operator, &r1_mission).await,
        std::slice::from_ref(&r1_mission)
    );
    assert_eq!(heard_until(&r1_controller, &r1_mission).await, [r1_mission]);

    // r1's controller: the same, but r1's mission instead of its command; then r1's
    // command and status, which the sim and r1's executive receive.
    let controller = harness.client_as("controller-r1").await;
    for key in r2_keys.iter().cloned().chain([
        keys::robot_mission(ROOT, "r1"),
        keys::robot_estimate(ROOT, "r1"),
    ]) {
        put(&controller, &key, forged()).await;
    }
    let (r1_command, r1_status) = (
        keys::robot_command(ROOT, "r1"),
        keys::robot_controller(ROOT, "r1"),
    );
    put(&controller, &r1_command, forged()).await;
    put(&controller, &r1_status, forged()).await;
    assert_eq!(
        heard_until(&operator, &r1_status).await,
        [r1_command.clone(), r1_status.clone()]
    );
    assert_eq!(heard_until(&sim, &r1_command).await, [r1_command]);
    assert_eq!(heard_until(&r1_executive, &r1_status).await, [r1_status]);
    for spy in &r2_receivers {
        assert_eq!(
            drain(&spy.subscriber),
            Vec::<String>::new(),
            "{} heard r1's credentials on r2's keys",
            spy.user
        );
    }

    // Nor do r1's credentials hear r2: r2's executive gives r2 a mission, r2's
    // controller hears it, r1's controller (on r2's key, and on every robot's) does not.
    let r1_listening = [
        Spy::on(&harness, "controller-r1", &keys::robot_mission(ROOT, "r2")).await,
        Spy::on(&harness, "controller-r1", &keys::robot_mission_any(ROOT)).await,
        Spy::on(&harness, "mission-r1", &keys::robot_estimate_any(ROOT)).await,
    ];
    let r2_executive = harness.client_as("mission-r2").await;
    let r2_mission = keys::robot_mission(ROOT, "r2");
    put(&r2_executive, &r2_mission, forged()).await;
    assert_eq!(
        heard_until(&r2_receivers[0], &r2_mission).await,
        [r2_mission]
    );
    for spy in &r1_listening {
        assert_eq!(
            drain(&spy.subscriber),
            Vec::<String>::new(),
            "{} heard r2's mission",
            spy.user
        );
    }
    harness.close().await;
}

/// A plan that runs until it is cancelled (50,000 generations), cancellable with `token`.
fn endless(id: &str, token: &str) -> PlanRequest {
    PlanRequest {
        request_id: Some(id.into()),
        cancel_token: Some(token.into()),
        start: [-8.0, -8.0],
        goal: [6.0, -7.0],
        t_exec_s: 80.0,
        deadline_s: 60.0,
        model: PlannerModel::Model1,
        params: GaOverrides {
            max_generations: Some(50_000),
            population: Some(60),
            ..GaOverrides::default()
        },
        seed: 11,
        map_version: None,
        shortest: Default::default(),
        seed_route: Vec::new(),
    }
}

/// A quick plan.
fn quick() -> PlanRequest {
    PlanRequest {
        request_id: None,
        cancel_token: None,
        params: GaOverrides {
            max_generations: Some(5),
            population: Some(20),
            ..GaOverrides::default()
        },
        ..endless("quick", "0123456789abcdef0123456789abcdef")
    }
}

/// Starts `request` for `robot` through its executive's planner client (in the
/// background) and waits until it plans; its ticket and its pending reply.
async fn start_plan(
    harness: &Harness,
    user: &str,
    robot: &str,
    mut request: PlanRequest,
) -> (
    PlanTicket,
    std::sync::Arc<PlannerClient>,
    tokio::task::JoinHandle<Result<Plan, ClientError>>,
) {
    let ticket = PlanTicket::issue(&mut request);
    let operator = harness.client_as("operator").await;
    let progress = subscribe(
        &operator,
        &keys::planner_robot_progress(ROOT, robot, &ticket.request_id),
    )
    .await;
    let session = harness.client_as(user).await.session().clone();
    let planner = std::sync::Arc::new(PlannerClient::for_robot(session, ROOT, robot));
    let pending = tokio::spawn({
        let planner = planner.clone();
        async move { planner.plan(&request).await }
    });
    within("the plan's progress", progress.recv_async())
        .await
        .unwrap_or_else(|e| panic!("{robot}'s plan is planning: {e}"));
    (ticket, planner, pending)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_robots_credentials_ask_and_cancel_its_own_plans_only() {
    let (_secrets, harness) = secure_site().await;
    let map_server = harness.start_role(harness.map_server_config()).await;
    let planner = harness
        .start_role(PlannerConfig {
            max_concurrent_plans: 3,
            plan_seconds_burst: 300.0,
            ..harness.planner_config("planner-0")
        })
        .await;

    // Asking: r1's executive gets r1's plans (on the shared robot key and through its
    // planner client, on an instance's); r2's, and the shared key's, get no reply from
    // the planner that answers them. r1's controller plans nothing.
    let executive = harness.client_as("mission-r1").await;
    let controller = harness.client_as("controller-r1").await;
    let asked = within(
        "r1's plan",
        executive
            .request::<PlanRequest, Plan>(&keys::planner_robot_plan(ROOT, "r1"), Some(&quick())),
    )
    .await;
    assert!(asked.is_ok(), "r1's executive plans for r1: {asked:?}");
    let client = PlannerClient::for_robot(executive.session().clone(), ROOT, "r1");
    let asked = within("r1's plan by an instance", client.plan(&quick())).await;
    assert!(asked.is_ok(), "r1's executive plans for r1: {asked:?}");
    let r2_executive = harness.client_as("mission-r2").await;
    let asked = within(
        "r2's plan",
        r2_executive
            .request::<PlanRequest, Plan>(&keys::planner_robot_plan(ROOT, "r2"), Some(&quick())),
    )
    .await;
    assert!(asked.is_ok(), "r2's executive plans for r2: {asked:?}");
    for (user, session) in [("mission-r1", &executive), ("controller-r1", &controller)] {
        let asker = Requester::new(session.session().clone(), DENIED_QUERY_WAIT);
        for key in [
            keys::planner_robot_plan(ROOT, "r2"),
            keys::planner_robot_plan_at(ROOT, "planner-0", "r2"),
            keys::planner_plan(ROOT),
            keys::planner_plan_at(ROOT, "planner-0"),
        ]
        .into_iter()
        .chain((user == "controller-r1").then(|| keys::planner_robot_plan(ROOT, "r1")))
        {
            let outcome = within(
                "a refused plan",
                asker.request::<PlanRequest, Plan>(&key, Some(&quick())),
            )
            .await;
            assert!(
                matches!(outcome, Err(ClientError::NoReply { .. })),
                "{user} on {key}: the planner must never get it (no reply at all), got {outcome:?}"
            );
        }
    }

    // Cancelling: r2's plan and r1's, the same id and token. r1's credentials cancel
    // r2's (on r2's key, even with its token) and the shared key's: r2's plan goes on.
    // r1's executive's last cancel, of r1's own plan, comes on the same planner
    // subscription after its cancel of r2's: when r1's plan has ended, r2's cancel
    // would have been handled.
    let token = "0123456789abcdef0123456789abcdef";
    let (r2_ticket, r2_planner, r2_plan) =
        start_plan(&harness, "mission-r2", "r2", endless("trip", token)).await;
    let (r1_ticket, r1_planner, r1_plan) =
        start_plan(&harness, "mission-r1", "r1", endless("trip", token)).await;
    let r2_cancel = encode(&r2_ticket.cancel_message());
    for session in [&controller, &executive] {
        put(
            session,
            &keys::planner_robot_cancel(ROOT, "r2", "trip"),
            r2_cancel.clone(),
        )
        .await;
        put(
            session,
            &keys::planner_cancel(ROOT, "trip"),
            r2_cancel.clone(),
        )
        .await;
    }
    within("r1's cancel", r1_planner.cancel(&r1_ticket))
        .await
        .expect("cancel put");
    let r1_plan = within("r1's plan", r1_plan)
        .await
        .expect("join")
        .expect("r1's plan");
    assert_eq!(
        r1_plan.stop_reason,
        StopReason::Cancelled,
        "r1 cancels its own plan"
    );
    tokio::time::sleep(SETTLE).await;
    assert!(
        !r2_plan.is_finished(),
        "r1's credentials must not cancel r2's plan"
    );
    // ... which its own executive can.
    within("r2's cancel", r2_planner.cancel(&r2_ticket))
        .await
        .expect("cancel put");
    let r2_plan = within("r2's plan", r2_plan)
        .await
        .expect("join")
        .expect("r2's plan");
    assert_eq!(r2_plan.stop_reason, StopReason::Cancelled);

    planner.stop().await.1.expect("the planner stops cleanly");
    map_server
        .stop()
        .await
        .1
        .expect("the map server stops cleanly");
    harness.close().await;
}
