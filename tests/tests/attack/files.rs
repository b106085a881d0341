//! Loads on a peer's behalf: the map server's `<root>/map/load` and the sim's `load`
//! read only inside their load directories, refuse everything else with the same
//! answer as a missing file, never quote a file, and log each refusal.

use roam_map_server::MapServerConfig;
use roam_proto::map::{LayerList, LoadMap};
use roam_proto::sim::{SimControl, SimStatus};
use roam_proto::{keys, ErrorCode, ErrorReply};
use roam_runtime::{ClientError, Requester};
use roam_tests::Harness;

use crate::logs::Captured;

/// A string every secret file holds: it must never come back, in a reply or a log.
pub(crate) const MARKER: &str = "roam-secret-7f3a91";

/// A folder with a load directory (`maps/`, a good map, a broken one, a link out, a map
/// whose image is outside) and, beside it, a secret.
pub(crate) struct Files {
    pub(crate) dir: tempfile::TempDir,
}

impl Files {
    pub(crate) fn new() -> Files {
        let dir = tempfile::tempdir().expect("tmp");
        let root = dir.path();
        let maps = root.join("maps");
        std::fs::create_dir(&maps).expect("maps");
        let secret = root.join("users.txt");
        std::fs::write(&secret, format!("operator:{MARKER}\nroot:x:0:0:{MARKER}\n"))
            .expect("secret");
        // A valid 4 x 4 map, all free.
        let mut pgm = b"P5\n4 4\n255\n".to_vec();
        pgm.extend_from_slice(&[254; 16]);
        std::fs::write(maps.join("ok.pgm"), pgm).expect("pgm");
        let yaml = "resolution: 0.5\norigin: [0, 0, 0]\noccupied_thresh: 0.65\nfree_thresh: 0.196\nnegate: 0\n";
        std::fs::write(maps.join("ok.yaml"), format!("image: ok.pgm\n{yaml}")).expect("yaml");
        std::fs::write(
            maps.join("escape.yaml"),
            format!("image: {}\n{yaml}", secret.display()),
        )
        .expect("yaml");
        std::fs::write(
            maps.join("dotdot.yaml"),
            format!("image: ../users.txt\n{yaml}"),
        )
        .expect("yaml");
        // A file in the directory that is not a map and holds a secret.
        std::fs::write(maps.join("notes.yaml"), format!("- {MARKER}: root:x:0:0\n"))
            .expect("notes");
        std::os::unix::fs::symlink(&secret, maps.join("link.yaml")).expect("symlink");
        Files { dir }
    }

    pub(crate) fn maps(&self) -> std::path::PathBuf {
        self.dir.path().join("maps")
    }

    fn secret(&self) -> std::path::PathBuf {
        self.dir.path().join("users.txt")
    }

    /// What a peer might ask for, each outside the directory or not there.
    pub(crate) fn forbidden(&self) -> Vec<String> {
        vec![
            "/etc/passwd".into(),
            "/etc/shadow".into(),
            "/proc/self/maps".into(),
            "../users.txt".into(),
            "../../../../../../etc/passwd".into(),
            self.secret().display().to_string(),
            "link.yaml".into(),
            "missing.yaml".into(),
            String::new(),
        ]
    }
}

fn refusal(result: Result<impl std::fmt::Debug, ClientError>, what: &str) -> ErrorReply {
    match result {
        Err(ClientError::Refused(reply)) => reply,
        other => panic!("{what}: expected a refusal, got {other:?}"),
    }
}

/// The reply with the requested name taken out: a missing file and a forbidden one must
/// then read the same.
fn shape(reply: &ErrorReply, requested: &str) -> (ErrorCode, String) {
    let message = if requested.is_empty() {
        reply.message.clone()
    } else {
        reply.message.replace(requested, "<file>")
    };
    (reply.code, message)
}

fn assert_no_content(reply: &ErrorReply, what: &str) {
    for leak in [MARKER, "root:x:0", "operator:"] {
        assert!(
            !reply.message.contains(leak),
            "{what}: the reply quotes a file: {}",
            reply.message
        );
    }
}

/// A refused load names the file as the peer gave it and none of the server's own
/// paths: not the load directory, nor the folder around it (unless the peer named it).
fn assert_no_server_path(reply: &ErrorReply, requested: &str, files: &Files) {
    let mut paths = vec![files.maps(), files.dir.path().to_owned()];
    paths.extend(paths.clone().iter().filter_map(|p| p.canonicalize().ok()));
    for path in paths {
        let path = path.display().to_string();
        if requested.contains(&path) {
            continue;
        }
        assert!(
            !reply.message.contains(&path),
            "'{requested}': the reply names the server's {path}: {}",
            reply.message
        );
    }
}

