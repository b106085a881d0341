//! One client cannot starve the planner for another: a client queues 10,000 requests
//! (each under a second of planning, deadlines of 600 s, the most a request may ask), and
//! a second client still gets its plan within its own 10 s deadline, served on its fair
//! share of the queue. Then the flood is answered to the last request when the planner
//! stops: nothing is left hanging.

use std::time::{Duration, Instant};

use roam_planner::client::PlannerClient;
use roam_planner::PlannerConfig;
use roam_proto::planner::{GaOverrides, PlanRequest, PlannerModel, ShortestPathUse};
use roam_proto::{decode, encode, keys, ErrorReply};
use roam_tests::Harness;

/// Requests the flooding client queues.
const FLOOD: usize = 10_000;
/// The second client's deadline.
const DEADLINE_S: f64 = 10.0;

fn request(generations: u32, deadline_s: f64, seed: u64) -> PlanRequest {
    PlanRequest {
        request_id: None,
        cancel_token: None,
        start: [-8.0, -8.0],
        goal: [6.0, -7.0],
        t_exec_s: 80.0,
        deadline_s,
        model: PlannerModel::Model1,
        params: GaOverrides {
            max_generations: Some(generations),
            population: Some(60),
            ..GaOverrides::default()
        },
        seed,
        map_version: None,
        shortest: ShortestPathUse::Omit,
        seed_route: Vec::new(),
    }
}

pub(crate) async fn second_client(harness: &Harness) {
    let map_server = harness.start_role(harness.map_server_config()).await;
    let planner = harness
        .start_role(PlannerConfig {
            max_concurrent_plans: 1,
            max_queued_plans: FLOOD,
            ..harness.planner_config("fair")
        })
        .await;
    let flooder = zenoh::open(harness.client_config()).await.expect("flooder");
    let key = format!("{}?client=flood", keys::planner_plan(&harness.root));
    let mut flood = tokio::task::JoinSet::new();
    for seed in 0..FLOOD as u64 {
        let (session, key) = (flooder.clone(), key.clone());
        let body = encode(&request(300, 600.0, seed));
        flood.spawn(async move {
            let replies = session
                .get(&key)
                .payload(body)
                .timeout(Duration::from_secs(600))
                .await
                .ok()?;
            let reply = replies.recv_async().await.ok()?;
            Some(match reply.result() {
                Ok(_) => "plan".to_owned(),
                Err(e) => String::from_utf8_lossy(&e.payload().to_bytes()).into_owned(),
            })
        });
    }
    // The flood is queued (its first plan running) before the second client asks.
    tokio::time::sleep(Duration::from_secs(4)).await;

    let session = zenoh::open(harness.client_config())
        .await
        .expect("second client");
    let client = PlannerClient::new(session.clone(), &harness.root);
    let asked = Instant::now();
    let plan = client.plan(&request(20, DEADLINE_S, 1)).await;
    let took = asked.elapsed().as_secs_f64();
    let plan =
        plan.unwrap_or_else(|e| panic!("the second client got no plan under the flood: {e}"));
    assert!(plan.reaches_goal, "{plan:?}");
    assert!(
        took <= DEADLINE_S,
        "the second client's plan took {took:.1} s, past its {DEADLINE_S} s deadline"
    );

    planner.stop().await.1.expect("planner stops cleanly");
    let answers = flood.join_all().await;
    let answered = answers.iter().flatten().count();
    // The flood held far more work than the second client's deadline: the queue
    // refused the rest of it for the wait.
    let longest_wait = answers
        .iter()
        .flatten()
        .filter_map(|a| decode::<ErrorReply>(a.as_bytes()).ok())
        .filter_map(|r| r.expected_wait_s)
        .fold(0.0_f64, f64::max);
    assert!(
        longest_wait > 10.0 * DEADLINE_S,
        "the flood queued only {longest_wait:.1} s of work"
    );
    eprintln!(
        "flood: {answered} of {FLOOD} answered, up to {longest_wait:.0} s of work queued; the second client's plan took {took:.2} s"
    );
    let _ = (session.close().await, flooder.close().await);
    map_server.stop().await.1.expect("map server stops cleanly");
}
