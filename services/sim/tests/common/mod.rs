//! Scenarios for the tests: written inline or shipped in `config/scenarios/`.

#![allow(dead_code)]

use std::path::{Path, PathBuf};

use roam_world::scenario::{self, Scenario};
use roam_world::DEFAULT_MAX_CELLS;

/// Parses a scenario written in a test.
pub fn inline(text: &str) -> Scenario {
    scenario::parse(Path::new("test.yaml"), text, DEFAULT_MAX_CELLS)
        .unwrap_or_else(|e| panic!("{e}"))
}

/// The folder of the shipped scenarios.
pub fn scenarios_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/scenarios")
}

/// Loads a shipped scenario by file name.
pub fn shipped(file: &str) -> Scenario {
    scenario::load(&scenarios_dir().join(file), DEFAULT_MAX_CELLS).unwrap_or_else(|e| panic!("{e}"))
}

/// A 10 x 10 m room of 0.5 m cells with border walls and a wall at x = 5..5.9 (cells
/// x = 10..=11) from y = 0 to y = 7, three anchors and two robots.
pub const ROOM: &str = "
name: room
map:
  grid:
    size_m: [10.0, 10.0]
    resolution: 0.5
    border_walls: true
    obstacles:
      - rect: [5.0, 0.0, 5.9, 7.0]
sensing: { observation_radius_m: 3.0 }
anchors:
  - { name: near, at: [2.0, 9.75] }
  - { name: mid, at: [9.0, 9.0] }
  - { name: far, at: [9.5, 0.5] }
robots:
  - { name: r1, at: [2.0, 5.0] }
  - { name: r2, at: [8.0, 2.0] }
";
