//! The role table: every service roam runs, what configures it, how it announces
//! itself and how it runs.
//!
//! A role is a service with its config: the map server, the planner, the sim,
//! localization, the controller, the mapper, the mission executive, and the ROS 2 node. The `roam` binary builds one from a config file
//! and its flags (`roam planner --config …`), [`crate::Stack`] builds one per service it
//! runs, and the integration tests build them from test configs; all three then start
//! it the same way: [`Role::run`] with a Zenoh config and a cancellation token, and
//! wait for [`Role::live_key`]. Adding a service means adding a variant here (and its
//! command-line flags in the binary).

use std::future::Future;
use std::pin::Pin;

use roam_controller::service::ControllerConfig;
use roam_localization::service::LocalizationConfig;
use roam_map_server::MapServerConfig;
use roam_mapper::service::MapperConfig;
use roam_mission::service::MissionConfig;
use roam_planner::PlannerConfig;
use roam_proto::keys;
use roam_ros2::node::Ros2Config;
use roam_sim::service::SimConfig;
use tokio_util::sync::CancellationToken;

/// What every role's config has: a key root, an instance name and a Zenoh section.
pub trait RoleConfig: serde::de::DeserializeOwned + Default {
    fn root(&self) -> &str;
    fn root_mut(&mut self) -> &mut String;
    fn instance(&self) -> Option<&str>;
    fn instance_mut(&mut self) -> &mut Option<String>;
    /// The config file's `zenoh:` section, a Zenoh config fragment.
    fn zenoh(&self) -> Option<&serde_json::Value>;
}

macro_rules! role_config {
    ($($config:ty),*) => {$(
        impl RoleConfig for $config {
            fn root(&self) -> &str {
                &self.service.root
            }
            fn root_mut(&mut self) -> &mut String {
                &mut self.service.root
            }
            fn instance(&self) -> Option<&str> {
                self.service.instance.as_deref()
            }
            fn instance_mut(&mut self) -> &mut Option<String> {
                &mut self.service.instance
            }
            fn zenoh(&self) -> Option<&serde_json::Value> {
                self.service.zenoh.as_ref()
            }
        }
    )*};
}

role_config!(
    MapServerConfig,
    PlannerConfig,
    SimConfig,
    LocalizationConfig,
    ControllerConfig,
    MapperConfig,
    MissionConfig,
    Ros2Config
);

/// One service of roam with its config.
#[derive(Debug, Clone)]
pub enum Role {
    MapServer(Box<MapServerConfig>),
    Planner(Box<PlannerConfig>),
    Sim(Box<SimConfig>),
    Localization(Box<LocalizationConfig>),
    Controller(Box<ControllerConfig>),
    Mapper(Box<MapperConfig>),
    Mission(Box<MissionConfig>),
    /// roam in a ROS 2 system over rmw_zenoh (`roam ros2`).
    Ros2(Box<Ros2Config>),
}

/// A running role: it ends with the service, with its error as text.
pub type RoleFuture = Pin<Box<dyn Future<Output = Result<(), String>> + Send + 'static>>;

/// Runs a role's config through the same body for every variant.
macro_rules! each_role {
    ($role:expr, $config:ident => $body:expr) => {
        match $role {
            Role::MapServer($config) => $body,
            Role::Planner($config) => $body,
            Role::Sim($config) => $body,
            Role::Localization($config) => $body,
            Role::Controller($config) => $body,
            Role::Mapper($config) => $body,
            Role::Mission($config) => $body,
            Role::Ros2($config) => $body,
        }
    };
}

/// Boxes a service's run future as a [`RoleFuture`].
fn boxed<E: std::fmt::Display>(
    run: impl Future<Output = Result<(), E>> + Send + 'static,
) -> RoleFuture {
    Box::pin(async move { run.await.map_err(|e| e.to_string()) })
}

