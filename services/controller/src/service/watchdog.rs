//! The wall-time watchdog: robots whose estimates stop are held, then released.

use std::sync::Arc;
use std::time::Duration;

use roam_proto::controller::{ControllerStatus, MissionState};
use roam_proto::keys;
use tokio_util::sync::CancellationToken;

use super::shared::ControllerShared;

/// Holds every robot whose estimates have stopped: a zero command and `halted_stale`;
/// forgets a robot whose estimates have stopped for `release_after_s` (it is gone).
pub(super) async fn watchdog(state: Arc<ControllerShared>, cancel: CancellationToken) {
    let tick = (state.stale_after / 4).max(Duration::from_millis(5));
    loop {
        tokio::select! {
            _ = cancel.cancelled() => return,
            _ = tokio::time::sleep(tick) => {}
        }
        release_gone(&state);
        let halted: Vec<(String, ControllerStatus, bool)> = {
            let mut robots = state.robots();
            robots
                .iter_mut()
                .filter(|(_, d)| {
                    d.controller.is_active() && d.last_estimate.elapsed() >= state.stale_after
                })
                .filter_map(|(robot, d)| {
                    let first = !d.stale;
                    d.stale = true;
                    let mut status = d.last.clone()?;
                    status.state = MissionState::HaltedStale;
                    status.u = [0.0, 0.0];
                    Some((robot.clone(), status, first))
                })
                .collect()
        };
        for (robot, status, first) in halted {
            if first {
                tracing::warn!(%robot, "no estimate for {:?}: holding the robot", state.stale_after);
            }
            state.command(&robot, [0.0, 0.0], None);
            state.put(&keys::robot_controller(&state.root, &robot), &status);
        }
    }
}

/// Releases the slots of robots not heard from for `release_after`: a robot removed from
/// the world, or one that never was, stops costing a slot, commands and statuses.
fn release_gone(state: &ControllerShared) {
    let release_after = state.release_after;
    state.seen().retain(|_, t| t.elapsed() < release_after);
    roam_runtime::lock(&state.held).retain(|_, (t, _)| t.elapsed() < release_after);
    {
        let seen = state.seen();
        roam_runtime::lock(&state.answered).retain(|robot, _| seen.contains_key(robot));
    }
    let queued: Vec<String> = roam_runtime::lock(&state.queued).keys().cloned().collect();
    let gone: Vec<String> = queued
        .into_iter()
        .filter(|r| !state.is_present(r))
        .collect();
    if !gone.is_empty() {
        let mut queued = roam_runtime::lock(&state.queued);
        for robot in gone {
            queued.remove(&robot);
        }
    }
    state.robots().retain(|robot, d| {
        let keep = d.last_estimate.elapsed() < release_after;
        if !keep {
            tracing::info!(%robot, "no estimate for {release_after:?}: the robot is gone, its slot released");
        }
        keep
    });
}
