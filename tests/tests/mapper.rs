//! The change-rate mapper through Zenoh: the sim's grid world (paper 004) → mapper (its
//! learner driving the robot) → map server; the change-probability and rate layers are
//! fetched with a `get` and their hot cells are where the blocks move.

use std::time::{Duration, Instant};

use roam_mapper::service::MapperConfig;
use roam_proto::cells::Cells;
use roam_proto::map::Layer;
use roam_proto::mapper::{
    ExplorationGoal, MapperStatus, CHANGE_INFORMATION_LAYER, CHANGE_PROBABILITY_LAYER,
    CHANGE_RATE_LAYER, RECENCY_LAYER,
};
use roam_proto::planner::{GaOverrides, Plan, PlanRequest, PlannerModel, ShortestPathUse};
use roam_proto::sim::{RobotCommand, SimControl, SimStatus};
use roam_proto::{decode, keys};
use roam_tests::{repo_path, within, Harness};

const GRID004: &str = "config/scenarios/grid004.yaml";

fn f32_cells(layer: &Layer) -> &[f32] {
    match &layer.cells {
        Cells::F32(c) => c,
        other => panic!("expected f32 cells, got {other:?}"),
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn sim_to_mapper_to_map_server_shows_where_the_blocks_move() {
    let harness = Harness::start().await;
    let mut map_config = harness.map_server_config();
    map_config.map = Some(repo_path(GRID004));
    let _map_server = harness.start_role(map_config).await;
    let _sim = harness.start_role(harness.sim_config(Some(GRID004))).await;
    let _mapper = harness
        .start_role(MapperConfig {
            scenario: Some(repo_path(GRID004)),
            explore: vec!["robot".into()],
            publish_period_s: 0.2,
            seed: 3,
            ..harness.mapper_config()
        })
        .await;
    let client = harness.client().await;
    let root = harness.root.clone();
    let commands = within(
        "subscribe",
        client
            .session()
            .declare_subscriber(keys::robot_command(&root, "robot")),
    )
    .await
    .expect("subscriber");
    let goals = within(
        "subscribe",
        client
            .session()
            .declare_subscriber(keys::robot_goal(&root, "robot")),
    )
    .await
    .expect("subscriber");

    // Lock-step: each step's observation goes to the mapper, whose learner answers with
    // the robot's next move before the next step.
    let steps = 1500u64;
    for step in 1..=steps {
        let _: SimStatus = within(
            "step",
            client.request(&keys::sim_control(&root), Some(&SimControl::Step { n: 1 })),
        )
        .await
        .expect("step");
        loop {
            let sample = within("a command", commands.recv_async())
                .await
                .expect("sample");
            let command: RobotCommand = decode(&sample.payload().to_bytes()).expect("command");
            if command.step == Some(step) {
                break;
            }
        }
    }
    let status: MapperStatus = within(
        "status",
        client.request::<MapperStatus, MapperStatus>(&keys::mapper_status(&root), None),
    )
    .await
    .expect("status");
    assert_eq!(status.observations, steps);
    assert!(status.map_changes > 0);
    assert_eq!(status.explorers.len(), 1);
    assert!(
        status.explorers[0].episodes > 5,
        "episodes of at most 42 steps: {status:?}"
    );
    let goal_sample = goals
        .try_recv()
        .expect("recv")
        .expect("a goal was published");
    let goal: ExplorationGoal = decode(&goal_sample.payload().to_bytes()).expect("goal");
    assert!(goal.strategy == "recency" || goal.strategy == "poisson");

    // The layers arrive within a few publish periods after the last observation.
    let until = Instant::now() + Duration::from_secs(10);
    let (rate, probability) = loop {
        let rate = fetch(&client, &root, CHANGE_RATE_LAYER).await;
        let probability = fetch(&client, &root, CHANGE_PROBABILITY_LAYER).await;
        let recency = fetch(&client, &root, RECENCY_LAYER).await;
        if let (Some(rate), Some(probability), Some(_)) = (rate, probability, recency) {
            break (rate, probability);
        }
        assert!(
            Instant::now() < until,
            "the mapper's layers never reached the map server"
        );
        tokio::time::sleep(Duration::from_millis(100)).await;
    };

    let scenario = roam_experiments::reproduce::mapper::experiment::grid004().expect("grid004");
    let truth =
        roam_experiments::reproduce::mapper::truth::true_rates(&scenario, 1.0).expect("true rates");
    let changing: std::collections::BTreeSet<usize> = truth.changing.iter().copied().collect();
    let rates = f32_cells(&rate);
    let learned: Vec<usize> = (0..rates.len()).filter(|&i| rates[i] > 0.0).collect();
    assert!(
        learned.len() >= 8,
        "only {} cells with a learned rate",
        learned.len()
    );
    for i in &learned {
        assert!(
            changing.contains(i),
            "cell {i} has a rate but no block ever moves there"
        );
    }
    // The hot cells of P(E > 0) are where the blocks move: every cell above 0.5 changes
    // in truth, and there are some.
    let p = f32_cells(&probability);
    let hot: Vec<usize> = (0..p.len()).filter(|&i| p[i] > 0.5).collect();
    assert!(
        !hot.is_empty(),
        "no hot cell in the change-probability layer"
    );
    for i in &hot {
        assert!(changing.contains(i), "hot cell {i} never changes in truth");
    }

    // The papers joined: a planner told to take the mapper's change_information layer
    // (100 · P(E > 0) as u8 scores) as its information map plans on it.
    // Both layers are sent in the same round, so equal versions are the same instant.
    let until = Instant::now() + Duration::from_secs(10);
    let (scores, probability) = loop {
        let scores = fetch(&client, &root, CHANGE_INFORMATION_LAYER).await;
        let probability = fetch(&client, &root, CHANGE_PROBABILITY_LAYER).await;
        if let (Some(s), Some(p)) = (scores, probability) {
            if s.version == p.version {
                break (s, p);
            }
        }
        assert!(Instant::now() < until, "no matching change layers");
        tokio::time::sleep(Duration::from_millis(50)).await;
    };
    let Cells::U8(s) = &scores.cells else {
        panic!("change_information is not u8");
    };
    for (i, (&score, &p)) in s.iter().zip(f32_cells(&probability)).enumerate() {
        assert!(
            (f32::from(score) - (p * 100.0).round()).abs() <= 1.0,
            "cell {i}: score {score} for P {p}"
        );
    }
    let mut planner_config = harness.planner_config("curious-about-change");
    planner_config.information_layer = CHANGE_INFORMATION_LAYER.into();
    let _planner = harness.start_role(planner_config).await;
    // The change coupling: a planner on max(information, change_information).
    let mut coupled_config = harness.planner_config("coupled");
    coupled_config.change_layer = Some(CHANGE_INFORMATION_LAYER.into());
    let _coupled = harness.start_role(coupled_config).await;
    let plan_request = PlanRequest {
        request_id: None,
        cancel_token: None,
        start: [0.5, 0.5],
        goal: [0.5, -6.5],
        t_exec_s: 60.0,
        deadline_s: 2.0,
        model: PlannerModel::Model1,
        params: GaOverrides {
            max_generations: Some(200),
            ..GaOverrides::default()
        },
        seed: 1,
        map_version: None,
        shortest: ShortestPathUse::Omit,
        seed_route: Vec::new(),
    };
    let request = |instance: &'static str| {
        let (client, key, body) = (
            client.clone(),
            keys::planner_plan_at(&root, instance),
            plan_request.clone(),
        );
        async move { client.request::<PlanRequest, Plan>(&key, Some(&body)).await }
    };
    let plan: Plan = within("plan", request("curious-about-change"))
        .await
        .expect("plan");
    assert!(plan.reaches_goal);
    let coupled: Plan = within("coupled plan", request("coupled"))
        .await
        .expect("coupled plan");
    assert!(coupled.reaches_goal);
    assert!(
        coupled
            .map_version
            .change
            .is_some_and(|v| v >= scores.version),
        "the coupled plan names change version {:?} (change_information is at {})",
        coupled.map_version.change,
        scores.version
    );
    assert_eq!(coupled.map_version.information, 1, "the static map stays");
    assert!(
        plan.map_version.information >= scores.version,
        "planned on information version {} (change_information is at {})",
        plan.map_version.information,
        scores.version
    );
}

async fn fetch(client: &roam_runtime::Requester, root: &str, name: &str) -> Option<Layer> {
    client
        .request::<Layer, Layer>(&keys::map_layer(root, name), None)
        .await
        .ok()
}

/// Asks the mapper how many observations it has merged.
async fn observations(client: &roam_runtime::Requester, root: &str) -> u64 {
    let status: MapperStatus = within(
        "mapper status",
        client.request::<MapperStatus, MapperStatus>(&keys::mapper_status(root), None),
    )
    .await
    .expect("status");
    status.observations
}

/// Steps the sim and waits until the mapper has merged more than `than` observations.
async fn step_until_merged(client: &roam_runtime::Requester, root: &str, than: u64) -> u64 {
    let until = Instant::now() + Duration::from_secs(10);
    loop {
        let _: SimStatus = within(
            "step",
            client.request(&keys::sim_control(root), Some(&SimControl::Step { n: 1 })),
        )
        .await
        .expect("step");
        let merged = observations(client, root).await;
        if merged > than {
            return merged;
        }
        assert!(
            Instant::now() < until,
            "the mapper stopped merging observations ({merged})"
        );
    }
}

/// One forged observation stamped far in the future once stopped the mapper for good
/// (every later one was "time going back"), and a sim reset stalled it until sim time
/// passed the old maximum. Observation times are now checked against the sim clock, and
/// a reset starts a new epoch: the mapper goes on merging after both.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_forged_time_and_a_sim_reset_do_not_stop_the_mapper() {
    let harness = Harness::start().await;
    let _sim = harness.start_role(harness.sim_config(Some(GRID004))).await;
    let _mapper = harness
        .start_role(MapperConfig {
            scenario: Some(repo_path(GRID004)),
            ..harness.mapper_config()
        })
        .await;
    let client = harness.client().await;
    let root = harness.root.clone();
    let observations_key = keys::robot_observation(&root, "robot");
    let seen = within(
        "subscribe",
        client.session().declare_subscriber(&observations_key),
    )
    .await
    .expect("subscriber");
    let merged = step_until_merged(&client, &root, 0).await;

    // A real observation, restamped 1e300 s, put on the robot's key.
    let sample = within("an observation", seen.recv_async())
        .await
        .expect("sample");
    let mut forged: roam_proto::sim::LocalObservation =
        decode(&sample.payload().to_bytes()).expect("observation");
    forged.time_s = 1e300;
    within(
        "put",
        client
            .session()
            .put(&observations_key, roam_proto::encode(&forged)),
    )
    .await
    .expect("put");
    let merged = step_until_merged(&client, &root, merged).await;

    // A reset: the sim's clock goes back to 0 and the mapper goes on.
    let _: SimStatus = within(
        "reset",
        client.request(
            &keys::sim_control(&root),
            Some(&SimControl::Reset { seed: 2 }),
        ),
    )
    .await
    .expect("reset");
    // The first step after the reset may be refused (its observation comes before its
    // clock); the ones after it are merged.
    let _ = step_until_merged(&client, &root, merged + 1).await;
}

