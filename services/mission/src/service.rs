//! `roam mission`: the executive as a service. It announces itself, drives its robot
//! through the configured tasks, publishes a `window_report` on
//! `<root>/robot/<id>/mission_report` as each window ends, and stays up (answering to
//! liveliness) until it is stopped.

use roam_runtime::Delivery;
use std::path::PathBuf;

use roam_proto::keys;
use roam_runtime::service_config::{ServiceConfig, UnknownFields};
use roam_runtime::{Service, ServiceError};
use serde::Deserialize;
use tokio_util::sync::CancellationToken;

use crate::executive::{self, ExecutiveConfig, ExecutiveError, Progress};

pub const SERVICE_NAME: &str = "mission";

/// The mission service's config file (YAML).
///
/// ```yaml
/// root: roam
/// executive:
///   robot: robot
///   tasks:
///     - { name: goal1, at: [-2.0, 4.0], start_s: 75.0 }
///     - { name: goal2, at: [6.0, -7.0], start_s: 165.0, duration_s: 5.0 }
///   model: model1        # model0 | model1 | model2 | greedy | shortest
///   plan_deadline_s: 1.0
///   w_loc: 2000          # the PEB localizability cost in the planner's fitness (default off)
///   peb_free_m: 0.5      # the PEB (m) that cost forgives (default 0: every decimetre costs)
/// ```
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default)]
pub struct MissionConfig {
    /// `root`, `instance` and `zenoh`, as every service names them.
    #[serde(flatten)]
    pub service: ServiceConfig,
    pub executive: ExecutiveConfig,
    /// Unused here; kept so every role's config has the same shape.
    pub scenario: Option<PathBuf>,
    /// Refuses a field this config does not name.
    #[serde(flatten)]
    pub unknown: UnknownFields,
}

impl Default for MissionConfig {
    fn default() -> Self {
        MissionConfig {
            service: ServiceConfig::default(),
            executive: ExecutiveConfig::default(),
            scenario: None,
            unknown: UnknownFields,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum MissionServiceError {
    #[error(transparent)]
    Service(#[from] ServiceError),
    #[error(transparent)]
    Executive(#[from] ExecutiveError),
}

fn log(p: Progress) {
    match p {
        Progress::Planned {
            window,
            task,
            budget_s,
            eta_s,
            curious,
            late_probability,
        } => tracing::info!(
            window, %task, budget_s, eta_s, curious, late_probability, "planned"
        ),
        Progress::Replanned { window, reason } => tracing::info!(window, %reason, "replanned"),
        Progress::Recovering { window, held_s } => {
            tracing::warn!(
                window,
                held_s,
                "held for the PEB: driving back to the last fix"
            )
        }
        Progress::Arrived {
            window,
            task,
            at_s,
            start_s,
        } => {
            tracing::info!(window, %task, at_s, start_s, "arrived")
        }
        Progress::GaveUp { window, task } => tracing::warn!(window, %task, "gave up"),
        Progress::Skipped { window, task } => {
            tracing::warn!(window, %task, "skipped: the task was over before its window began")
        }
        Progress::Answered {
            window,
            model,
            took_s,
            replan,
        } => tracing::debug!(
            window,
            model = model.as_str(),
            took_s,
            replan,
            "plan answered"
        ),
    }
}

/// Runs the executive as a service until its tasks are done and `cancel` is cancelled.
pub async fn run(
    config: MissionConfig,
    zenoh_config: zenoh::Config,
    cancel: CancellationToken,
) -> Result<(), MissionServiceError> {
    crate::tasks::check(&config.executive.tasks).map_err(ExecutiveError::from)?;
    let mut service =
        Service::start(SERVICE_NAME, &config.service, zenoh_config, cancel.clone()).await?;
    service.announce().await?;
    let session = service.session().clone();
    let key = keys::robot_mission_report(&config.service.root, &config.executive.robot);
    let publish = |outcome: &executive::WindowOutcome| {
        roam_runtime::publish_wait(&session, &key, &outcome.report, Delivery::Reliable);
    };
    match executive::run(
        &session,
        &config.service.root,
        &config.executive,
        &cancel,
        &log,
        &publish,
    )
    .await
    {
        Ok(_) | Err(ExecutiveError::Cancelled) => {}
        Err(e) => {
            service
                .shutdown(roam_runtime::service::DEFAULT_GRACE)
                .await?;
            return Err(e.into());
        }
    }
    service.run_until_stopped().await?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shipped_config_is_the_builtin_day() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/mission.yaml");
        let config: MissionConfig = roam_runtime::config_file::load(&path).expect("parses");
        assert_eq!(config.executive.tasks, crate::tasks::builtin());
        assert_eq!(config.executive.robot, "robot");
    }
}
