//! The shipped map server config parses, with the limits it documents.

use std::path::Path;

use roam_map_server::store::DEFAULT_LIMITS;
use roam_map_server::MapServerConfig;

fn config_dir() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config")
}

#[test]
fn the_map_server_config_example_parses() {
    let config: MapServerConfig =
        roam_runtime::config_file::load(&config_dir().join("map-server.yaml")).expect("config");
    assert_eq!(config.service.root, "roam");
    assert_eq!(config.limits, DEFAULT_LIMITS);
}