/// Waits until the mapper's status satisfies `done`.
async fn status_until(
    client: &roam_runtime::Requester,
    root: &str,
    what: &str,
    done: impl Fn(&MapperStatus) -> bool,
) -> MapperStatus {
    let until = Instant::now() + Duration::from_secs(10);
    loop {
        let status: MapperStatus = within(
            "mapper status",
            client.request::<MapperStatus, MapperStatus>(&keys::mapper_status(root), None),
        )
        .await
        .expect("status");
        if done(&status) {
            return status;
        }
        assert!(Instant::now() < until, "{what}: {status:?}");
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
}

/// Fetches layer `name` until `done` holds for it.
async fn layer_until(
    client: &roam_runtime::Requester,
    root: &str,
    name: &str,
    done: impl Fn(&Layer) -> bool,
) -> Layer {
    let until = Instant::now() + Duration::from_secs(10);
    loop {
        if let Some(layer) = fetch(client, root, name).await {
            if done(&layer) {
                return layer;
            }
        }
        assert!(
            Instant::now() < until,
            "the {name} layer never came as expected"
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

/// The news value and the map now through Zenoh (no sim: observations and a mission put
/// by hand on grid004's 25 × 25 cells of 1 m). Robot a watches a 5 × 5 window for three
/// seconds and sees a cell blocked at the third; robot b is given a mission along row 20,
/// where no robot has looked. The `news` layer is 100 where no robot looked, 0 along b's
/// mission (b will see it), and 100 there again once b's mission is cleared; the
/// `occupied_now` layer has a's blocked cell occupied from the observation that saw it,
/// and the static map's value where no robot looked; a planner on the news product
/// (`coupling: news`) plans on the `news` layer.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn the_news_and_the_map_now_reach_the_map_server() {
    use roam_mapper::news::NewsParams;
    use roam_mapper::prior::RatePrior;
    use roam_mapper::reserve::ReserveParams;
    use roam_proto::controller::Mission;
    use roam_proto::map::{GridMeta, Origin};
    use roam_proto::mapper::{NEWS_LAYER, OCCUPIED_NOW_LAYER};
    use roam_proto::sim::LocalObservation;

    let harness = Harness::start().await;
    let mut map_config = harness.map_server_config();
    map_config.map = Some(repo_path(GRID004));
    let _map_server = harness.start_role(map_config).await;
    let _mapper = harness
        .start_role(MapperConfig {
            scenario: Some(repo_path(GRID004)),
            publish_period_s: 0.1,
            news: NewsParams {
                prior: RatePrior {
                    alpha: 1.0,
                    beta_s: 10.0,
                },
                reserve: ReserveParams {
                    s_per_m: 2.0,
                    radius_m: Some(0.0),
                },
            },
            ..harness.mapper_config()
        })
        .await;
    let client = harness.client().await;
    let root = harness.root.clone();
    let cell = |x: usize, y: usize| y * 25 + x;

    // Robot a: cells (2..=6, 2..=6) free at t = 1 and 2; at t = 3 cell (4, 4) blocked.
    for t in 1..=3u64 {
        let mut cells = vec![0i8; 25];
        if t == 3 {
            cells[2 * 5 + 2] = 100;
        }
        let observation = LocalObservation {
            robot: "a".into(),
            step: t,
            time_s: t as f64,
            at: [-8.0, -8.0],
            x0: 2,
            y0: 2,
            meta: GridMeta {
                width: 5,
                height: 5,
                resolution: 1.0,
                origin: Origin::default(),
            },
            cells: Cells::I8(cells),
        };
        within(
            "put an observation",
            client.session().put(
                keys::robot_observation(&root, "a"),
                roam_proto::encode(&observation),
            ),
        )
        .await
        .expect("put");
        status_until(&client, &root, "the observation merged", |s| {
            s.observations == t
        })
        .await;
    }

    // Robot b's mission along row 20, cells 5 to 15 (world y = 8).
    let put_mission = |waypoints: Vec<[f64; 2]>| {
        let mission = Mission {
            after_step: None,
            robot: "b".into(),
            id: "b-1".into(),
            waypoints,
            recovery: false,
        };
        let (session, key) = (client.session().clone(), keys::robot_mission(&root, "b"));
        async move {
            within(
                "put a mission",
                session.put(key, roam_proto::encode(&mission)),
            )
            .await
            .expect("put");
        }
    };
    put_mission(vec![[-7.0, 8.0], [3.0, 8.0]]).await;
    let status = status_until(&client, &root, "b's reservation", |s| {
        !s.reservations.is_empty()
    })
    .await;
    assert_eq!(status.reservations.len(), 1);
    assert_eq!(status.reservations[0].robot, "b");
    assert_eq!(status.reservations[0].cells, 11, "row 20, cells 5 to 15");

    let u8_cells = |layer: &Layer| match &layer.cells {
        Cells::U8(c) => c.clone(),
        other => panic!("news is not u8: {other:?}"),
    };
    let row_reserved = |news: &[u8]| (5..=15).all(|x| news[cell(x, 20)] == 0);
    let news = layer_until(&client, &root, NEWS_LAYER, |l| row_reserved(&u8_cells(l))).await;
    let news = u8_cells(&news);
    // Where no robot looked nor will: news for certain; beside b's row too.
    assert_eq!(news[cell(12, 12)], 100);
    assert_eq!(news[cell(4, 20)], 100);
    assert_eq!(news[cell(10, 21)], 100);
    // a's window was seen at t = 3, the newest observation: no news yet.
    assert_eq!(news[cell(3, 3)], 0);

    let occupied = layer_until(&client, &root, OCCUPIED_NOW_LAYER, |_| true).await;
    let Cells::I8(occupied) = &occupied.cells else {
        panic!("occupied_now is not i8");
    };
    assert_eq!(
        occupied[cell(4, 4)],
        100,
        "blocked from the observation that saw it"
    );
    assert_eq!(occupied[cell(3, 3)], 0);
    // Never seen: the static map's value (grid004's border wall, its free interior).
    assert_eq!(occupied[cell(0, 0)], 100);
    assert_eq!(occupied[cell(12, 12)], 0);
    assert!(occupied.iter().all(|&v| (0..=100).contains(&v)));

    // A planner on the news product plans on this layer.
    let mut planner_config = harness.planner_config("news-coupled");
    planner_config.change_layer = Some(NEWS_LAYER.into());
    planner_config.coupling = roam_planner::coupling::Coupling::News;
    let _planner = harness.start_role(planner_config).await;
    let request = PlanRequest {
        request_id: None,
        cancel_token: None,
        start: [0.5, 0.5],
        goal: [0.5, -6.5],
        t_exec_s: 60.0,
        deadline_s: 2.0,
        model: PlannerModel::Model1,
        params: GaOverrides {
            max_generations: Some(50),
            ..GaOverrides::default()
        },
        seed: 1,
        map_version: None,
        shortest: ShortestPathUse::Omit,
        seed_route: Vec::new(),
    };
    let until = Instant::now() + Duration::from_secs(10);
    let plan = loop {
        let plan: Result<Plan, _> = within(
            "a plan on the news product",
            client.request::<PlanRequest, Plan>(
                &keys::planner_plan_at(&root, "news-coupled"),
                Some(&request),
            ),
        )
        .await;
        match plan {
            Ok(plan) if plan.map_version.change.is_some() => break plan,
            other => assert!(
                Instant::now() < until,
                "no plan on the news layer: {other:?}"
            ),
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    };
    assert!(plan.reaches_goal);

    // An empty mission clears b's reservation: its row is news again.
    put_mission(Vec::new()).await;
    status_until(&client, &root, "b's reservation released", |s| {
        s.reservations.is_empty()
    })
    .await;
    layer_until(&client, &root, NEWS_LAYER, |l| {
        (5..=15).all(|x| u8_cells(l)[cell(x, 20)] == 100)
    })
    .await;
}
