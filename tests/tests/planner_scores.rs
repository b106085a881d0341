//! Information scores above paper 000's 0..=100 through Zenoh: a planner pointed at a
//! u8 layer with scores up to 255 plans (no panic in Model I's 101-slot tables, Eq. 9)
//! and plans exactly as on the same layer clamped to 100, the rule
//! `roam_planner::world::MAX_INFORMATION_SCORE` documents.

use roam_proto::cells::Cells;
use roam_proto::keys;
use roam_proto::map::{Layer, LayerChange, LayerUpdate, UpdateAck};
use roam_proto::planner::{GaOverrides, Plan, PlanRequest, PlannerModel, ShortestPathUse};
use roam_tests::{within, Harness};

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn scores_above_100_plan_as_if_clamped_to_100() {
    let harness = Harness::start().await;
    let _server = harness.start_role(harness.map_server_config()).await;
    let client = harness.client().await;
    let root = harness.root.as_str();
    let information: Layer = within(
        "information layer",
        client.request::<Layer, Layer>(&keys::map_layer(root, "information"), None),
    )
    .await
    .expect("information layer");
    let Cells::U8(scores) = &information.cells else {
        panic!("information is not u8");
    };
    // Every score times five, up to 255: the zones of interest above 100, the rest
    // still graded below it.
    let bright: Vec<u8> = scores
        .iter()
        .map(|&s| (u16::from(s) * 5).min(255) as u8)
        .collect();
    let above = bright.iter().filter(|&&s| s > 100).count();
    assert!(above > 100, "{above} cells above 100");
    let clamped: Vec<u8> = bright.iter().map(|&s| s.min(100)).collect();
    for (name, cells) in [("bright", bright), ("bright_clamped", clamped)] {
        let update = LayerUpdate {
            base_version: 0,
            change: LayerChange::Replace {
                meta: information.meta,
                cells: Cells::U8(cells),
            },
            world: None,
        };
        let _: UpdateAck = within(
            "layer",
            client.request(&keys::map_update(root, name), Some(&update)),
        )
        .await
        .expect("layer accepted");
    }
    let mut services = Vec::new();
    for name in ["bright", "bright_clamped"] {
        let mut config = harness.planner_config(name);
        config.information_layer = name.into();
        services.push(harness.start_role(config).await);
    }
    let request = PlanRequest {
        request_id: None,
        cancel_token: None,
        start: [-8.0, -8.0],
        goal: [-2.0, 4.0],
        t_exec_s: 60.0,
        deadline_s: 30.0,
        model: PlannerModel::Model1,
        params: GaOverrides {
            max_generations: Some(150),
            population: Some(60),
            ..GaOverrides::default()
        },
        seed: 5,
        map_version: None,
        shortest: ShortestPathUse::Omit,
        seed_route: Vec::new(),
    };
    let mut plans = Vec::new();
    for name in ["bright", "bright_clamped"] {
        let plan: Plan = within(
            "plan",
            client.request(&keys::planner_plan_at(root, name), Some(&request)),
        )
        .await
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        plans.push(plan);
    }
    let (bright, clamped) = (&plans[0], &plans[1]);
    assert!(bright.u_ges > 0.0, "{bright:?}");
    assert_eq!(bright.cells, clamped.cells);
    assert_eq!(bright.u_ges.to_bits(), clamped.u_ges.to_bits());
    assert_eq!(
        bright.distinct_information.to_bits(),
        clamped.distinct_information.to_bits()
    );
    assert_eq!(
        serde_json::to_value(bright.fitness).expect("fitness"),
        serde_json::to_value(clamped.fitness).expect("fitness")
    );
}
