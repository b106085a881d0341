//! The integration harness: real services in-process around a real router on
//! loopback, used only through Zenoh, as a client on another machine would.
//!
//! Each test gets its own router on a free port, multicast scouting off, and its own
//! key root, so tests run in parallel without seeing each other. Services are awaited
//! by liveliness, never by sleeping, and every await has a timeout.

pub mod lockstep;

use std::future::IntoFuture;
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

use roam_controller::service::ControllerConfig;
use roam_localization::service::LocalizationConfig;
use roam_map_server::MapServerConfig;
use roam_mapper::service::MapperConfig;
use roam_planner::PlannerConfig;
use roam_proto::keys;
use roam_runtime::service_config::ServiceConfig;
use roam_runtime::wait_for_liveliness;
use roam_runtime::{Requester, SessionArgs};
use roam_sim::service::SimConfig;
use roam_stack::router::Router;
use roam_stack::Role;
use tokio::task::JoinHandle;
use tokio_util::sync::CancellationToken;

/// How long any single step of a test may take before it fails.
pub const STEP: Duration = Duration::from_secs(10);

/// Awaits `future` for at most [`STEP`], failing the test with `what` otherwise.
pub async fn within<F: IntoFuture>(what: &str, future: F) -> F::Output {
    match tokio::time::timeout(STEP, future).await {
        Ok(value) => value,
        Err(_) => panic!("timed out after {STEP:?}: {what}"),
    }
}

/// A path in the repository (tests run from the `tests/` crate).
pub fn repo_path(relative: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(relative)
}

/// A router and a unique key root for one test.
#[derive(Debug)]
pub struct Harness {
    pub router: Router,
    pub root: String,
    /// On a secure site ([`Harness::start_secure`]), the Zenoh config of each role; the
    /// services a harness starts then open their sessions as their own role.
    site: Option<SecureSite>,
}

/// The client side of a secure site: the Zenoh config a session without credentials
/// uses (TLS to the router, nothing else) and one config per role (the same plus the
/// role's user name and password), keyed by role name (`map-server`, `sim`, ...).
#[derive(Debug, Clone)]
pub struct SecureSite {
    pub anonymous: zenoh::Config,
    pub roles: std::collections::BTreeMap<String, zenoh::Config>,
}

/// A service running in this process.
#[derive(Debug)]
pub struct RunningService {
    cancel: CancellationToken,
    handle: JoinHandle<Result<(), String>>,
}

impl RunningService {
    /// Cancels the service and waits until it has stopped; returns how long that took
    /// and what the service returned.
    pub async fn stop(self) -> (Duration, Result<(), String>) {
        let started = Instant::now();
        self.cancel.cancel();
        let outcome = within("service stop", self.handle).await;
        let outcome = outcome.unwrap_or_else(|e| Err(format!("panicked: {e}")));
        (started.elapsed(), outcome)
    }
}

static NEXT_ROOT: AtomicU32 = AtomicU32::new(0);

fn init_tracing() {
    let _ = tracing_subscriber::fmt()
        .with_env_filter(tracing_subscriber::EnvFilter::from_default_env())
        .with_test_writer()
        .try_init();
}

impl Harness {
    /// Starts a router on a free loopback port with a fresh key root.
    pub async fn start() -> Harness {
        init_tracing();
        let router = within("router start", Router::on_loopback())
            .await
            .expect("router");
        let root = format!(
            "test-{}-{}",
            std::process::id(),
            NEXT_ROOT.fetch_add(1, Ordering::Relaxed)
        );
        Harness {
            router,
            root,
            site: None,
        }
    }

    /// A harness around a router the test started itself (with TLS, authentication and
    /// access control, say), under `root`: the services it starts use their role's
    /// config from `site` ([`Harness::role_config`]), and [`Harness::client_config`] is
    /// `site.anonymous`. The key root is the caller's because an access-control policy
    /// names its keys.
    pub fn start_secure(router: Router, root: &str, site: SecureSite) -> Harness {
        init_tracing();
        Harness {
            router,
            root: root.to_owned(),
            site: Some(site),
        }
    }

    /// A Zenoh config for a client session connected to this harness's router (on a
    /// secure site: without credentials).
    pub fn client_config(&self) -> zenoh::Config {
        match &self.site {
            Some(site) => site.anonymous.clone(),
            None => SessionArgs::client_of(&self.router.endpoint)
                .zenoh_config(None)
                .expect("client config"),
        }
    }

    /// The Zenoh config of a session acting as `role` (a service name, or `operator`):
    /// on a secure site that role's credentials, otherwise [`Harness::client_config`].
    pub fn role_config(&self, role: &str) -> zenoh::Config {
        match &self.site {
            Some(site) => site
                .roles
                .get(role)
                .cloned()
                .unwrap_or_else(|| panic!("the secure site has no credentials for '{role}'")),
            None => self.client_config(),
        }
    }

    /// A client session acting as `role` ([`Harness::role_config`]) with a request helper.
    pub async fn client_as(&self, role: &str) -> Requester {
        let session = within(
            "client open",
            roam_runtime::session::open(self.role_config(role)),
        )
        .await
        .unwrap_or_else(|e| panic!("client session as {role}: {e}"));
        Requester::new(session, Duration::from_secs(5))
    }

    /// A client session with a request helper (on a secure site it has no credentials,
    /// so the router refuses it: use [`Harness::client_as`] there).
    pub async fn client(&self) -> Requester {
        let session = within(
            "client open",
            roam_runtime::session::open(self.client_config()),
        )
        .await
        .expect("client session");
        Requester::new(session, Duration::from_secs(5))
    }

