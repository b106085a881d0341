//! Worlds for the planner's tests.

use roam_map_server::grid::Grid;
use roam_map_server::layers::inflate;
use roam_map_server::map_file;
use roam_map_server::store::DEFAULT_LIMITS;
use roam_planner::world::World;

/// The built-in 20 × 20 m downtime world, inflated by its robot radius.
pub fn builtin_world() -> World {
    let content = map_file::builtin(DEFAULT_LIMITS.max_layer_cells).expect("builtin");
    let inflated = inflate(
        &content.occupancy,
        content.robot_radius_m.unwrap_or(0.2),
        65,
    );
    let information = content.information.expect("information");
    World::new(&inflated, &information, 0.25).expect("world")
}

/// An open `w × h` world at 0.2 m with walls around and a score-`score` square.
#[allow(dead_code)]
pub fn open_world(w: u32, h: u32) -> World {
    let meta = roam_proto::map::GridMeta {
        width: w,
        height: h,
        resolution: 0.2,
        origin: roam_proto::map::Origin::default(),
    };
    let occupancy = Grid::filled(meta, 0i8);
    let mut information = Grid::filled(meta, 0u8);
    for y in h as usize / 2..h as usize {
        for x in w as usize / 2..w as usize {
            information.cells[y * w as usize + x] = 60;
        }
    }
    World::new(&occupancy, &information, 0.25).expect("world")
}
