//! The mission executive on Zenoh: a client of the planner, the controller,
//! localization and the clock. One executive drives one robot through its tasks.
//!
//! | key | kind | payload |
//! |---|---|---|
//! | `<root>/map/layer/{inflated,information}` | get, at start | `layer` (to thin paths and score them) |
//! | `<root>/planner/…/plan` | get, one per plan (a window's first, a replan, the next window's; a second only when a curious replan fails) | `plan_request` (`shortest: fallback`) → `plan` (with the shortest path) |
//! | `<root>/robot/<id>/mission` | put, per plan | `mission` (the thinned waypoints) |
//! | `<root>/robot/<id>/estimate` | subscription | `position_estimate` |
//! | `<root>/robot/<id>/controller` | subscription | `controller_status` |
//! | `<root>/sim/clock` | subscription | `sim_clock` (the mission clock; wall time without a sim) |
//! | `<root>/map/{layer,delta}/<obstacles_layer>`, `<root>/map/layer/inflated` | subscription, and get at start and on the index's refresh (only with `obstacles_layer`) | `layer`, `layer_delta` (what the fleet believes occupied now: a route it blocks is replanned) |
//!
//! The window's rules live in a plain state machine ([`crate::window`], with the replan
//! policy in [`crate::watch`]); this module is the thin async loop around it: it decodes
//! what it hears, feeds the machine, and performs its actions (plan requests, one per
//! plan; missions published; progress; the calibration's file).
//!
//! **Time.** Task start times are on the mission clock: sim seconds when a sim world
//! publishes its clock. The planner's deadline is wall time, so what planning costs on
//! the mission clock is the deadline times the clock's measured rate (a sim running at
//! 20× charges a 0.5 s plan 10 s of downtime); the driving budget t_exec is the time to
//! the task's start minus that.
mod progress;
mod robot;
mod window_loop;

use std::sync::Arc;
use std::time::Duration;

use roam_planner::client::PlannerClient;
use roam_planner::params::GaParams;
use roam_runtime::Requester;
use tokio_util::sync::CancellationToken;

use crate::calibration::{store, Calibration, CalibrationConfig};
use crate::information::InformationScale;
use crate::inputs::{listen, wait_for_world};
use crate::window::Handover;
pub use crate::window::WindowOutcome;

pub use crate::config::ExecutiveConfig;

pub use crate::error::ExecutiveError;

pub use progress::Progress;
use robot::{Executive, Heard};

/// The robot's time calibration: from its file when one is configured and usable, else
/// Table I's prior.
fn load_calibration(config: &ExecutiveConfig) -> Result<Calibration, ExecutiveError> {
    let prior = config.time_model_prior;
    let settings = CalibrationConfig::default();
    let calibration = match &config.calibration_file {
        Some(path) => {
            let (calibration, loaded) = store::load(path, &config.robot, prior, settings)
                .map_err(|e| ExecutiveError::Config(e.to_string()))?;
            tracing::info!(path = %path.display(), ?loaded, model = ?calibration.model(), "time calibration");
            calibration
        }
        None => {
            Calibration::new(prior, settings).map_err(|e| ExecutiveError::Config(e.to_string()))?
        }
    };
    Ok(calibration)
}

/// Drives `config.robot` through its tasks and returns each window's outcome, calling
/// `on_window` as each one ends.
pub async fn run(
    session: &zenoh::Session,
    root: &str,
    config: &ExecutiveConfig,
    cancel: &CancellationToken,
    progress: &(dyn Fn(Progress) + Sync),
    on_window: &(dyn Fn(&WindowOutcome) + Sync),
) -> Result<Vec<WindowOutcome>, ExecutiveError> {
    config.check()?;
    let requester = Requester::new(session.clone(), Duration::from_secs(10));
    let world = wait_for_world(&requester, root, cancel).await?;
    // A day whose tasks are in walls or cannot be reached from each other in time is
    // refused before the robot moves, naming the tasks and the seconds missing.
    crate::day_check::check_day(&config.tasks, &world, config.time_model_prior, None)?;
    let params = GaParams::default();
    // The report's information is measured on the static map, as the driven path's: a
    // planner on the change coupling reports its own figure on the coupled map, which
    // changes with the mapper.
    let scale = InformationScale {
        world: &world,
        params: &params,
    };
    let inputs = listen(session, root, &config.robot).await?;
    let mut executive = Executive {
        session,
        root,
        config,
        // The robot's own plan keys: on a secure site its credentials reach no others.
        planner: Arc::new(PlannerClient::for_robot(
            session.clone(),
            root,
            &config.robot,
        )),
        inputs,
        position: None,
        calibration: load_calibration(config)?,
        plan_wall_s: None,
        replan_wall_s: None,
        handover: Handover::first(config.margin()),
        tag: session.zid().to_string().chars().take(8).collect(),
        heard: Heard::default(),
        obstacles: match &config.obstacles_layer {
            Some(layer) => Some(
                crate::obstacles::follow(
                    session,
                    root,
                    layer,
                    config.obstacle_inflation_m,
                    cancel.child_token(),
                )
                .await?,
            ),
            None => None,
        },
        resume: config
            .resume_file
            .as_deref()
            .and_then(|path| crate::resume::load(path, &config.robot)),
    };
    executive.hear_the_clock(cancel).await?;
    let mut outcomes = Vec::with_capacity(config.tasks.len());
    for (window, task) in config.tasks.iter().enumerate() {
        let next = config.tasks.get(window + 1);
        if let Some(outcome) = executive
            .window(window, task, next, scale, cancel, progress)
            .await?
        {
            on_window(&outcome);
            outcomes.push(outcome);
        }
    }
    Ok(outcomes)
}
