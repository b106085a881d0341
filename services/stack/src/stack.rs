//! `roam stack`: every landed service in one process around an in-process router on
//! loopback, multicast off. The same shape as a compose stack, so what works here works
//! across machines: the map server, the planner, the sim world (free-running at 1x on the
//! built-in world), localization, the APF controller (drives a robot once it is given a
//! mission) and the change-rate mapper (maps; drives no robot unless configured to).
//!
//! One stack runs one world: the map or scenario it is given goes to every service. A
//! ROS map has no sim world (no robots, no anchors), so on one the stack runs what makes
//! sense on a map alone (the map server, the planners and the mapper, at the map's size)
//! and says which services it left out ([`Stack::left_out`]).

use std::path::PathBuf;
use std::time::Duration;

use roam_controller::service::ControllerConfig;
use roam_localization::service::LocalizationConfig;
use roam_map_server::MapServerConfig;
use roam_mapper::service::MapperConfig;
use roam_planner::coupling::Coupling;
use roam_planner::PlannerConfig;
use roam_proto::keys;
use roam_runtime::service_config::ServiceConfig;
use roam_runtime::{wait_for_liveliness, LivelinessWait, SessionArgs};
use roam_sim::service::SimConfig;
use tokio::task::JoinSet;
use tokio_util::sync::CancellationToken;

use crate::roles::Role;
use crate::router::Router;

/// What the stack runs on.
#[derive(Debug, Clone, Default)]
pub struct StackOptions {
    pub root: Option<String>,
    /// A ROS map or scenario for every service; the built-in world when absent.
    pub map: Option<PathBuf>,
    /// Where the map server persists its layers; in memory when absent.
    pub data_dir: Option<PathBuf>,
    /// Where the map server's and the sim's `load` requests may read; none: loads off.
    pub load_dirs: Vec<PathBuf>,
    /// The router's endpoint, e.g. `tcp/127.0.0.1:7447`; a free loopback port when absent.
    pub listen: Option<String>,
    /// Planner instances to run (default 1).
    pub planners: usize,
    /// The sim's real-time factor (default 1; 0 runs as fast as possible).
    pub sim_rate: Option<f64>,
    /// The controller's parameters (default: paper 002's).
    pub apf: Option<roam_controller::params::ApfParams>,
    /// How the planners couple the mapper's layers into the information map: `max`
    /// (default; the change coupling, on `change_information`) or `news` (interest × the
    /// probability of news, on the mapper's `news` layer: a fleet's).
    pub coupling: Coupling,
    /// The planners plan around what the fleet has seen occupied (the mapper's
    /// `occupied_now`; `roam_planner::seen`).
    pub avoid_seen: bool,
    /// Run the ROS 2 node too (`roam ros2`: roam's topics and services on rmw_zenoh's
    /// keys, through the stack's router); its `root` is the stack's.
    pub ros2: Option<roam_ros2::node::Ros2Config>,
}

impl StackOptions {
    /// The roles the stack runs on a world with a sim world, in start order: the map
    /// server, the planners (on the change coupling: the stack runs the mapper), the
    /// sim (free-running), localization, the controller, the mapper, and the ROS 2 node
    /// when asked for.
    pub fn roles(&self, root: &str) -> Vec<Role> {
        let mut roles = vec![Role::from(MapServerConfig {
            service: ServiceConfig::at(root),
            map: self.map.clone(),
            data_dir: self.data_dir.clone(),
            load_dirs: self.load_dirs.clone(),
            ..MapServerConfig::default()
        })];
        roles.extend((0..self.planners.max(1)).map(|index| {
            Role::from(PlannerConfig {
                service: ServiceConfig {
                    instance: Some(format!("planner-{index}")),
                    ..ServiceConfig::at(root)
                },
                change_layer: Some(
                    match self.coupling {
                        Coupling::Max => roam_proto::mapper::CHANGE_INFORMATION_LAYER,
                        Coupling::News => roam_proto::mapper::NEWS_LAYER,
                    }
                    .to_owned(),
                ),
                coupling: self.coupling,
                obstacles_layer: self
                    .avoid_seen
                    .then(|| roam_proto::mapper::OCCUPIED_NOW_LAYER.to_owned()),
                ..PlannerConfig::default()
            })
        }));
        roles.push(Role::from(SimConfig {
            service: ServiceConfig::at(root),
            scenario: self.map.clone(),
            rate: Some(self.sim_rate.unwrap_or(1.0)),
            load_dirs: self.load_dirs.clone(),
            ..SimConfig::default()
        }));
        roles.push(Role::from(LocalizationConfig {
            service: ServiceConfig::at(root),
            scenario: self.map.clone(),
            ..LocalizationConfig::default()
        }));
        roles.push(Role::from(ControllerConfig {
            service: ServiceConfig::at(root),
            scenario: self.map.clone(),
            apf: self.apf.clone().unwrap_or_default(),
            ..ControllerConfig::default()
        }));
        roles.push(Role::from(MapperConfig {
            service: ServiceConfig::at(root),
            scenario: self.map.clone(),
            ..MapperConfig::default()
        }));
        if let Some(ros2) = &self.ros2 {
            let mut ros2 = ros2.clone();
            ros2.service.root = root.to_owned();
            roles.push(Role::from(ros2));
        }
        roles
    }
}

