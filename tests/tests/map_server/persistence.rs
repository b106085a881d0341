//! What survives a restart: the same versions and content, the last good copy of a
//! corrupt layer, and derived layers in step after a kill between saves.

use super::*;

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_restarted_server_answers_with_the_same_versions_and_content() {
    let harness = Harness::start().await;
    let data = tempfile::tempdir().expect("tmp");
    let config = roam_map_server::MapServerConfig {
        data_dir: Some(data.path().to_owned()),
        ..harness.map_server_config()
    };
    let server = harness.start_role(config.clone()).await;
    let client = harness.client().await;
    let update_key = keys::map_update(&harness.root, "occupancy");
    within(
        "update",
        client.request::<LayerUpdate, UpdateAck>(&update_key, Some(&set(1, 20, 30, 100.0))),
    )
    .await
    .expect("v2");
    within(
        "update",
        client.request::<LayerUpdate, UpdateAck>(&update_key, Some(&set(2, 21, 30, 100.0))),
    )
    .await
    .expect("v3");
    let before = get_layer(&client, &harness.root, "occupancy").await;
    let inflated_before = get_layer(&client, &harness.root, "inflated").await;
    server.stop().await.1.expect("clean stop");
    assert!(
        !harness.is_live(roam_map_server::SERVICE_NAME).await,
        "the liveliness token is gone"
    );

    let server = harness.start_role(config).await;
    let after = get_layer(&client, &harness.root, "occupancy").await;
    assert_eq!(after.version, 3);
    assert_eq!(after, before);
    assert_eq!(
        get_layer(&client, &harness.root, "inflated").await,
        inflated_before
    );
    // And it goes on from there.
    let ack: UpdateAck = within(
        "update",
        client.request(&update_key, Some(&set(3, 22, 30, 100.0))),
    )
    .await
    .expect("v4");
    assert_eq!(ack.version, 4);
    server.stop().await.1.expect("clean stop");
    harness.close().await;
}

/// The newest snapshot of occupancy is cut in half on disk: the server falls back to
/// the previous copy and the change logged on top of it, serves that above the lost
/// version (so followers that keep the newest take it), and computes `inflated` again
/// from it; the information map, of the lost map's size, is loaded again.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_corrupt_persisted_layer_is_reported_and_the_last_good_copy_served() {
    let harness = Harness::start().await;
    let data = tempfile::tempdir().expect("tmp");
    let config = roam_map_server::MapServerConfig {
        data_dir: Some(data.path().to_owned()),
        load_dirs: vec![repo_path("config/maps")],
        ..harness.map_server_config()
    };
    let server = harness.start_role(config.clone()).await;
    let client = harness.client().await;
    let key = keys::map_update(&harness.root, "occupancy");
    within(
        "update",
        client.request::<LayerUpdate, UpdateAck>(&key, Some(&set(1, 5, 5, 100.0))),
    )
    .await
    .expect("v2, in the change log");
    let before_load = get_layer(&client, &harness.root, "occupancy").await;
    let depot = "depot.yaml";
    within(
        "load",
        client.request::<LoadMap, LayerList>(
            &keys::map_load(&harness.root),
            Some(&LoadMap {
                path: depot.into(),
                base_version: Some(2),
            }),
        ),
    )
    .await
    .expect("v3, a new snapshot");
    server.stop().await.1.expect("clean stop");

    let file = data.path().join("layers/occupancy.layer");
    let bytes = std::fs::read(&file).expect("layer file");
    std::fs::write(&file, &bytes[..bytes.len() / 2]).expect("truncate");

    let server = harness.start_role(config).await;
    let list: LayerList = within(
        "index",
        client.request::<LayerList, LayerList>(&keys::map_index(&harness.root), None),
    )
    .await
    .expect("list");
    let warnings = list.warnings.join("\n");
    assert!(
        warnings.contains("occupancy.layer is corrupt: truncated"),
        "{warnings}"
    );
    assert!(warnings.contains("last good copy"), "{warnings}");
    assert!(warnings.contains("served as version 4"), "{warnings}");
    let occupancy = get_layer(&client, &harness.root, "occupancy").await;
    assert_eq!(
        (occupancy.version, &occupancy.cells),
        (4, &before_load.cells),
        "the previous copy with its logged change, above the lost version 3"
    );
    let inflated = get_layer(&client, &harness.root, "inflated").await;
    assert_eq!(inflated.meta, occupancy.meta, "inflated follows it");
    assert!(inflated.version >= 4, "never back: {}", inflated.version);
    let information = get_layer(&client, &harness.root, "information").await;
    assert_eq!(information.meta, occupancy.meta, "{warnings}");
    assert!(
        data.path().join("layers/occupancy.layer.corrupt").exists(),
        "the corrupt file is kept"
    );

    server.stop().await.1.expect("clean stop");
    harness.close().await;
}

