//! Derived layers in step: `inflated` must be `occupancy` inflated and `heuristic` must
//! be `information` compressed, as the map server would compute them now from the
//! sources it serves. Checked at the end of the chaos day, when every restart and
//! restore is behind it, by computing both again here with the map server's own
//! recipes (`roam_world::layers`, `DerivedParams`).

use roam_map_server::store::DerivedParams;
use roam_proto::cells::Cells;
use roam_proto::keys;
use roam_proto::map::{
    GridMeta, Layer, HEURISTIC_LAYER, INFLATED_LAYER, INFORMATION_LAYER, OCCUPANCY_LAYER,
};
use roam_runtime::Requester;
use roam_world::grid::Grid;
use roam_world::layers;

/// The derived layers checked and the names of those out of step (or unreadable).
pub(super) async fn out_of_step(
    requester: &Requester,
    root: &str,
    robot_radius_m: f64,
) -> (usize, Vec<String>) {
    let params = DerivedParams {
        robot_radius_m,
        ..DerivedParams::default()
    };
    let mut bad = Vec::new();
    let inflated_ok = match pair(requester, root, OCCUPANCY_LAYER, INFLATED_LAYER).await {
        Some((meta, Cells::I8(cells), Cells::I8(have))) => {
            let grid = Grid { meta, cells };
            layers::inflate(&grid, params.robot_radius_m, params.lethal_threshold).cells == have
        }
        _ => false,
    };
    if !inflated_ok {
        bad.push(INFLATED_LAYER.to_owned());
    }
    let heuristic_ok = match pair(requester, root, INFORMATION_LAYER, HEURISTIC_LAYER).await {
        Some((meta, Cells::U8(cells), Cells::F32(have))) => {
            let grid = Grid { meta, cells };
            let want = layers::heuristic(&grid, params.heuristic_compression).cells;
            want.len() == have.len()
                && want
                    .iter()
                    .zip(&have)
                    .all(|(a, b)| a.to_bits() == b.to_bits())
        }
        _ => false,
    };
    if !heuristic_ok {
        bad.push(HEURISTIC_LAYER.to_owned());
    }
    (2, bad)
}

/// The source layer's grid and cells and the derived layer's cells, as the map server
/// serves them now; `None` when either cannot be read.
async fn pair(
    requester: &Requester,
    root: &str,
    source: &str,
    derived: &str,
) -> Option<(GridMeta, Cells, Cells)> {
    let (source_key, derived_key) = (
        keys::map_layer(root, source),
        keys::map_layer(root, derived),
    );
    let source: Layer = requester
        .request::<Layer, Layer>(&source_key, None)
        .await
        .ok()?;
    let derived: Layer = requester
        .request::<Layer, Layer>(&derived_key, None)
        .await
        .ok()?;
    Some((source.meta, source.cells, derived.cells))
}
