//! Every shipped scenario and config file parses; the built-in world is what it says.

use std::path::{Path, PathBuf};

use roam_map_server::grid::{occupancy, world_to_cell};
use roam_map_server::map_file;
use roam_map_server::scenario::{self, ScenarioError};
use roam_map_server::store::DEFAULT_LIMITS;
use roam_map_server::MapServerConfig;

fn config_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config")
}

#[test]
fn every_shipped_scenario_loads() {
    let mut seen = 0;
    for entry in std::fs::read_dir(config_dir().join("scenarios")).expect("scenarios dir") {
        let path = entry.expect("entry").path();
        if path.extension().and_then(|e| e.to_str()) == Some("yaml") {
            scenario::load(&path, DEFAULT_LIMITS.max_layer_cells).unwrap_or_else(|e| panic!("{e}"));
            seen += 1;
        }
    }
    assert!(seen >= 1);
}

#[test]
fn the_map_server_config_example_parses() {
    let config: MapServerConfig =
        roam_runtime::config_file::load(&config_dir().join("map-server.yaml")).expect("config");
    assert_eq!(config.root, "roam");
    assert_eq!(config.limits, DEFAULT_LIMITS);
}

#[test]
fn the_builtin_world_has_walls_zones_and_free_places() {
    let content = map_file::builtin(DEFAULT_LIMITS.max_layer_cells).expect("builtin");
    let occ = &content.occupancy;
    assert_eq!((occ.meta.width, occ.meta.height), (100, 100));
    assert_eq!(occ.get(0, 50), Some(occupancy::OCCUPIED), "border wall");
    let info = content.information.expect("information");
    let (lx, ly) = world_to_cell(&info.meta, -5.0, 8.0).expect("in map");
    assert_eq!(info.get(lx, ly), Some(90), "the lab zone");
    let parsed = scenario::parse(
        Path::new("builtin"),
        map_file::BUILTIN_SCENARIO,
        DEFAULT_LIMITS.max_layer_cells,
    )
    .expect("parse");
    for place in &parsed.file.places {
        let (x, y) = world_to_cell(&occ.meta, place.at[0], place.at[1]).expect("inside");
        assert_eq!(
            occ.get(x, y),
            Some(occupancy::FREE),
            "{} is free",
            place.name
        );
    }
}

#[test]
fn scenario_errors_name_the_file_and_field() {
    let path = Path::new("/tmp/roam-bad.yaml");
    let text = "name: x\nmap:\n  grid:\n    size_m: [2.0, 2.0]\n    resolution: 0.1\ninformation:\n  zones:\n    - { name: z, score: 120, rect: [0, 0, 1, 1] }\n";
    let err =
        scenario::parse(path, text, DEFAULT_LIMITS.max_layer_cells).expect_err("must be refused");
    let msg = err.to_string();
    assert!(matches!(err, ScenarioError::Field { .. }), "{msg}");
    assert!(
        msg.contains("/tmp/roam-bad.yaml") && msg.contains("information.zones[0].score"),
        "{msg}"
    );

    let err = scenario::parse(
        path,
        "name: x\nmap: {grid: {size_m: [1, 1], resolution: 0.1}}\nanchorz: []\n",
        1000,
    )
    .expect_err("must be refused");
    assert!(err.to_string().contains("anchorz"), "{err}");

    let err = scenario::parse(
        path,
        "name: x\nmap: {grid: {size_m: [100, 100], resolution: 0.1}}\n",
        1000,
    )
    .expect_err("must be refused");
    assert!(err.to_string().contains("max_layer_cells"), "{err}");
}
