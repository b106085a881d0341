//! Observations merged into the map, and the command and goal each one gives a robot
//! the learner drives.

use roam_proto::cells::Cells;
use roam_proto::keys;
use roam_proto::map::GridMeta;
use roam_proto::mapper::ExplorationGoal;
use roam_proto::sim::{LocalObservation, RobotCommand};
use roam_runtime::{limited_warn, routing};

use crate::change_map::ObservationWindow;
use crate::news::MAX_RESERVING_ROBOTS;

use super::shared::MapperShared;

/// Why an observation cannot be merged (logged; a subscriber has no one to answer).
fn check_observation(meta: &GridMeta, o: &LocalObservation) -> Result<(), String> {
    if (o.meta.resolution - meta.resolution).abs() > 1e-9 * meta.resolution {
        return Err(format!(
            "its resolution {} m differs from the map's {} m",
            roam_proto::number(o.meta.resolution),
            meta.resolution
        ));
    }
    let (x1, y1) = (
        u64::from(o.x0) + u64::from(o.meta.width),
        u64::from(o.y0) + u64::from(o.meta.height),
    );
    if x1 > u64::from(meta.width) || y1 > u64::from(meta.height) {
        return Err(format!(
            "its window ends at cell ({x1}, {y1}), outside the {} x {} map",
            meta.width, meta.height
        ));
    }
    match &o.cells {
        Cells::I8(c) if c.len() as u64 == u64::from(o.meta.width) * u64::from(o.meta.height) => {
            Ok(())
        }
        Cells::I8(c) => Err(format!(
            "it has {} cells for a {} x {} window",
            c.len(),
            o.meta.width,
            o.meta.height
        )),
        _ => Err("its cells are not i8 occupancy values".to_owned()),
    }
}

fn cell_centre(meta: &GridMeta, (x, y): (u32, u32)) -> [f64; 2] {
    [
        meta.origin.x + (f64::from(x) + 0.5) * meta.resolution,
        meta.origin.y + (f64::from(y) + 0.5) * meta.resolution,
    ]
}

pub(super) fn on_observation(state: &MapperShared, key: &str, o: LocalObservation) {
    let robot = match routing::robot_for(&state.root, key, &o.robot) {
        Ok(robot) => robot,
        Err(e) => return limited_warn!(state.warnings, key, "ignoring an observation: {e}"),
    };
    let meta = state.mapping().meta;
    if let Err(e) = check_observation(&meta, &o) {
        return limited_warn!(state.warnings, robot, %robot, step = o.step, "ignoring an observation: {e}");
    }
    let Some(window) = ObservationWindow::from_wire(&o) else {
        return;
    };
    let out = {
        let mut guard = state.mapping();
        let m = &mut *guard;
        if m.meta != meta {
            // The map server moved to another world meanwhile.
            return;
        }
        let t = match m.epochs.observation_time(o.time_s) {
            Ok(t) => t,
            Err(e) => {
                return limited_warn!(state.warnings, robot, %robot, "ignoring an observation: {e}");
            }
        };
        let update = match m.map.observe(&window, t) {
            Ok(u) => u,
            Err(e) => {
                return limited_warn!(state.warnings, robot, %robot, "ignoring an observation: {e}");
            }
        };
        m.epochs.accepted(t);
        m.observations += 1;
        if m.positions.len() < MAX_RESERVING_ROBOTS || m.positions.contains_key(robot) {
            m.positions.insert(robot.to_owned(), o.at);
        }
        m.map_changes += update.map_changes(true) as u64;
        m.now_s = m.now_s.max(t);
        m.dirty = true;
        let features = m.map.features(t);
        m.features = (features.p, features.r);
        match (m.explorers.get_mut(robot), m.map.cell_of(o.at)) {
            (Some(explorer), Some(cell)) => {
                match explorer.on_update(&mut m.map, &update, cell, t) {
                    Ok(step) => {
                        let at = cell_centre(&m.meta, step.episode_goal);
                        let strategy = step.strategy.as_str().to_owned();
                        let episodes = explorer.episodes_ended();
                        let fresh = m.published_goals.get(robot).is_none_or(|last| {
                            last.goal != at
                                || last.strategy != strategy
                                || last.episodes != episodes
                        });
                        let goal = fresh.then(|| {
                            let goal = ExplorationGoal {
                                robot: robot.to_owned(),
                                step: o.step,
                                time_s: o.time_s,
                                goal: at,
                                strategy,
                                episodes,
                            };
                            m.published_goals.insert(robot.to_owned(), goal.clone());
                            goal
                        });
                        Some((step.u, goal))
                    }
                    Err(e) => {
                        limited_warn!(state.warnings, robot, %robot, "no exploration step: {e}");
                        None
                    }
                }
            }
            _ => None,
        }
    };
    if let Some((u, goal)) = out {
        state.put(
            &keys::robot_command(&state.root, robot),
            &RobotCommand {
                u,
                step: Some(o.step),
            },
        );
        if let Some(goal) = goal {
            state.put(&keys::robot_goal(&state.root, robot), &goal);
        }
    }
}
