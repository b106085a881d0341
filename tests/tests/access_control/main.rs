//! A secure site as `deploy/secure/make-secrets.sh` makes it: TLS, user/password
//! authentication, and access control by role and, for each robot's executive and
//! controller, by robot. One test attacks a real map server and sim with no credentials,
//! a wrong password, an authenticated user no rule names, and other roles' credentials;
//! `robots.rs` has robot r1's credentials try robot r2's keys and plans, `ros2.rs` the ROS
//! 2 node's credentials what its node does not use; another test runs every role's real
//! service through the router (the built-in world's robot with its own executive and
//! controller, and the ROS 2 node), to show the policy lets each do its whole job.
//!
//! The generator writes the CA, the certificates, the user dictionary, every user's
//! client config and the router's config (for the robots `robot`, `r1` and `r2`) into a
//! temporary directory, and the test uses those files, with only the endpoints (a free
//! port) overridden (`site.rs`). Each negative check is one that would fail with the
//! access control off (`access_control/enabled:false` on the router makes every one of
//! them fail): a command that would move the robot, a write that a subscriber would
//! receive, a map update, deletion or load the map server would accept, a plan query
//! the planner would answer, a cancel it would honour.

use std::time::Duration;

use roam_controller::service::ControllerConfig;
use roam_map_server::MapServerConfig;
use roam_mission::service::MissionConfig;
use roam_proto::cells::Cells;
use roam_proto::localization::{PebQuery, PebReply, PebWhere};
use roam_proto::map::{
    DeleteLayer, Layer, LayerChange, LayerDeleted, LayerList, LayerUpdate, LoadMap, UpdateAck,
};
use roam_proto::mapper::MapperStatus;
use roam_proto::mission::WindowReport;
use roam_proto::sim::RobotCommand;
use roam_proto::{decode, encode, keys, ErrorCode};
use roam_ros2::node::Ros2Config;
use roam_runtime::service_config::ServiceConfig;
use roam_runtime::{ClientError, Requester};
use roam_tests::{within, RunningService};

mod intrusion;
mod observe;
mod robots;
mod ros2;
mod site;

use intrusion::{
    assert_intrusion_has_no_effect, assert_intrusion_has_no_effect_on_robot,
    assert_only_the_right_credentials_open, Watch,
};
use observe::{alive_services, drain, put, step_and_locate, subscribe, versions};
use site::{secure_site, GUEST};

