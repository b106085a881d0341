//! Every refusal of the planner through Zenoh is structured (a code, a message that
//! says what to change, the limit named) and bounded: positions off the map or in an
//! obstacle, budgets too short, bad parameters, stale map versions, malformed and
//! oversized payloads. Real map server and planner in process, used only as a client.

use std::time::{Duration, Instant};

use roam_proto::planner::{GaOverrides, MapVersion, Plan, PlanRequest, StopReason};
use roam_proto::{keys, ErrorCode};
use roam_runtime::ClientError;
use roam_tests::within;

mod planner_client;
use planner_client::{ask, boot, refusal, request};

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn every_refusal_is_structured_and_says_what_to_change() {
    let running = boot(&[("solo", 2)]).await;
    let client = running.harness.client().await;
    let root = running.harness.root.clone();
    let ok = request([-8.0, -8.0], [6.0, -7.0], 80.0, 5);

    let off = refusal(
        &client,
        &root,
        &PlanRequest {
            start: [40.0, 0.0],
            ..ok.clone()
        },
    )
    .await;
    assert_eq!(off.code, ErrorCode::InvalidRequest);
    assert!(off.message.contains("off the map"), "{}", off.message);

    let blocked = refusal(
        &client,
        &root,
        &PlanRequest {
            goal: [-9.9, 0.0],
            ..ok.clone()
        },
    )
    .await;
    assert!(
        blocked.message.contains("inside an obstacle"),
        "{}",
        blocked.message
    );

    let short = refusal(
        &client,
        &root,
        &PlanRequest {
            t_exec_s: 10.0,
            ..ok.clone()
        },
    )
    .await;
    assert_eq!(short.code, ErrorCode::InvalidRequest);
    assert!(
        short
            .message
            .contains("shorter than the fastest path's ETA"),
        "{}",
        short.message
    );

    let deadline = refusal(
        &client,
        &root,
        &PlanRequest {
            deadline_s: 5000.0,
            ..ok.clone()
        },
    )
    .await;
    assert_eq!(deadline.code, ErrorCode::LimitExceeded);
    assert_eq!(
        deadline.limit.map(|l| l.name),
        Some("deadline_s".to_owned())
    );

    let params = refusal(
        &client,
        &root,
        &PlanRequest {
            params: GaOverrides {
                mutation_ratio: Some(2.0),
                ..GaOverrides::default()
            },
            ..ok.clone()
        },
    )
    .await;
    assert!(
        params.message.contains("mutation_ratio"),
        "{}",
        params.message
    );

    // An impossible time model (a robot that drives in no time) names the parameter
    // and its range.
    let time_model = refusal(
        &client,
        &root,
        &PlanRequest {
            params: GaOverrides {
                v_lin: Some(0.0),
                ..GaOverrides::default()
            },
            ..ok.clone()
        },
    )
    .await;
    assert_eq!(time_model.code, ErrorCode::InvalidRequest, "{time_model:?}");
    assert!(
        time_model.message.contains("v_lin") && time_model.message.contains("(0, 1000]"),
        "{}",
        time_model.message
    );

    // A cancel token outside the rules is refused without being repeated.
    let token = refusal(
        &client,
        &root,
        &PlanRequest {
            cancel_token: Some("short-secret".into()),
            ..ok.clone()
        },
    )
    .await;
    assert_eq!(token.code, ErrorCode::InvalidRequest);
    assert!(token.message.contains("cancel_token"), "{}", token.message);
    assert!(!token.message.contains("short-secret"), "{}", token.message);

    // A huge request id comes back as a short excerpt and its length.
    let long_id = "x".repeat(60_000);
    let id = refusal(
        &client,
        &root,
        &PlanRequest {
            request_id: Some(long_id),
            ..ok.clone()
        },
    )
    .await;
    assert_eq!(id.code, ErrorCode::InvalidRequest);
    assert!(id.message.contains("(60000 bytes)"), "{}", id.message);
    assert!(id.message.len() < 400, "{} bytes", id.message.len());

    // A decoder's error quoting a huge string is bounded too.
    let quoted = match within(
        "raw",
        client.request_raw::<Plan>(
            &keys::planner_plan(&root),
            Some(
                format!(
                    r#"{{"v":1,"kind":"plan_request","body":{{"start":[0,0],"goal":[1,1],"t_exec_s":1,"deadline_s":1,"model":"{}"}}}}"#,
                    "m".repeat(50_000)
                )
                .into_bytes(),
            ),
        ),
    )
    .await
    {
        Err(ClientError::Refused(r)) => r,
        other => panic!("{other:?}"),
    };
    assert_eq!(quoted.code, ErrorCode::Malformed);
    assert!(
        quoted.message.len() < 1000,
        "{} bytes",
        quoted.message.len()
    );
    // It says how long the whole text was (the 50,000-character variant and serde's
    // list of the models expected), not only the part it quotes.
    let stated = quoted
        .message
        .split_once("… (")
        .and_then(|(_, rest)| rest.split_once(" bytes)"))
        .and_then(|(n, _)| n.parse::<usize>().ok());
    assert!(stated.is_some_and(|n| n > 50_000), "{}", quoted.message);

    let version = refusal(
        &client,
        &root,
        &PlanRequest {
            map_version: Some(MapVersion {
                inflated: 99,
                information: 1,
                change: None,
                obstacles: None,
            }),
            ..ok.clone()
        },
    )
    .await;
    assert_eq!(version.code, ErrorCode::NotFound);
    assert!(version.message.contains("unknown"), "{}", version.message);

    let malformed = match within(
        "raw",
        client.request_raw::<Plan>(&keys::planner_plan(&root), Some(b"[1,2".to_vec())),
    )
    .await
    {
        Err(ClientError::Refused(r)) => r,
        other => panic!("{other:?}"),
    };
    assert_eq!(malformed.code, ErrorCode::Malformed);

    // No path: wall the goal in through the map server, then plan on the new map.
    let mut cells = Vec::new();
    for x in 30..=36u32 {
        cells.push(roam_proto::map::CellWrite {
            x,
            y: 30,
            value: 100.0,
        });
        cells.push(roam_proto::map::CellWrite {
            x,
            y: 36,
            value: 100.0,
        });
    }
    for y in 31..=35u32 {
        cells.push(roam_proto::map::CellWrite {
            x: 30,
            y,
            value: 100.0,
        });
        cells.push(roam_proto::map::CellWrite {
            x: 36,
            y,
            value: 100.0,
        });
    }
    // And a ring around cell (42, 42) at two cells: with the robot's inflation that
    // cell is left free with no legal move out of it.
    for k in 40..=44u32 {
        for (x, y) in [(k, 40), (k, 44), (40, k), (44, k)] {
            cells.push(roam_proto::map::CellWrite { x, y, value: 100.0 });
        }
    }
    let update = roam_proto::map::LayerUpdate {
        base_version: 1,
        change: roam_proto::map::LayerChange::SetCells { cells },
        world: None,
    };
    let _: roam_proto::map::UpdateAck = within(
        "wall",
        client.request(&keys::map_update(&root, "occupancy"), Some(&update)),
    )
    .await
    .expect("wall in");
    // Cell (33, 33) is the world point (-3.3, -3.3); wait until the planner has map v2.
    let walled = PlanRequest {
        goal: [-3.3, -3.3],
        map_version: Some(MapVersion {
            inflated: 2,
            information: 1,
            change: None,
            obstacles: None,
        }),
        ..ok.clone()
    };
    let no_path = loop {
        let reply = refusal(&client, &root, &walled).await;
        if reply.code != ErrorCode::NotFound || !reply.message.contains("unknown") {
            break reply;
        }
        tokio::time::sleep(Duration::from_millis(20)).await;
    };
    assert_eq!(no_path.code, ErrorCode::NotFound);
    assert!(no_path.message.contains("no path"), "{}", no_path.message);

    // A round trip from the enclosed cell (42, 42), the world point (-1.5, -1.5): no
    // loop fits, and the refusal names the start and t_exec_s.
    let enclosed = refusal(
        &client,
        &root,
        &PlanRequest {
            start: [-1.5, -1.5],
            goal: [-1.5, -1.5],
            ..walled.clone()
        },
    )
    .await;
    assert_eq!(enclosed.code, ErrorCode::InvalidRequest);
    for named in ["start (-1.5, -1.5)", "no legal move", "t_exec_s"] {
        assert!(enclosed.message.contains(named), "{}", enclosed.message);
    }
    running.stop().await;
}

