//! One step: the commands pending for it, the step under the lock, and its messages
//! published once the lock is released.

use roam_proto::sim::{ObjectsTruth, RobotCommand, SimClock};
use roam_proto::{decode, keys, ErrorReply, Message};
use roam_runtime::Delivery;

use crate::messages::{robot_messages, RobotMessages};
use crate::semi_static::landed_truth;
use crate::sim::Command;

use super::limits::MAX_COMMAND_BYTES;
use super::replies::sim_error;
use super::shared::SimShared;

/// Stores a command for the next step; commands for unknown robots or with non-finite
/// values are dropped (logged), so the pending map never outgrows the robots.
pub(super) fn take_command(state: &SimShared, key: &str, payload: &[u8]) {
    let Some(robot) = keys::robot_of(&state.root, key) else {
        return;
    };
    if payload.len() > MAX_COMMAND_BYTES {
        return roam_runtime::limited_warn!(
            state.warnings, robot, %robot, bytes = payload.len(),
            "dropping a command over {MAX_COMMAND_BYTES} bytes unread"
        );
    }
    let command = match decode::<RobotCommand>(payload) {
        Ok(c) if c.u.iter().all(|v| v.is_finite()) => c,
        Ok(c) => {
            return roam_runtime::limited_warn!(
                state.warnings, robot, %robot, u = ?c.u, "dropping a command that is not finite"
            )
        }
        Err(e) => {
            return roam_runtime::limited_warn!(
                state.warnings, robot, %robot, "dropping a command that does not decode: {e}"
            )
        }
    };
    let mut control = state.control();
    if control.sim.robot(robot).is_some() {
        control.pending.insert(robot.to_owned(), command);
    } else {
        tracing::debug!(%robot, "dropping a command for a robot the sim does not have");
    }
}

/// What one step has to publish once the lock is released.
pub(super) struct Stepped {
    clock: SimClock,
    robots: Vec<RobotMessages>,
    /// The landed objects, when one landed or left in the step.
    objects: Option<ObjectsTruth>,
}

/// One step under the lock; returns the messages to publish after it is released.
pub(super) fn step_once(state: &SimShared) -> Result<Stepped, ErrorReply> {
    let mut control = state.control();
    let commands: Vec<Command> = std::mem::take(&mut control.pending)
        .into_iter()
        .map(|(robot, c)| Command { robot, u: c.u })
        .collect();
    let report = control.sim.step(&commands).map_err(|e| sim_error(&e))?;
    let clock = SimClock {
        step: report.step,
        time_s: report.time_s,
    };
    let messages = report
        .robots
        .iter()
        .map(|r| robot_messages(&control.sim, report.step, report.time_s, r))
        .collect();
    let landed = landed_truth(control.sim.world().objects());
    let objects = (!landed
        .iter()
        .map(|o| o.id)
        .eq(control.objects_published.iter().copied()))
    .then(|| {
        control.objects_published = landed.iter().map(|o| o.id).collect();
        ObjectsTruth {
            step: report.step,
            time_s: report.time_s,
            objects: landed,
        }
    });
    Ok(Stepped {
        clock,
        robots: messages,
        objects,
    })
}

/// Every reading of a step is delivered: a robot's localization and controller run in
/// lock-step on them.
async fn put<T: Message>(state: &SimShared, key: &str, message: &T) {
    roam_runtime::publish(&state.session, key, message, Delivery::Reliable).await;
}

pub(super) async fn publish(state: &SimShared, stepped: Stepped) {
    let root = &state.root;
    let Stepped {
        clock,
        robots,
        objects,
    } = stepped;
    if let Some(objects) = &objects {
        put(state, &keys::sim_objects(root), objects).await;
    }
    for m in robots {
        let robot = m.truth.robot.clone();
        put(state, &keys::robot_ranges(root, &robot), &m.ranges).await;
        put(state, &keys::robot_truth(root, &robot), &m.truth).await;
        if let Some(o) = &m.observation {
            put(state, &keys::robot_observation(root, &robot), o).await;
        }
        if let Some(e) = &m.events {
            put(state, &keys::robot_events(root, &robot), e).await;
        }
    }
    put(state, &keys::sim_clock(root), &clock).await;
}