/// The key root `router.json5`'s rules are written for.
const ROOT: &str = "roam";
/// The built-in world's robot (its executive and controller log in as `mission-robot`
/// and `controller-robot`).
const ROBOT: &str = "robot";

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn only_the_controller_drives_and_only_map_writers_change_the_map() {
    let (secrets, harness) = secure_site().await;
    let endpoint = harness.router.endpoint.clone();

    // The real services, each as its own role.
    let map_server = harness.start_role(harness.map_server_config()).await;
    let sim = harness.start_role(harness.sim_config(None)).await;

    assert_only_the_right_credentials_open(&secrets, &endpoint).await;

    let watch = Watch::start(&harness).await;
    let planner = harness.client_as("planner").await;

    // Positive control: the robot's controller's command moves it in one step, and the
    // sim's rights receive it.
    let controller = harness.client_as("controller-robot").await;
    let at_start = step_and_locate(&watch.operator).await;
    drain(&watch.sim_spy);
    put(
        &controller,
        &keys::robot_command(ROOT, ROBOT),
        encode(&RobotCommand {
            u: [1.0, 1.0],
            step: None,
        }),
    )
    .await;
    let at_driven = step_and_locate(&watch.operator).await;
    let moved = (at_driven[0] - at_start[0]).hypot(at_driven[1] - at_start[1]);
    assert!(
        moved > 1e-3,
        "the controller's command must move the robot: {at_start:?} -> {at_driven:?}"
    );
    assert_eq!(
        drain(&watch.sim_spy),
        vec![keys::robot_command(ROOT, ROBOT)],
        "the sim's rights receive the controller's command"
    );

    // An authenticated user that no subject names (the ACL's default deny).
    let guest = harness.client_as(GUEST).await;
    assert_intrusion_has_no_effect("guest", &guest, &watch).await;

    // Another role's valid credentials: the planner may read maps, not write them, and
    // may not drive.
    let occupancy: Layer = within(
        "planner reads a layer",
        planner.request::<Layer, Layer>(&keys::map_layer(ROOT, "occupancy"), None),
    )
    .await
    .expect("the planner may read layers");
    assert_eq!(occupancy.name, "occupancy");
    assert_intrusion_has_no_effect("planner", &planner, &watch).await;
    // The operator may read everything but not command a robot either.
    assert_intrusion_has_no_effect_on_robot("operator", &watch).await;

    // A map writer: the mapper's update reaches the map server, which applies it (a new
    // change_rate layer, as the mapper sends) and publishes it, and the planner's rights
    // receive the real map server's publication. A write the server itself refuses
    // (`inflated` is derived) comes back as the server's structured error.
    let mapper = harness.client_as("mapper").await;
    let list: LayerList = within(
        "mapper lists layers",
        mapper.request::<LayerList, LayerList>(&keys::map_index(ROOT), None),
    )
    .await
    .expect("the mapper may list the layers");
    let meta = list
        .layers
        .iter()
        .find(|l| l.name == "occupancy")
        .map(|l| l.meta)
        .expect("an occupancy layer");
    drain(&watch.planner_spy);
    let base_version = list
        .layers
        .iter()
        .find(|l| l.name == "change_rate")
        .map_or(0, |l| l.version);
    let update = LayerUpdate {
        base_version,
        change: LayerChange::Replace {
            meta,
            cells: Cells::F32(vec![0.25; meta.cell_count() as usize]),
        },
        world: None,
    };
    let ack: UpdateAck = within(
        "mapper update",
        mapper.request(&keys::map_update(ROOT, "change_rate"), Some(&update)),
    )
    .await
    .expect("the mapper's update is applied");
    assert_eq!(ack.layer, "change_rate");
    assert_eq!(ack.version, base_version + 1);
    assert_eq!(
        versions(&watch.operator).await.get("change_rate"),
        Some(&ack.version)
    );
    let published = within("layer publication", watch.planner_spy.recv_async())
        .await
        .expect("a layer publication");
    assert_eq!(
        published.key_expr().as_str(),
        keys::map_layer(ROOT, "change_rate"),
        "the planner's rights receive the map server's own layers"
    );
    let refused = within(
        "mapper writes a derived layer",
        mapper.request::<LayerUpdate, UpdateAck>(
            &keys::map_update(ROOT, "inflated"),
            Some(&LayerUpdate {
                base_version: 0,
                change: LayerChange::Replace {
                    meta,
                    cells: Cells::I8(vec![0; meta.cell_count() as usize]),
                },
                world: None,
            }),
        ),
    )
    .await;
    match refused {
        Err(ClientError::Refused(reply)) => assert_ne!(
            reply.code,
            ErrorCode::Internal,
            "a structured refusal from the map server: {reply:?}"
        ),
        other => panic!("the map server answers the mapper with an error reply, got {other:?}"),
    }
    // ... and a map writer may delete a layer it may update.
    let deleted: LayerDeleted = within(
        "mapper deletes a layer",
        mapper.request(
            &keys::map_delete(ROOT, "change_rate"),
            Some(&DeleteLayer {
                base_version: ack.version,
            }),
        ),
    )
    .await
    .expect("the mapper's deletion is applied");
    assert_eq!(deleted.version, ack.version);
    assert!(
        !versions(&watch.operator).await.contains_key("change_rate"),
        "the deleted layer is no longer listed"
    );

    stop(sim).await;
    stop(map_server).await;
    harness.close().await;
}

/// Waits (at most 30 s) until `client`, a session just opened, has an answer from the
/// map server's index: on a loaded machine a new session's first query can end without
/// a reply before its routes are in place, which says nothing about the rule under test.
async fn answered_by_the_map_server(client: &Requester) {
    let started = std::time::Instant::now();
    loop {
        match client
            .request::<LayerList, LayerList>(&keys::map_index(ROOT), None)
            .await
        {
            Err(ClientError::NoReply { .. }) if started.elapsed().as_secs() < 30 => {
                tokio::time::sleep(std::time::Duration::from_millis(200)).await;
            }
            _ => return,
        }
    }
}

async fn stop(service: RunningService) {
    service.stop().await.1.expect("the service stops cleanly");
}

/// The escalation an attack run found: the operator, who may load maps, asked the map
/// server to load the router's user dictionary and got every role's password back in
/// the parse error. Loads now read only inside the map server's load directories: the
/// dictionary is refused like a missing file, no password is in any reply, and a map
/// in the directory still loads.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_map_writer_cannot_read_the_routers_secrets_through_a_load() {
    let (secrets, harness) = secure_site().await;
    let map_server = harness
        .start_role(MapServerConfig {
            load_dirs: vec![roam_tests::repo_path("config/maps")],
            ..harness.map_server_config()
        })
        .await;
    let operator = harness.client_as("operator").await;
    answered_by_the_map_server(&operator).await;
    let users = secrets.users.display().to_string();
    let relative = format!("../../../../../../../../..{users}");
    for requested in [users.as_str(), relative.as_str(), "/etc/passwd"] {
        let outcome = within(
            "operator load",
            operator.request::<LoadMap, LayerList>(
                &keys::map_load(ROOT),
                Some(&LoadMap {
                    path: requested.to_owned(),
                    base_version: None,
                }),
            ),
        )
        .await;
        let Err(ClientError::Refused(reply)) = outcome else {
            panic!("loading {requested}: expected a refusal, got {outcome:?}");
        };
        assert_eq!(
            reply.code,
            ErrorCode::NotFound,
            "{requested}: {}",
            reply.message
        );
        for password in secrets.passwords.values() {
            assert!(
                !reply.message.contains(password.as_str()),
                "a password came back: {}",
                reply.message
            );
        }
    }
    let list: LayerList = within(
        "operator loads a shipped map",
        operator.request(
            &keys::map_load(ROOT),
            Some(&LoadMap {
                path: "depot.yaml".into(),
                base_version: None,
            }),
        ),
    )
    .await
    .expect("a map in the load directory loads");
    assert!(list.layers.iter().any(|l| l.name == "occupancy"));
    stop(map_server).await;
    harness.close().await;
}

