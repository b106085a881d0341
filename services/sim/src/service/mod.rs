//! The sim world on Zenoh: a thin adapter around [`Sim`].
//!
//! | key | kind | payload |
//! |---|---|---|
//! | `<root>/sim/control` | queryable | `sim_control` → `sim_status` |
//! | `<root>/sim/clock` | publication, every step | `sim_clock` |
//! | `<root>/robot/*/cmd` | subscription | `robot_command` (applies to the next step) |
//! | `<root>/robot/<id>/{ranges,observation,truth,events}` | publications, every step | `range_scan`, `observation`, `ground_truth`, `robot_events` |
//!
//! Two ways to run: free at a real-time factor (`resume`), or in lock-step, where each
//! `step` request runs n steps and answers once their messages are published. Commands
//! are taken by a callback subscriber the moment they arrive, so a command put before
//! a `step` request from the same session is in that step: lock-step runs are
//! reproducible through the service, bit for bit.

mod config;
mod control;
mod free_run;
mod limits;
mod replies;
mod shared;
mod snapshots;
mod step;

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};

use roam_proto::keys;
use roam_runtime::warn_limit::WarnLimiter;
use roam_runtime::{Service, ServiceError};
use roam_world::load_dirs::LoadDirs;
use roam_world::scenario;
use tokio_util::sync::CancellationToken;

use crate::sim::Sim;

use control::answer_control;
use free_run::free_run;
use limits::check_rate;
use shared::{Control, SimShared};
use snapshots::{keep_snapshots, resume_from};
use step::take_command;

pub use config::{SimConfig, SimServiceError};
pub use limits::{
    MAX_COMMAND_BYTES, MAX_RATE, MAX_REQUEST_BYTES, MAX_ROBOT_STEPS_PER_REQUEST,
    MAX_STEPS_PER_REQUEST, MIN_RATE, SNAPSHOT_PERIOD,
};

pub const SERVICE_NAME: &str = "sim";

/// Runs the sim until `cancel` is cancelled.
pub async fn run(
    config: SimConfig,
    zenoh_config: zenoh::Config,
    cancel: CancellationToken,
) -> Result<(), SimServiceError> {
    if let Some(rate) = config.rate {
        check_rate(rate).map_err(|e| SimServiceError::Config(e.message))?;
    }
    let load_dirs =
        LoadDirs::new(&config.load_dirs).map_err(|e| SimServiceError::Config(e.to_string()))?;
    let (name, scenario) = scenario::load_or_builtin(config.scenario.as_deref())?;
    let mut sim = Sim::new(&scenario, config.seed)?;
    if let Some(path) = &config.state_file {
        resume_from(&mut sim, &name, config.seed, path)?;
    }
    let mut service = Service::start(SERVICE_NAME, &config.service, zenoh_config, cancel).await?;
    service.guard_world(roam_world::world_id::of_scenario(&scenario));
    let state = Arc::new(SimShared {
        root: config.service.root.clone(),
        session: service.session().clone(),
        control: Mutex::new(Control {
            sim,
            scenario: name,
            running: config.rate.is_some(),
            rate: config.rate.unwrap_or(1.0),
            pending: BTreeMap::new(),
            late_steps: 0,
            free_steps: 0,
            objects_published: Vec::new(),
        }),
        load_dirs,
        stepper: tokio::sync::Mutex::new(()),
        step_request: tokio::sync::Mutex::new(()),
        wake: tokio::sync::Notify::new(),
        warnings: WarnLimiter::new(),
    });

    // Commands: a callback, so a command is pending as soon as it arrives (the status names
    // it, for a lock-step driver: a command and a step request from another session
    // arrive in no promised order).
    let command_key = keys::robot_command_any(&config.service.root);
    let commands = {
        let state = state.clone();
        service
            .session()
            .declare_subscriber(&command_key)
            .callback(move |sample| {
                take_command(
                    &state,
                    sample.key_expr().as_str(),
                    &sample.payload().to_bytes(),
                )
            })
            .await
            .map_err(|e| ServiceError::Declare {
                what: "subscriber",
                key: command_key.clone(),
                reason: e.to_string(),
            })?
    };

    let control = service
        .declare_queryable(&keys::sim_control(&config.service.root))
        .await?;
    service.serve(control, state.clone(), |s, q| async move {
        answer_control(s, q).await
    });
    {
        let (state, cancel) = (state.clone(), service.cancel_token());
        service.spawn(async move { free_run(state, cancel).await });
    }
    if let Some(path) = config.state_file.clone() {
        let (state, cancel) = (state.clone(), service.cancel_token());
        service.spawn(async move { keep_snapshots(state, path, cancel).await });
    }
    service.announce().await?;
    service.cancelled().await;
    drop(commands);
    service
        .shutdown(roam_runtime::service::DEFAULT_GRACE)
        .await?;
    Ok(())
}