impl Role {
    /// The service's name: its liveliness tokens' `<service>`, its command, and its
    /// credentials' user name on a secure site.
    pub fn name(&self) -> &'static str {
        match self {
            Role::MapServer(_) => roam_map_server::SERVICE_NAME,
            Role::Planner(_) => roam_planner::SERVICE_NAME,
            Role::Sim(_) => roam_sim::service::SERVICE_NAME,
            Role::Localization(_) => roam_localization::service::SERVICE_NAME,
            Role::Controller(_) => roam_controller::service::SERVICE_NAME,
            Role::Mapper(_) => roam_mapper::service::SERVICE_NAME,
            Role::Mission(_) => roam_mission::service::SERVICE_NAME,
            Role::Ros2(_) => roam_ros2::node::SERVICE_NAME,
        }
    }

    pub fn root(&self) -> &str {
        each_role!(self, c => c.root())
    }

    pub fn instance(&self) -> Option<&str> {
        each_role!(self, c => c.instance())
    }

    /// The config file's `zenoh:` section.
    pub fn zenoh(&self) -> Option<&serde_json::Value> {
        each_role!(self, c => c.zenoh())
    }

    /// Whether the role needs a sim world (robots, anchors): on a map alone the sim,
    /// localization and the controller have nothing to do.
    pub fn needs_sim_world(&self) -> bool {
        matches!(
            self,
            Role::Sim(_) | Role::Localization(_) | Role::Controller(_)
        )
    }

    /// The liveliness key to wait for: the instance's own token when the config names
    /// the instance, any instance of the service otherwise.
    pub fn live_key(&self) -> String {
        match self.instance() {
            Some(instance) => keys::liveliness(self.root(), self.name(), instance),
            None => keys::liveliness_of(self.root(), self.name()),
        }
    }

    /// Runs the service until `cancel` is cancelled (or it fails).
    pub fn run(self, zenoh: zenoh::Config, cancel: CancellationToken) -> RoleFuture {
        match self {
            Role::MapServer(c) => boxed(roam_map_server::run(*c, zenoh, cancel)),
            Role::Planner(c) => boxed(roam_planner::run(*c, zenoh, cancel)),
            Role::Sim(c) => boxed(roam_sim::service::run(*c, zenoh, cancel)),
            Role::Localization(c) => boxed(roam_localization::service::run(*c, zenoh, cancel)),
            Role::Controller(c) => boxed(roam_controller::service::run(*c, zenoh, cancel)),
            Role::Mapper(c) => boxed(roam_mapper::service::run(*c, zenoh, cancel)),
            Role::Mission(c) => boxed(roam_mission::service::run(*c, zenoh, cancel)),
            Role::Ros2(c) => boxed(roam_ros2::node::run(*c, zenoh, cancel)),
        }
    }
}

macro_rules! role_from {
    ($($variant:ident($config:ty)),*) => {$(
        impl From<$config> for Role {
            fn from(config: $config) -> Role {
                Role::$variant(Box::new(config))
            }
        }
    )*};
}

role_from!(
    MapServer(MapServerConfig),
    Planner(PlannerConfig),
    Sim(SimConfig),
    Localization(LocalizationConfig),
    Controller(ControllerConfig),
    Mapper(MapperConfig),
    Mission(MissionConfig),
    Ros2(Ros2Config)
);

#[cfg(test)]
mod tests {
    use super::*;
    use roam_runtime::service_config::ServiceConfig;

    #[test]
    fn a_named_instance_is_awaited_by_its_own_token() {
        let planner = Role::from(PlannerConfig {
            service: ServiceConfig {
                instance: Some("p-1".into()),
                ..ServiceConfig::at("r")
            },
            ..PlannerConfig::default()
        });
        assert_eq!(planner.name(), "planner");
        assert_eq!(planner.live_key(), keys::liveliness("r", "planner", "p-1"));
        let sim = Role::from(SimConfig {
            service: ServiceConfig::at("r"),
            ..SimConfig::default()
        });
        assert_eq!(sim.live_key(), keys::liveliness_of("r", "sim"));
    }

    /// Every role's config file takes the common fields beside its own and refuses a
    /// field it does not name, with the field's name: the flattened
    /// [`ServiceConfig`] does not let a typo through.
    #[test]
    fn every_role_config_takes_the_common_fields_and_refuses_a_typo() {
        use roam_runtime::config_file::parse;
        use std::path::Path;

        fn check<C: RoleConfig + serde::de::DeserializeOwned>(role: &str) {
            let path = Path::new("role.yaml");
            let text = "root: site\ninstance: one\nzenoh: { mode: client }\n";
            let config: C = parse(path, text).unwrap_or_else(|e| panic!("{role}: {e}"));
            assert_eq!(config.root(), "site", "{role}");
            assert_eq!(config.instance(), Some("one"), "{role}");
            assert_eq!(
                config.zenoh(),
                Some(&serde_json::json!({ "mode": "client" })),
                "{role}"
            );
            for typo in ["rot: site", "instnce: one", "zenho: {}"] {
                let e = parse::<C>(path, typo)
                    .err()
                    .unwrap_or_else(|| panic!("{role} took {typo}"));
                let name = typo.split(':').next().unwrap_or_default();
                assert!(
                    e.to_string().contains(&format!("unknown field `{name}`")),
                    "{role}: {e}"
                );
            }
        }
        check::<MapServerConfig>("map_server");
        check::<PlannerConfig>("planner");
        check::<SimConfig>("sim");
        check::<LocalizationConfig>("localization");
        check::<ControllerConfig>("controller");
        check::<MapperConfig>("mapper");
        check::<MissionConfig>("mission");
        check::<Ros2Config>("ros2");
    }
}