/// The policy is complete: every role, run as itself, does its whole job through the
/// secure router. The robot's executive (`mission-robot`) finds the planner by
/// liveliness, gets maps and a curious plan on the robot's plan keys, gives the robot's
/// controller (`controller-robot`) its waypoints, the controller drives the sim on
/// localization's estimates, and the first window's report reaches the operator; the
/// mapper's and localization's layers reach the map server; the operator can ask the
/// localization and the mapper and see every service's liveliness token; a ROS 2 node
/// sees the ROS 2 node's graph token and the robot's pose, and gets a plan through its
/// service.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn every_role_does_its_job_through_the_secure_router() {
    let (_secrets, harness) = secure_site().await;
    let mut services = vec![
        harness.start_role(harness.map_server_config()).await,
        harness
            .start_role(harness.planner_config("planner-0"))
            .await,
    ];
    let mut sim_config = harness.sim_config(None);
    sim_config.rate = Some(10.0);
    services.push(harness.start_role(sim_config).await);
    services.push(harness.start_role(harness.localization_config(None)).await);
    services.push(
        harness
            .start_role_as(
                "controller-robot",
                ControllerConfig {
                    apf: roam::demo::indoor_apf(),
                    robots: vec![ROBOT.to_owned()],
                    ..harness.controller_config()
                },
            )
            .await,
    );
    services.push(harness.start_role(harness.mapper_config()).await);
    services.push(
        harness
            .start_role(Ros2Config {
                service: ServiceConfig::at(ROOT),
                ..Ros2Config::default()
            })
            .await,
    );

    let operator = harness.client_as("operator").await;
    let reports = subscribe(&operator, &keys::robot_mission_report(ROOT, ROBOT)).await;
    let plans = subscribe(&operator, &keys::planner_robot_progress(ROOT, ROBOT, "*")).await;
    services.push(
        harness
            .start_role_as(
                "mission-robot",
                MissionConfig {
                    service: ServiceConfig::at(ROOT),
                    ..MissionConfig::default()
                },
            )
            .await,
    );

    // The first downtime window: 75 s of sim time at 10x, plus planning.
    let sample = tokio::time::timeout(Duration::from_secs(40), reports.recv_async())
        .await
        .expect("the first window's report within 40 s")
        .expect("sample");
    let report: WindowReport = decode(&sample.payload().to_bytes()).expect("a window report");
    assert_eq!(report.task, "goal1", "{report:?}");
    assert!(
        report.driven_information > 0.0,
        "the robot drove and saw: {report:?}"
    );
    assert!(
        !drain(&plans).is_empty(),
        "the planner planned the robot's window on the robot's plan keys"
    );

    // The map writers' layers are on the map server.
    let deadline = tokio::time::Instant::now() + Duration::from_secs(10);
    loop {
        let held = versions(&operator).await;
        if held.contains_key("peb") && held.contains_key("change_rate") {
            break;
        }
        assert!(
            tokio::time::Instant::now() < deadline,
            "localization's and the mapper's layers reach the map server: {held:?}"
        );
        tokio::time::sleep(Duration::from_millis(200)).await;
    }

    // The operator asks the other services and sees every service alive.
    let status: MapperStatus = within(
        "mapper status",
        operator.request::<MapperStatus, MapperStatus>(&keys::mapper_status(ROOT), None),
    )
    .await
    .expect("the operator may ask the mapper");
    assert!(status.observations > 0, "{status:?}");
    let peb: PebReply = within(
        "peb query",
        operator.request(
            &keys::localization_peb(ROOT),
            Some(&PebQuery {
                at: PebWhere::Points(vec![[0.0, 0.0]]),
                anchors: None,
                gradient: false,
                crb: false,
            }),
        ),
    )
    .await
    .expect("the operator may ask for the PEB");
    assert!(
        matches!(peb, PebReply::Points(ref at) if at.len() == 1),
        "{peb:?}"
    );
    // A token reaches a liveliness query through the router some time after it is
    // declared (seconds on a loaded machine): asked again until all are there.
    let deadline = tokio::time::Instant::now() + Duration::from_secs(15);
    let mut alive = alive_services(&operator).await;
    while alive.len() < 8 && tokio::time::Instant::now() < deadline {
        tokio::time::sleep(Duration::from_millis(500)).await;
        alive = alive_services(&operator).await;
    }
    assert_eq!(
        alive,
        [
            "controller",
            "localization",
            "map-server",
            "mapper",
            "mission",
            "planner",
            "ros2",
            "sim"
        ],
        "the operator sees every service's liveliness token"
    );
    ros2::assert_the_node_serves_ros_2(&harness.client_as("ros-node").await).await;

    for service in services.into_iter().rev() {
        stop(service).await;
    }
    harness.close().await;
}
