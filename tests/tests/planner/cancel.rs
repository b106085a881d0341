//! Progress and cancel through Zenoh: a plan's progress is published and its requester
//! may cancel it; a stranger's cancel (a guessed token, another robot's keys) does
//! nothing.

use super::*;
use crate::in_flight::*;

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

/// Issue 19: anyone sees request ids (progress keys are public), so an id is not enough
/// to cancel. A stranger's cancels, with a guessed token or none, do nothing; the
/// requester's token ends the plan.
///
/// Ordering makes it certain the stranger's cancels were handled while both plans ran:
/// the stranger cancels its own plan C last, from the same session, and the planner
/// handles one session's cancels in order. When C's cancelled reply arrives, A and B are
/// still planning; then each ends at its requester's cancel. Both plans are endless, so
/// neither can end on its own before the stranger's cancels are handled, however fast
/// the machine.
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
    let (a_progress, a) = start_endless_plan(&requester, &root, "plan-a", Some(TOKEN_A)).await;
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

    cancel(requester.session(), &root, "plan-a", Some(TOKEN_A)).await;
    let a = within("the requester's cancel of A", a)
        .await
        .expect("join")
        .expect("plan");
    assert_eq!(a.stop_reason, StopReason::Cancelled);
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
