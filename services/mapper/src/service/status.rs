//! The answer to `mapper/status`: counts, each explorer's goal and each reservation.

use std::sync::Arc;

use roam_proto::mapper::{ExplorerStatus, MapperStatus, ReservationStatus};
use roam_proto::ErrorReply;
use roam_runtime::reply;
use zenoh::query::Query;

use super::shared::MapperShared;

fn status(state: &MapperShared) -> MapperStatus {
    let m = state.mapping();
    MapperStatus {
        observations: m.observations,
        map_changes: m.map_changes,
        p: m.features.0,
        r: m.features.1,
        layers_sent: m.layers_sent,
        explorers: m
            .explorers
            .iter()
            .map(|(robot, e)| {
                let published = m.published_goals.get(robot);
                ExplorerStatus {
                    robot: robot.clone(),
                    strategy: published.map(|g| g.strategy.clone()),
                    goal: published.map(|g| g.goal),
                    episodes: e.episodes_ended(),
                }
            })
            .collect(),
        reservations: m
            .news
            .reserving_robots()
            .map(|robot| ReservationStatus {
                robot: robot.to_owned(),
                cells: m.news.reserved_cells(robot) as u64,
            })
            .collect(),
    }
}

pub(super) async fn answer_status(state: Arc<MapperShared>, query: Query) {
    let result: Result<MapperStatus, ErrorReply> = Ok(status(&state));
    reply::send_result(&query, result).await;
}
