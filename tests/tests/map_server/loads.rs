//! Loads: only from the configured load directories, with errors that name what is
//! wrong; none at all without them.

use super::*;

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn loads_read_only_the_load_directories_and_name_what_is_wrong() {
    let harness = Harness::start().await;
    let dir = tempfile::tempdir().expect("tmp");
    let maps = concat!(env!("CARGO_MANIFEST_DIR"), "/../config/maps");
    let server = harness
        .start_role(MapServerConfig {
            load_dirs: vec![dir.path().to_owned(), maps.into()],
            ..harness.map_server_config()
        })
        .await;
    let client = harness.client().await;
    let key = keys::map_load(&harness.root);
    let load = |path: &str, base_version: Option<u64>| LoadMap {
        path: path.to_owned(),
        base_version,
    };

    // No reply names where the server keeps its directories.
    let server_paths = [
        dir.path().display().to_string(),
        dir.path().canonicalize().expect("c").display().to_string(),
        std::path::Path::new(maps)
            .canonicalize()
            .expect("c")
            .display()
            .to_string(),
    ];
    let tells_nothing = |reply: &ErrorReply| {
        for path in &server_paths {
            assert!(
                !reply.message.contains(path.as_str()),
                "the reply names the server's {path}: {}",
                reply.message
            );
        }
    };

    let missing =
        refusal(client.request::<LoadMap, LayerList>(&key, Some(&load("missing.yaml", None))))
            .await;
    assert_eq!(missing.code, ErrorCode::NotFound);
    assert!(
        missing.message.contains("'missing.yaml'")
            && missing
                .message
                .contains("outside the configured load directories"),
        "{}",
        missing.message
    );
    tells_nothing(&missing);
    // Outside the directories: the same answer as a missing file, naming the file as
    // the peer gave it.
    let passwd =
        refusal(client.request::<LoadMap, LayerList>(&key, Some(&load("/etc/passwd", None)))).await;
    assert_eq!(passwd.code, ErrorCode::NotFound);
    assert!(!passwd.message.contains("root:"), "{}", passwd.message);
    assert_eq!(
        passwd.message.replace("/etc/passwd", "missing.yaml"),
        missing.message
    );
    tells_nothing(&passwd);

    // A map whose image is truncated: named relative to its load directory.
    std::fs::write(dir.path().join("bad.pgm"), b"P5\n10 10\n255\n\x00\x00").expect("pgm");
    std::fs::write(dir.path().join("bad.yaml"), "image: bad.pgm\nresolution: 0.05\norigin: [0, 0, 0]\noccupied_thresh: 0.65\nfree_thresh: 0.196\n").expect("yaml");
    let corrupt =
        refusal(client.request::<LoadMap, LayerList>(&key, Some(&load("bad.yaml", None)))).await;
    assert_eq!(corrupt.code, ErrorCode::CorruptFile);
    assert!(
        corrupt.message.contains("map image bad.pgm"),
        "{}",
        corrupt.message
    );
    tells_nothing(&corrupt);

    // A map inside the directories whose image is outside them is refused like a
    // missing file, without naming what it refers to.
    std::fs::write(dir.path().join("escape.yaml"), "image: /etc/passwd\nresolution: 0.05\norigin: [0, 0, 0]\noccupied_thresh: 0.65\nfree_thresh: 0.196\n").expect("yaml");
    let escape =
        refusal(client.request::<LoadMap, LayerList>(&key, Some(&load("escape.yaml", None)))).await;
    assert_eq!(escape.code, ErrorCode::NotFound, "{}", escape.message);
    assert!(
        escape.message.contains("'escape.yaml'") && !escape.message.contains("/etc/passwd"),
        "{}",
        escape.message
    );
    tells_nothing(&escape);

    // A good map loads, bumps the versions and is served.
    let list: LayerList = within(
        "load",
        client.request(&key, Some(&load("depot.yaml", Some(1)))),
    )
    .await
    .expect("load depot");
    let occupancy = list
        .layers
        .iter()
        .find(|l| l.name == "occupancy")
        .expect("occupancy");
    assert_eq!((occupancy.meta.width, occupancy.version), (604, 2));
    // A load based on an old version is stale.
    let stale =
        refusal(client.request::<LoadMap, LayerList>(&key, Some(&load("depot.yaml", Some(1)))))
            .await;
    assert_eq!(stale.code, ErrorCode::StaleVersion);

    server.stop().await.1.expect("clean stop");
    harness.close().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn without_load_directories_loads_are_off() {
    let harness = Harness::start().await;
    let server = harness.start_role(harness.map_server_config()).await;
    let client = harness.client().await;
    let depot = concat!(env!("CARGO_MANIFEST_DIR"), "/../config/maps/depot.yaml");
    let off = refusal(client.request::<LoadMap, LayerList>(
        &keys::map_load(&harness.root),
        Some(&LoadMap {
            path: depot.into(),
            base_version: None,
        }),
    ))
    .await;
    assert_eq!(off.code, ErrorCode::InvalidRequest);
    assert!(off.message.contains("loads are off"), "{}", off.message);
    server.stop().await.1.expect("clean stop");
    harness.close().await;
}
