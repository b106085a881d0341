//! Which world a service was given: one stack runs one world.
//!
//! Every service of a stack is handed a map or scenario (`--map`, `--scenario`). When
//! they are handed different ones, each works on its own world without a word: a PEB
//! layer 100 × 100 beside a 1006 × 1674 occupancy, a controller avoiding walls that are
//! not there. The world's id is the map itself: a hash of the occupancy grid's placement
//! and cells (FNV-1a 64), with the scenario's name (or the map file's stem) to show to a
//! person. Two services agree on the world when their hashes agree; the map server
//! publishes its world in `<root>/map/layers`, refuses updates made for another, and
//! every other service compares its own at start (`roam_runtime::world_check`).

use roam_proto::map::{GridMeta, WorldId};

use crate::grid::Grid;
use crate::seed::{fnv1a_extend, FNV1A_OFFSET};

fn meta_bytes(meta: &GridMeta) -> Vec<u8> {
    let mut out = Vec::with_capacity(48);
    out.extend_from_slice(&meta.width.to_le_bytes());
    out.extend_from_slice(&meta.height.to_le_bytes());
    for v in [
        meta.resolution,
        meta.origin.x,
        meta.origin.y,
        meta.origin.yaw,
    ] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

/// The id of the world whose occupancy grid is `occupancy`, shown as `name`.
pub fn world_id(name: &str, occupancy: &Grid<i8>) -> WorldId {
    let mut hash = fnv1a_extend(FNV1A_OFFSET, &meta_bytes(&occupancy.meta));
    // i8 cells as their bytes: the grid's own representation, whatever the platform.
    let cells: Vec<u8> = occupancy.cells.iter().map(|&c| c as u8).collect();
    hash = fnv1a_extend(hash, &cells);
    WorldId {
        name: roam_proto::excerpt(name).to_string(),
        hash: format!("{hash:016x}"),
    }
}

/// The world of a loaded scenario (the same id the map server gives it).
pub fn of_scenario(scenario: &crate::scenario::Scenario) -> WorldId {
    world_id(&scenario.file.name, &scenario.occupancy)
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_proto::map::Origin;

    fn grid(fill: i8) -> Grid<i8> {
        Grid::filled(
            GridMeta {
                width: 3,
                height: 2,
                resolution: 0.5,
                origin: Origin::default(),
            },
            fill,
        )
    }

    #[test]
    fn the_same_map_is_the_same_world_whatever_its_name() {
        assert_eq!(world_id("a", &grid(0)).hash, world_id("b", &grid(0)).hash);
        assert_ne!(world_id("a", &grid(0)).hash, world_id("a", &grid(100)).hash);
        let mut moved = grid(0);
        moved.meta.origin.x = 1.0;
        assert_ne!(world_id("a", &grid(0)).hash, world_id("a", &moved).hash);
    }
}
