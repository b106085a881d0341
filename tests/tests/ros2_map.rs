//! `--ros2-map`: the map server takes its occupancy from a ROS 2 publisher of
//! nav_msgs/msg/OccupancyGrid, through Zenoh only. A fake ROS 2 publisher puts maps on
//! the exact rmw_zenoh key with the attachment; a good map becomes a new occupancy
//! version cell for cell; a 10⁹-cell map, a truncated payload, a sample without the
//! attachment and a map of another type hash are refused with a logged line (the first
//! naming `max_layer_cells`) and change nothing; a good map after them is still taken.

use std::io::Write;
use std::sync::{Arc, Mutex, OnceLock};
use std::time::Duration;

use roam_proto::cells::Cells;
use roam_proto::keys;
use roam_proto::map::{Layer, LayerList};
use roam_ros2::attachment::Attachment;
use roam_ros2::msg::{MapMetaData, OccupancyGrid, Pose};
use roam_ros2::node::Ros2Config;
use roam_ros2::{cdr, hash, names, types};
use roam_runtime::service_config::ServiceConfig;
use roam_tests::{within, Harness};

#[derive(Clone, Default)]
struct Capture(Arc<Mutex<Vec<u8>>>);

impl Write for Capture {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.lock().expect("log").extend_from_slice(buf);
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

impl Capture {
    fn text(&self) -> String {
        String::from_utf8_lossy(&self.0.lock().expect("log")).into_owned()
    }
}

/// The log of this test binary, captured: its global subscriber is installed once, by
/// whichever test comes first, before any harness installs its own (which then finds
/// one set and leaves it). Every test here calls it first, so the capture never loses
/// the race for the global default to the harness of a test running beside it.
fn captured_log() -> Capture {
    static LOG: OnceLock<Capture> = OnceLock::new();
    LOG.get_or_init(|| {
        let log = Capture::default();
        let writer = log.clone();
        tracing_subscriber::fmt()
            .with_writer(move || writer.clone())
            .with_ansi(false)
            .init();
        log
    })
    .clone()
}

fn grid(width: u32, height: u32, data: Vec<i8>) -> OccupancyGrid {
    let mut grid = OccupancyGrid {
        info: MapMetaData {
            resolution: 0.5,
            width,
            height,
            origin: Pose::default(),
            ..MapMetaData::default()
        },
        data,
        ..OccupancyGrid::default()
    };
    grid.header.frame_id = "map".into();
    grid.info.origin.position.x = -1.0;
    grid
}

async fn occupancy_version(client: &roam_runtime::Requester, root: &str) -> u64 {
    let list: LayerList = client
        .request::<LayerList, LayerList>(&keys::map_index(root), None)
        .await
        .expect("layers");
    list.layers
        .iter()
        .find(|l| l.name == "occupancy")
        .map_or(0, |l| l.version)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_ros2_map_becomes_occupancy_and_bad_maps_are_refused() {
    let log = captured_log();
    let h = Harness::start().await;
    let _map_server = h.start_role(h.map_server_config()).await;
    let config = Ros2Config {
        service: ServiceConfig::at(h.root.clone()),
        map_input: Some("/map".into()),
        ..Ros2Config::default()
    };
    let _ros2 = h.start_role(config).await;
    let client = h.client().await;
    let session = client.session().clone();
    let v0 = occupancy_version(&client, &h.root).await;

    let hash = hash::message_type_hash(types::OCCUPANCY_GRID).expect("hash");
    let dds = types::dds_type_name(types::OCCUPANCY_GRID).expect("dds");
    let key = names::entity_key(0, "/map", &dds, &hash);
    let gid = [7u8; 16];
    let mut seq = 0;
    let mut put = |payload: Vec<u8>, key: String, with_attachment: bool| {
        seq += 1;
        let att = Attachment {
            sequence_number: seq,
            source_timestamp_ns: roam_ros2::attachment::now_ns(),
            gid,
        };
        let session = session.clone();
        async move {
            let mut put = session.put(key, payload);
            if with_attachment {
                put = put.attachment(att.to_bytes().to_vec());
            }
            put.await.expect("put");
        }
    };
    let wait_version = |want: u64| {
        let client = client.clone();
        let root = h.root.clone();
        async move {
            loop {
                if occupancy_version(&client, &root).await >= want {
                    return;
                }
                tokio::time::sleep(Duration::from_millis(50)).await;
            }
        }
    };

    // A good map: a new occupancy version, cell for cell.
    let good = grid(4, 3, vec![0, 0, 100, -1, 0, 50, 100, 0, 0, 0, 0, 100]);
    put(cdr::encode(&good).expect("cdr"), key.clone(), true).await;
    within("the first map", wait_version(v0 + 1)).await;
    let layer: Layer = client
        .request::<Layer, Layer>(&keys::map_layer(&h.root, "occupancy"), None)
        .await
        .expect("occupancy");
    assert_eq!((layer.meta.width, layer.meta.height), (4, 3));
    assert_eq!(layer.meta.resolution, 0.5);
    assert_eq!(layer.meta.origin.x, -1.0);
    assert_eq!(layer.cells, Cells::I8(good.data.clone()));
    let v1 = occupancy_version(&client, &h.root).await;

    // Bad maps: 10⁹ cells (a header that says so), a truncated payload, no attachment,
    // another type hash.
    let huge = grid(40_000, 25_000, vec![0; 16]);
    put(cdr::encode(&huge).expect("cdr"), key.clone(), true).await;
    let bytes = cdr::encode(&good).expect("cdr");
    put(bytes[..bytes.len() - 5].to_vec(), key.clone(), true).await;
    put(bytes.clone(), key.clone(), false).await;
    let other = names::entity_key(0, "/map", &dds, &format!("RIHS01_{}", "0".repeat(64)));
    put(bytes.clone(), other, true).await;

    // A good map after them is still taken, and it is the only change.
    let second = grid(2, 2, vec![100, 0, 0, 100]);
    put(cdr::encode(&second).expect("cdr"), key.clone(), true).await;
    within("the second map", wait_version(v1 + 1)).await;
    let layer: Layer = client
        .request::<Layer, Layer>(&keys::map_layer(&h.root, "occupancy"), None)
        .await
        .expect("occupancy");
    assert_eq!(layer.cells, Cells::I8(second.data.clone()));
    assert_eq!(occupancy_version(&client, &h.root).await, v1 + 1);

    let text = log.text();
    assert!(
        text.contains("1000000000 cells") && text.contains("max_layer_cells"),
        "the 10⁹-cell map's refusal names the limit:\n{text}"
    );
    assert!(
        text.contains("not a valid OccupancyGrid"),
        "truncated:\n{text}"
    );
    assert!(
        text.contains("without rmw_zenoh's attachment"),
        "no attachment:\n{text}"
    );
    assert!(text.contains("RIHS01_0000"), "another type hash:\n{text}");
}

/// A map from ROS 2 of another size than the stack's reaches every service: the map
/// server holds it as a new world and forgets the layers of the old grid; the mapper
/// maps the new world afresh and sends its layers on the new grid; the planner plans
/// on it. No layer is left on the old grid (checked on the map server's index, through
/// Zenoh as any client reads it).
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_ros2_map_of_another_size_reaches_every_service() {
    let _log = captured_log();
    let h = Harness::start().await;
    let _map_server = h.start_role(h.map_server_config()).await;
    let _mapper = h.start_role(h.mapper_config()).await;
    let _planner = h.start_role(h.planner_config("p1")).await;
    let ros2 = Ros2Config {
        service: ServiceConfig::at(h.root.clone()),
        map_input: Some("/map".into()),
        ..Ros2Config::default()
    };
    let _ros2 = h.start_role(ros2).await;
    let client = h.client().await;
    let index = |client: roam_runtime::Requester, root: String| async move {
        client
            .request::<LayerList, LayerList>(&keys::map_index(&root), None)
            .await
            .expect("layers")
    };
    // The built-in world, with the mapper's layers on its grid.
    let before = within("the mapper's layers on the built-in grid", async {
        loop {
            let list = index(client.clone(), h.root.clone()).await;
            if list.layers.iter().any(|l| l.name == "news") {
                return list;
            }
            tokio::time::sleep(Duration::from_millis(100)).await;
        }
    })
    .await;
    let old_world = before.world.clone().expect("a world");

    // A 40 × 30 map of 0.5 m from ROS 2 (the built-in world is 100 × 100 of 0.2 m).
    let hash = hash::message_type_hash(types::OCCUPANCY_GRID).expect("hash");
    let dds = types::dds_type_name(types::OCCUPANCY_GRID).expect("dds");
    let key = names::entity_key(0, "/map", &dds, &hash);
    let map = grid(40, 30, vec![0; 1200]);
    let attachment = Attachment {
        sequence_number: 1,
        source_timestamp_ns: roam_ros2::attachment::now_ns(),
        gid: [9; 16],
    };
    client
        .session()
        .put(key, cdr::encode(&map).expect("cdr"))
        .attachment(attachment.to_bytes().to_vec())
        .await
        .expect("put");

    let after = within("every layer on the new grid", async {
        loop {
            let list = index(client.clone(), h.root.clone()).await;
            let on_new_grid = |l: &roam_proto::map::LayerInfo| {
                l.name == "heuristic" || (l.meta.width, l.meta.height) == (40, 30)
            };
            let news = list.layers.iter().any(|l| l.name == "news");
            if news && list.layers.iter().all(on_new_grid) {
                return list;
            }
            tokio::time::sleep(Duration::from_millis(100)).await;
        }
    })
    .await;
    let new_world = after.world.clone().expect("a world");
    assert_ne!(new_world.hash, old_world.hash, "a new grid is a new world");
    for name in [
        "occupancy",
        "inflated",
        "information",
        "news",
        "occupied_now",
        "change_rate",
    ] {
        let layer = after.layers.iter().find(|l| l.name == name);
        assert!(
            layer.is_some_and(|l| l.meta.resolution == 0.5),
            "{name}: {after:?}"
        );
    }

    // The planner plans on the new map: from one corner of it to the other.
    let planner = roam_planner::client::PlannerClient::new(client.session().clone(), &h.root);
    let request = roam_proto::planner::PlanRequest {
        request_id: None,
        cancel_token: None,
        start: [1.0, 1.0],
        goal: [16.0, 13.0],
        t_exec_s: 600.0,
        deadline_s: 5.0,
        model: roam_proto::planner::PlannerModel::Shortest,
        params: Default::default(),
        seed: 0,
        map_version: None,
        shortest: roam_proto::planner::ShortestPathUse::Omit,
        seed_route: Vec::new(),
    };
    let plan = within("a plan on the new map", async {
        loop {
            match planner.plan(&request).await {
                Ok(plan) => return plan,
                Err(_) => tokio::time::sleep(Duration::from_millis(200)).await,
            }
        }
    })
    .await;
    assert!(plan.reaches_goal, "{plan:?}");
}