    /// Starts a service in this process as a client of the router, and waits until the
    /// liveliness token `live_key` appears. A service that stops before that fails the
    /// test with its own error.
    pub async fn start_service<F, Fut, E>(&self, live_key: String, run: F) -> RunningService
    where
        F: FnOnce(zenoh::Config, CancellationToken) -> Fut,
        Fut: std::future::Future<Output = Result<(), E>> + Send + 'static,
        E: std::fmt::Display,
    {
        self.start_service_with(self.client_config(), live_key, run)
            .await
    }

    /// [`Harness::start_service`] with the session config of `role`
    /// ([`Harness::role_config`]): how the `start_*` helpers start each service as itself.
    pub async fn start_service_as<F, Fut, E>(
        &self,
        role: &str,
        live_key: String,
        run: F,
    ) -> RunningService
    where
        F: FnOnce(zenoh::Config, CancellationToken) -> Fut,
        Fut: std::future::Future<Output = Result<(), E>> + Send + 'static,
        E: std::fmt::Display,
    {
        self.start_service_with(self.role_config(role), live_key, run)
            .await
    }

    async fn start_service_with<F, Fut, E>(
        &self,
        config: zenoh::Config,
        live_key: String,
        run: F,
    ) -> RunningService
    where
        F: FnOnce(zenoh::Config, CancellationToken) -> Fut,
        Fut: std::future::Future<Output = Result<(), E>> + Send + 'static,
        E: std::fmt::Display,
    {
        let cancel = CancellationToken::new();
        let service = run(config, cancel.clone());
        let mut handle = tokio::spawn(async move { service.await.map_err(|e| e.to_string()) });
        let live = wait_for_liveliness(&self.router.session, &live_key, STEP);
        tokio::pin!(live);
        tokio::select! {
            outcome = &mut live => outcome.expect("service up"),
            finished = &mut handle => panic!("the service stopped at start: {finished:?}"),
        }
        RunningService { cancel, handle }
    }

    /// A map server config under this harness's root, built-in world, no persistence.
    pub fn map_server_config(&self) -> MapServerConfig {
        MapServerConfig {
            service: ServiceConfig::at(self.root.clone()),
            ..MapServerConfig::default()
        }
    }

    /// A planner config under this harness's root with the given instance name.
    pub fn planner_config(&self, instance: &str) -> PlannerConfig {
        PlannerConfig {
            service: ServiceConfig {
                instance: Some(instance.to_owned()),
                ..ServiceConfig::at(self.root.clone())
            },
            ..PlannerConfig::default()
        }
    }

    /// A sim config under this harness's root: `scenario` (the built-in world when
    /// `None`), paused for lock-step; `load` requests may read the shipped scenarios
    /// (`config/scenarios`, by name).
    pub fn sim_config(&self, scenario: Option<&str>) -> SimConfig {
        SimConfig {
            service: ServiceConfig::at(self.root.clone()),
            scenario: scenario.map(repo_path),
            rate: None,
            load_dirs: vec![repo_path("config/scenarios")],
            ..SimConfig::default()
        }
    }

    /// A localization config under this harness's root on a scenario's sensing model and
    /// constellation (`scenario` relative to the repository; the built-in world when
    /// `None`).
    pub fn localization_config(&self, scenario: Option<&str>) -> LocalizationConfig {
        LocalizationConfig {
            service: ServiceConfig::at(self.root.clone()),
            scenario: scenario.map(repo_path),
            ..LocalizationConfig::default()
        }
    }

    /// Starts a service of roam's role table ([`Role`]: a config of any service
    /// converts into one) as itself ([`Harness::role_config`]), and waits for its
    /// liveliness token: its instance's own when the config names one (a planner
    /// announces itself once it has a map, so start the map server first).
    pub async fn start_role(&self, role: impl Into<Role>) -> RunningService {
        let role = role.into();
        let name = role.name();
        self.start_role_as(name, role).await
    }

    /// [`Harness::start_role`] with the credentials of `user` (on a secure site, a user
    /// whose name is not the service's: a robot's `controller-<id>`, say).
    pub async fn start_role_as(&self, user: &str, role: impl Into<Role>) -> RunningService {
        let role = role.into();
        let key = role.live_key();
        self.start_service_as(user, key, |zenoh, cancel| role.run(zenoh, cancel))
            .await
    }

    /// A controller config under this harness's root (built-in world, paper defaults).
    pub fn controller_config(&self) -> ControllerConfig {
        ControllerConfig {
            service: ServiceConfig::at(self.root.clone()),
            ..ControllerConfig::default()
        }
    }

    /// A mapper config under this harness's root (built-in world, drives no robot).
    pub fn mapper_config(&self) -> MapperConfig {
        MapperConfig {
            service: ServiceConfig::at(self.root.clone()),
            ..MapperConfig::default()
        }
    }

    /// Whether any instance of `service` currently holds a liveliness token.
    pub async fn is_live(&self, service: &str) -> bool {
        let replies = within(
            "liveliness get",
            self.router
                .session
                .liveliness()
                .get(keys::liveliness_of(&self.root, service))
                .timeout(Duration::from_secs(2)),
        )
        .await
        .expect("liveliness get");
        within("liveliness replies", replies.recv_async())
            .await
            .is_ok()
    }

    pub async fn close(self) {
        self.router.close().await;
    }
}