/// The map server's loads.
pub(crate) async fn map_loads(harness: &Harness, client: &Requester, files: &Files) {
    let server = harness
        .start_role(MapServerConfig {
            load_dirs: vec![files.maps()],
            ..harness.map_server_config()
        })
        .await;
    let key = keys::map_load(&harness.root);
    let load = |path: &str| LoadMap {
        path: path.to_owned(),
        base_version: None,
    };
    let missing = refusal(
        client
            .request::<LoadMap, LayerList>(&key, Some(&load("missing.yaml")))
            .await,
        "missing",
    );
    assert_eq!(missing.code, ErrorCode::NotFound);
    let missing_shape = shape(&missing, "missing.yaml");
    for requested in files.forbidden() {
        let reply = refusal(
            client
                .request::<LoadMap, LayerList>(&key, Some(&load(&requested)))
                .await,
            &requested,
        );
        assert_no_content(&reply, &requested);
        assert_no_server_path(&reply, &requested, files);
        if !requested.is_empty() {
            assert_eq!(
                shape(&reply, &requested),
                missing_shape,
                "'{requested}' is answered otherwise than a missing file: an existence oracle"
            );
            assert!(
                reply.message.contains(&format!("'{requested}'"))
                    && reply
                        .message
                        .contains("outside the configured load directories"),
                "{}",
                reply.message
            );
        }
    }
    // Inside the directory, but following a reference out of it: refused the same way.
    for requested in ["escape.yaml", "dotdot.yaml"] {
        let reply = refusal(
            client
                .request::<LoadMap, LayerList>(&key, Some(&load(requested)))
                .await,
            requested,
        );
        assert_eq!(
            reply.code,
            ErrorCode::NotFound,
            "{requested}: {}",
            reply.message
        );
        assert_no_content(&reply, requested);
        assert_no_server_path(&reply, requested, files);
    }
    // Inside the directory and not a map: named as corrupt, without its content, and
    // relative to its directory.
    let notes = refusal(
        client
            .request::<LoadMap, LayerList>(&key, Some(&load("notes.yaml")))
            .await,
        "notes",
    );
    assert_no_content(&notes, "notes.yaml");
    assert_no_server_path(&notes, "notes.yaml", files);
    assert!(notes.message.contains("notes.yaml"), "{}", notes.message);
    // And a real map in the directory loads.
    let list: LayerList = client
        .request(&key, Some(&load("ok.yaml")))
        .await
        .expect("a map in the load directory loads");
    assert!(list
        .layers
        .iter()
        .any(|l| l.name == "occupancy" && l.meta.width == 4));
    server.stop().await.1.expect("clean stop");
}

/// The sim's loads.
pub(crate) async fn sim_loads(harness: &Harness, client: &Requester, files: &Files) {
    let mut config = harness.sim_config(None);
    config.load_dirs = vec![files.maps()];
    let sim = harness.start_role(config).await;
    let key = keys::sim_control(&harness.root);
    let load = |path: &str| SimControl::Load {
        path: path.to_owned(),
        seed: 0,
    };
    let missing = refusal(
        client
            .request::<SimControl, SimStatus>(&key, Some(&load("missing.yaml")))
            .await,
        "sim missing",
    );
    let missing_shape = shape(&missing, "missing.yaml");
    for requested in files
        .forbidden()
        .into_iter()
        .chain(["escape.yaml".into(), "notes.yaml".into()])
    {
        let reply = refusal(
            client
                .request::<SimControl, SimStatus>(&key, Some(&load(&requested)))
                .await,
            &requested,
        );
        assert_no_content(&reply, &requested);
        assert_no_server_path(&reply, &requested, files);
        if files.forbidden().contains(&requested) && !requested.is_empty() {
            assert_eq!(
                shape(&reply, &requested),
                missing_shape,
                "sim: '{requested}'"
            );
        }
    }
    sim.stop().await.1.expect("clean stop");
}

/// No secret in the log, and every refused load logged, with the detail the peer's
/// reply leaves out (the server's load directory).
pub(crate) fn check_log(log: &Captured, from: usize, files: &Files) {
    let text = log.since(from);
    assert!(!text.contains(MARKER), "a secret reached the log");
    assert!(
        text.contains("refused a map load") && text.contains("refused a scenario load"),
        "refused loads are logged at the default level"
    );
    let maps = files.maps().canonicalize().unwrap_or_else(|_| files.maps());
    assert!(
        text.contains(&maps.display().to_string()),
        "the log keeps the load directory of a refused load"
    );
}
