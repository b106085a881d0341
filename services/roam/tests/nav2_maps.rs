//! `roam stack --map` on Nav2 maps at the resolutions users have (3, 5 and 10 cm),
//! generated here as map_server writes them (a PGM and its yaml): the stack boots with
//! defaults that fit the map (a ROS map has no `sensing:` section, so nothing the user
//! did not write is checked against the map's resolution), and every layer the map
//! server lists is on the map's grid (the heuristic on its coarser blocks).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use roam_stack::router::free_loopback_port;

mod clients;
use clients::RoamProcess;

const ROAM: &str = env!("CARGO_BIN_EXE_roam");

/// A 6 × 4.5 m room with a wall around it and a pillar, at `resolution` metres, written
/// as `room.pgm` and `room.yaml` (trinary, Nav2's thresholds) in `dir`; the yaml's path.
fn write_room(dir: &Path, resolution: f64) -> PathBuf {
    let (w, h) = (
        (6.0 / resolution).round() as usize,
        (4.5 / resolution).round() as usize,
    );
    let mut pgm = format!("P5\n{w} {h}\n255\n").into_bytes();
    for row in 0..h {
        let y = (h - 1 - row) as f64 * resolution;
        for col in 0..w {
            let x = col as f64 * resolution;
            let wall = !(0.3..=5.7).contains(&x) || !(0.3..=4.2).contains(&y);
            let pillar = (2.5..3.0).contains(&x) && (2.0..2.5).contains(&y);
            pgm.push(if wall || pillar { 0 } else { 254 });
        }
    }
    std::fs::write(dir.join("room.pgm"), pgm).expect("pgm");
    let yaml = dir.join("room.yaml");
    std::fs::write(
        &yaml,
        format!(
            "image: room.pgm\nresolution: {resolution}\norigin: [0.0, 0.0, 0.0]\n\
             negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n"
        ),
    )
    .expect("yaml");
    yaml
}

/// `roam map layers` through `endpoint`, asked again (for at most 60 s) until it
/// lists `expected` layers or more.
fn layers(endpoint: &str, root: &str, expected: usize) -> Vec<serde_json::Value> {
    let started = Instant::now();
    loop {
        let output = Command::new(ROAM)
            .args(["map", "layers", "--mode", "client", "--connect", endpoint])
            .args(["--root", root, "--timeout", "2"])
            .output()
            .expect("run roam map layers");
        if output.status.success() {
            let list: serde_json::Value =
                serde_json::from_slice(&output.stdout).expect("layer list json");
            let layers = list["layers"].as_array().cloned().unwrap_or_default();
            if layers.len() >= expected {
                return layers;
            }
        }
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "fewer than {expected} layers after 60 s: {}",
            String::from_utf8_lossy(&output.stderr)
        );
        std::thread::sleep(Duration::from_millis(300));
    }
}

#[test]
fn the_stack_boots_on_nav2_maps_at_3_5_and_10_cm_with_every_layer_on_the_map() {
    let dir = tempfile::tempdir().expect("tmp");
    for resolution in [0.03_f64, 0.05, 0.10] {
        let sub = dir.path().join(format!("{}", (resolution * 100.0).round()));
        std::fs::create_dir_all(&sub).expect("dir");
        let map = write_room(&sub, resolution);
        let endpoint = format!("tcp/127.0.0.1:{}", free_loopback_port().expect("port"));
        let root = format!(
            "nav2-{}-{}",
            (resolution * 100.0).round(),
            std::process::id()
        );
        let map_arg = map.display().to_string();
        let _stack = RoamProcess::start(
            &["stack", "--listen", &endpoint, "--map", &map_arg],
            &root,
            "roam stack up",
        );
        // The map server's four, and the mapper's layers once it has published them.
        let listed = layers(&endpoint, &root, 8);
        let (w, h) = (
            (6.0 / resolution).round() as u64,
            (4.5 / resolution).round() as u64,
        );
        for layer in &listed {
            let name = layer["name"].as_str().unwrap_or("?");
            let meta = &layer["meta"];
            let at = meta["resolution"].as_f64().unwrap_or(f64::NAN);
            if name == "heuristic" {
                assert!(
                    at > resolution,
                    "{resolution} m: the heuristic is in blocks"
                );
                continue;
            }
            assert_eq!(
                (meta["width"].as_u64(), meta["height"].as_u64()),
                (Some(w), Some(h)),
                "{resolution} m: layer {name}"
            );
            assert!(
                (at - resolution).abs() < 1e-9,
                "{resolution} m: {name} at {at}"
            );
        }
        for name in [
            "occupancy",
            "inflated",
            "information",
            "heuristic",
            "change_rate",
        ] {
            assert!(
                listed.iter().any(|l| l["name"] == name),
                "{resolution} m: no {name} layer in {listed:?}"
            );
        }
    }
}
