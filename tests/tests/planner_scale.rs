//! Issue 16 through Zenoh: planning at 0.2 m on a 5 cm map (the depot scenario) gives
//! the in-process answer bit for bit and a path driven on the map's cells; the queue
//! answers a burst in order within deadlines, refuses at once what cannot make its
//! deadline, and lets a cancel reach a queued request; bad settings are refused
//! naming the limit. Real map server and planners in process, used only as a client.

use std::sync::atomic::AtomicBool;

use roam_map_server::layers::inflate;
use roam_map_server::store::DEFAULT_LIMITS;
use roam_planner::params::GaParams;
use roam_planner::plan::{plan, PlanSpec};
use roam_planner::world::World;
use roam_planner::PlannerConfig;
use roam_proto::keys;
use roam_proto::planner::{GaOverrides, Plan, PlanRequest, PlannerModel};
use roam_runtime::{ClientError, Requester};
use roam_tests::{repo_path, within, Harness, RunningService};

const DEPOT: &str = "config/scenarios/depot.yaml";

fn request(start: [f64; 2], goal: [f64; 2], t_exec_s: f64, generations: u32) -> PlanRequest {
    PlanRequest {
        request_id: None,
        cancel_token: None,
        start,
        goal,
        t_exec_s,
        deadline_s: 60.0,
        model: PlannerModel::Model1,
        params: GaOverrides {
            max_generations: Some(generations),
            population: Some(60),
            ..GaOverrides::default()
        },
        seed: 23,
        map_version: None,
    }
}

struct Running {
    harness: Harness,
    map_server: RunningService,
    planners: Vec<RunningService>,
}

/// A map server on `map` (the built-in world when `None`) and one planner per config.
async fn boot(map: Option<&str>, planners: Vec<PlannerConfig>) -> Running {
    let harness = Harness::start().await;
    let map_server = harness
        .start_map_server(roam_map_server::MapServerConfig {
            map: map.map(repo_path),
            ..harness.map_server_config()
        })
        .await;
    let mut started = Vec::new();
    for config in planners {
        let config = PlannerConfig {
            root: harness.root.clone(),
            ..config
        };
        started.push(harness.start_planner(config).await);
    }
    Running {
        harness,
        map_server,
        planners: started,
    }
}

impl Running {
    async fn stop(self) {
        for planner in self.planners {
            planner.stop().await.1.expect("planner stops cleanly");
        }
        self.map_server.stop().await.1.expect("map server stops");
        self.harness.close().await;
    }
}

fn planner(name: &str) -> PlannerConfig {
    PlannerConfig {
        instance: Some(name.to_owned()),
        ..PlannerConfig::default()
    }
}

async fn ask(client: &Requester, root: &str, request: &PlanRequest) -> Result<Plan, ClientError> {
    within(
        "plan",
        client.request(&keys::planner_plan(root), Some(request)),
    )
    .await
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
        roam_map_server::scenario::load(&repo_path(DEPOT), DEFAULT_LIMITS.max_layer_cells)
            .expect("scenario");
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
