//! What the sim's control queryable, command subscriber and free run share, and the
//! status it answers with.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::{Mutex, MutexGuard};

use roam_proto::sim::{PendingCommand, RobotCommand, SimStatus};
use roam_runtime::warn_limit::WarnLimiter;
use roam_world::load_dirs::LoadDirs;

use crate::messages::points;
use crate::sim::Sim;

/// The scenario as a status names it to any peer: its file name, never a path on the
/// sim's machine (the built-in world's name has no folder, so it stays as it is).
fn shown_name(scenario: &str) -> String {
    Path::new(scenario)
        .file_name()
        .map_or_else(|| scenario.to_owned(), |n| n.to_string_lossy().into_owned())
}

/// What control requests change.
pub(super) struct Control {
    pub(super) sim: Sim,
    pub(super) scenario: String,
    pub(super) running: bool,
    pub(super) rate: f64,
    /// The latest command per robot, taken by the next step.
    pub(super) pending: BTreeMap<String, RobotCommand>,
    pub(super) late_steps: u64,
    pub(super) free_steps: u64,
    /// The ids of the objects landed at the last `sim/objects` message: the next goes
    /// out when they differ.
    pub(super) objects_published: Vec<u64>,
}

/// What the sim's control queryable, command subscriber and free run share.
pub(super) struct SimShared {
    pub(super) root: String,
    pub(super) session: zenoh::Session,
    pub(super) control: Mutex<Control>,
    pub(super) load_dirs: LoadDirs,
    /// Held by whoever steps and publishes (the free run, one `step` request), so the
    /// messages of two steps never interleave and two lock-step drivers cannot pile up.
    pub(super) stepper: tokio::sync::Mutex<()>,
    /// Held by the step request being served: a second one is told `busy` at once,
    /// while one that only meets the free run's last step (just paused) waits for it.
    pub(super) step_request: tokio::sync::Mutex<()>,
    /// Woken by every control request, so the free run sees a pause, a new rate or a
    /// reset at once instead of after the sleep it was in.
    pub(super) wake: tokio::sync::Notify,
    /// Refused commands, logged a few per robot and window.
    pub(super) warnings: WarnLimiter,
}

impl SimShared {
    pub(super) fn control(&self) -> MutexGuard<'_, Control> {
        roam_runtime::lock(&self.control)
    }

    pub(super) fn status(&self) -> SimStatus {
        let c = self.control();
        let (robots, anchors) = points(&c.sim);
        SimStatus {
            scenario: shown_name(&c.scenario),
            seed: c.sim.seed(),
            step: c.sim.steps(),
            time_s: c.sim.time_s(),
            running: c.running,
            rate: c.rate,
            step_s: c.sim.params().time.step_s,
            late_steps: c.late_steps,
            free_steps: c.free_steps,
            robots,
            anchors,
            pending: c
                .pending
                .iter()
                .map(|(robot, command)| PendingCommand {
                    robot: robot.clone(),
                    step: command.step,
                })
                .collect(),
        }
    }
}
