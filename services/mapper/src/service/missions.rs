//! Missions turned into reservations: the cells a robot's path will show it.

use roam_proto::controller::Mission;
use roam_runtime::{limited_warn, routing};

use crate::news::MAX_RESERVED_CELLS;
use crate::reserve::cells_along;

use super::shared::MapperShared;

/// A robot's new mission replaces its reservation ([`crate::news`]); an empty one
/// releases it.
pub(super) fn on_mission(state: &MapperShared, key: &str, mission: Mission) {
    let robot = match routing::robot_for(&state.root, key, &mission.robot) {
        Ok(robot) => robot,
        Err(e) => return limited_warn!(state.warnings, key, "ignoring a mission: {e}"),
    };
    if mission.waypoints.is_empty() {
        let mut m = state.mapping();
        if m.news.release(robot) {
            m.dirty = true;
        }
        return;
    }
    // The path's cells are found outside the lock: a long path on a large map takes a
    // while, and observations keep merging meanwhile.
    let (start_s, position, meta) = {
        let m = state.mapping();
        (m.now_s, m.positions.get(robot).copied(), m.meta)
    };
    let path: Vec<[f64; 2]> = position
        .into_iter()
        .chain(mission.waypoints.iter().copied())
        .collect();
    let reserved = cells_along(
        &meta,
        &path,
        start_s,
        state.reserve_s_per_m,
        state.reserve_radius_m,
        MAX_RESERVED_CELLS,
    )
    .and_then(|cells| {
        let mut m = state.mapping();
        if m.meta != meta {
            return Ok(0);
        }
        let count = m.news.reserve(robot, cells)?;
        m.dirty = true;
        Ok(count)
    });
    if let Err(e) = reserved {
        limited_warn!(state.warnings, robot, %robot, "no reservation for a mission: {e}");
    }
}