#[derive(Debug, thiserror::Error)]
pub enum StackError {
    #[error("the in-process router could not start: {0}")]
    Router(#[from] roam_runtime::SessionError),
    #[error("{service} did not announce itself within {timeout:?}")]
    NotUp {
        service: &'static str,
        timeout: Duration,
    },
    #[error("{service} stopped: {reason}")]
    Failed {
        service: &'static str,
        reason: String,
    },
    #[error("watching liveliness failed: {0}")]
    Liveliness(String),
    /// The scenario's error is in the message and not a `source`: the binary prints the
    /// whole chain (`{:#}`), which would say it twice.
    #[error("the stack's world cannot be read: {0}")]
    World(roam_world::scenario::ScenarioError),
}

impl From<roam_world::scenario::ScenarioError> for StackError {
    fn from(e: roam_world::scenario::ScenarioError) -> Self {
        StackError::World(e)
    }
}

type ServiceTasks = JoinSet<(&'static str, Result<(), String>)>;

/// A running stack.
#[derive(Debug)]
pub struct Stack {
    pub router: Router,
    pub root: String,
    cancel: CancellationToken,
    /// Each service task returns its own name with its outcome.
    services: ServiceTasks,
    /// The services not run on this world, each with why.
    pub left_out: Vec<(&'static str, String)>,
}

impl Stack {
    /// Starts the router and every service, and waits until each holds its liveliness
    /// token (up to `timeout`).
    pub async fn start(options: StackOptions, timeout: Duration) -> Result<Stack, StackError> {
        let router = match &options.listen {
            Some(endpoint) => {
                Router::start(&SessionArgs::router_on(endpoint), endpoint.clone()).await?
            }
            None => Router::on_loopback().await?,
        };
        let root = options
            .root
            .clone()
            .unwrap_or_else(|| keys::DEFAULT_ROOT.to_owned());
        let cancel = CancellationToken::new();
        let client = SessionArgs::client_of(&router.endpoint);
        let mut services = JoinSet::new();

        let (_, world) = roam_world::scenario::load_or_builtin(options.map.as_deref())?;
        let mut left_out = Vec::new();
        let roles = if world.has_sim_world() {
            options.roles(&root)
        } else {
            let why = format!(
                "world '{}' is a map alone: no robots and no anchors to simulate, localize or drive",
                world.file.name
            );
            let (kept, dropped): (Vec<Role>, Vec<Role>) = options
                .roles(&root)
                .into_iter()
                .partition(|role| !role.needs_sim_world());
            left_out.extend(dropped.iter().map(|role| (role.name(), why.clone())));
            kept
        };
        let mut running = Vec::with_capacity(roles.len());
        for role in roles {
            let (name, live_key) = (role.name(), role.live_key());
            let run = role.run(client.zenoh_config(None)?, cancel.child_token());
            services.spawn(async move { (name, run.await) });
            running.push((name, live_key));
        }

        let mut stack = Stack {
            router,
            root,
            cancel,
            services,
            left_out,
        };
        for (service, live_key) in running {
            let session = stack.router.session.clone();
            let live = wait_until_key(&session, &live_key, service, timeout);
            tokio::select! {
                outcome = live => if let Err(e) = outcome {
                    stack.cancel.cancel();
                    return Err(e);
                },
                // A service that fails at start reports its own reason.
                Some((name, reason)) = stack.next_stopped() => {
                    stack.cancel.cancel();
                    return Err(StackError::Failed { service: name, reason });
                }
            }
        }
        Ok(stack)
    }

    /// Resolves when a service stops by itself, with its name and why; `None` when no
    /// service is left.
    pub async fn next_stopped(&mut self) -> Option<(&'static str, String)> {
        let joined = self.services.join_next().await?;
        Some(match joined {
            Ok((name, Ok(()))) => (name, "stopped".to_owned()),
            Ok((name, Err(reason))) => (name, reason),
            Err(e) => ("a service", format!("panicked: {e}")),
        })
    }

    /// Stops every service (each with its own grace period), then the router.
    pub async fn shutdown(mut self) -> Result<(), StackError> {
        self.cancel.cancel();
        let mut first_error = None;
        let deadline = tokio::time::Instant::now() + Duration::from_secs(5);
        loop {
            match tokio::time::timeout_at(deadline, self.services.join_next()).await {
                Ok(None) => break,
                Ok(Some(Ok((_, Ok(()))))) => {}
                Ok(Some(Ok((service, Err(reason))))) => {
                    first_error.get_or_insert(StackError::Failed { service, reason });
                }
                Ok(Some(Err(e))) => {
                    first_error.get_or_insert(StackError::Failed {
                        service: "a service",
                        reason: format!("panicked: {e}"),
                    });
                }
                Err(_) => {
                    self.services.abort_all();
                    first_error.get_or_insert(StackError::Failed {
                        service: "the stack",
                        reason: "services did not stop within 5 s".into(),
                    });
                    break;
                }
            }
        }
        self.router.close().await;
        first_error.map_or(Ok(()), Err)
    }
}

/// Waits for `<root>/@live/<service>/*` to appear.
pub async fn wait_until_live(
    session: &zenoh::Session,
    root: &str,
    service: &'static str,
    timeout: Duration,
) -> Result<(), StackError> {
    wait_until_key(
        session,
        &keys::liveliness_of(root, service),
        service,
        timeout,
    )
    .await
}

/// Waits for a liveliness token on `live_key` (a service's, [`Role::live_key`]).
async fn wait_until_key(
    session: &zenoh::Session,
    live_key: &str,
    service: &'static str,
    timeout: Duration,
) -> Result<(), StackError> {
    wait_for_liveliness(session, live_key, timeout)
        .await
        .map_err(|e| match e {
            LivelinessWait::Timeout => StackError::NotUp { service, timeout },
            LivelinessWait::Zenoh(reason) => StackError::Liveliness(reason),
        })
}