/// A SIGKILL between the save of occupancy and the save of inflated, and one during
/// the next append: the files as such a crash leaves them (occupancy's log has the
/// last acknowledged change, inflated's does not; occupancy's ends in a torn record).
/// The restarted server computes `inflated` again, and every obstacle of the
/// `occupancy` it serves is occupied in the `inflated` it serves.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn inflated_always_matches_occupancy_after_a_kill_between_saves() {
    use roam_map_server::persist::log;

    let harness = Harness::start().await;
    let data = tempfile::tempdir().expect("tmp");
    let config = roam_map_server::MapServerConfig {
        data_dir: Some(data.path().to_owned()),
        ..harness.map_server_config()
    };
    let server = harness.start_role(config.clone()).await;
    let client = harness.client().await;
    let key = keys::map_update(&harness.root, "occupancy");
    for (base, x) in [(1, 30), (2, 60)] {
        within(
            "update",
            client.request::<LayerUpdate, UpdateAck>(&key, Some(&set(base, x, 40, 100.0))),
        )
        .await
        .expect("update");
    }
    server.stop().await.1.expect("clean stop");

    let layers = data.path().join("layers");
    // Inflated's last record (version 3) never reached the disk.
    let inflated_log = layers.join("inflated.log");
    let scan = log::scan(&inflated_log, "inflated", u64::MAX, u64::MAX).expect("scan");
    let last = scan.records.last().expect("a record");
    assert_eq!(last.version, 3);
    let cut = scan.good_bytes - log::record_bytes(last.edits.len(), last.edits.values.dtype());
    std::fs::OpenOptions::new()
        .write(true)
        .open(&inflated_log)
        .and_then(|f| f.set_len(cut))
        .expect("cut");
    // And half of an unacknowledged version 4 of occupancy.
    let torn = log::encode(
        4,
        0,
        &roam_map_server::edits::CellEdits {
            positions: vec![(80, 40)],
            values: Cells::I8(vec![100]),
        },
    );
    std::fs::OpenOptions::new()
        .append(true)
        .open(layers.join("occupancy.log"))
        .and_then(|mut f| std::io::Write::write_all(&mut f, &torn[..torn.len() / 2]))
        .expect("torn append");

    let server = harness.start_role(config).await;
    let occupancy = get_layer(&client, &harness.root, "occupancy").await;
    let inflated = get_layer(&client, &harness.root, "inflated").await;
    assert_eq!(occupancy.version, 3, "every acknowledged change, no more");
    let at = |x: usize| occupancy.cells.get_f64(40 * 100 + x);
    assert_eq!(
        (at(30), at(60), at(80)),
        (Some(100.0), Some(100.0), Some(0.0))
    );
    assert!(inflated.version >= 3, "never back: {}", inflated.version);
    let mut obstacles = 0;
    for i in 0..occupancy.cells.len() {
        if occupancy.cells.get_f64(i).is_some_and(|c| c >= 65.0) {
            obstacles += 1;
            assert_eq!(
                inflated.cells.get_f64(i),
                Some(100.0),
                "obstacle cell {i} is free in inflated"
            );
        }
    }
    assert!(obstacles > 2, "the world has obstacles: {obstacles}");
    let Cells::I8(cells) = &occupancy.cells else {
        panic!("occupancy is i8");
    };
    let list: LayerList = within(
        "index",
        client.request::<LayerList, LayerList>(&keys::map_index(&harness.root), None),
    )
    .await
    .expect("list");
    let warnings = list.warnings.join("\n");
    assert!(warnings.contains("'inflated' computed again"), "{warnings}");
    assert!(warnings.contains("incomplete last record"), "{warnings}");
    // Exactly what inflating this occupancy gives, with the built-in world's radius.
    let radius = roam_map_server::map_file::builtin(roam_world::DEFAULT_MAX_CELLS)
        .expect("built-in world")
        .robot_radius_m
        .unwrap_or(0.2);
    let expected = roam_world::layers::inflate(
        &roam_world::grid::Grid {
            meta: occupancy.meta,
            cells: cells.clone(),
        },
        radius,
        65,
    );
    assert_eq!(inflated.cells, Cells::I8(expected.cells));

    server.stop().await.1.expect("clean stop");
    harness.close().await;
}