/// A deadline bounds the work, so a request is not refused for work it
/// could only do after its deadline. Model I at Table I's population with 100,000
/// generations and an 80 s budget (paths of at most 201 cells) would cost 4.02e9, over
/// `max_plan_cost`; with a 2 s deadline only the generations that can start before it
/// count, and the plan comes back within the deadline, cut there with its best path.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_deadline_bounds_the_work_instead_of_refusing_it() {
    let running = boot(&[("solo", 2)]).await;
    let client = running.harness.client().await;
    let root = running.harness.root.clone();
    let curious = PlanRequest {
        deadline_s: 2.0,
        params: GaOverrides {
            max_generations: Some(100_000),
            ..GaOverrides::default()
        },
        ..request([-8.0, -8.0], [6.0, -7.0], 80.0, 100_000)
    };
    let started = Instant::now();
    let plan = ask(&client, &root, &curious)
        .await
        .expect("planned, not refused");
    let wall = started.elapsed();
    assert!(wall < Duration::from_secs_f64(2.5), "{wall:?}");
    assert!(plan.reaches_goal, "{plan:?}");
    assert!(plan.within_budget, "{plan:?}");
    // Cut at the deadline: the reply says so, and how many generations ran.
    assert_eq!(plan.stop_reason, StopReason::Deadline, "{plan:?}");
    assert!(
        (1..100_000).contains(&plan.generations),
        "{}",
        plan.generations
    );
    running.stop().await;
}
