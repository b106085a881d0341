//! A running service: its Zenoh session, its liveliness token, one cancellation tree for
//! all its tasks, and the graceful stop that undoes all of it.
//!
//! The life of a service:
//! 1. [`Service::start`] opens the session;
//! 2. the service declares its queryables and subscribers and spawns its loops with
//!    [`Service::spawn`]; each loop selects on [`Service::cancelled`];
//! 3. [`Service::announce`] declares `<root>/@live/<service>/<instance>`. The token comes
//!    last on purpose: whoever sees it can use every key of the service at once;
//! 4. on cancellation (a signal, a test, the stack stopping) [`Service::shutdown`] lets
//!    the loops refuse new work, waits for in-flight work up to a grace period, reports
//!    the tasks that did not stop, drops the liveliness token and closes the session.

use std::future::Future;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use roam_proto::map::WorldId;
use roam_proto::{excerpt, keys};
use tokio::sync::Semaphore;
use tokio_util::sync::CancellationToken;
use tokio_util::task::TaskTracker;
use zenoh::handlers::FifoChannelHandler;
use zenoh::liveliness::LivelinessToken;
use zenoh::query::{Query, Queryable};
use zenoh::Session;

use crate::client::Requester;
use crate::reply;
use crate::service_config::ServiceConfig;
use crate::session::{self, SessionError};
use crate::warn_limit::WarnLimiter;
use crate::world_check::{self, WorldMismatch};

/// Queries one queryable handles at once (see [`Service::serve`]).
pub const MAX_IN_FLIGHT: usize = 32;

/// The largest sample [`Service::subscribe`] decodes: the largest layer the map server
/// holds (16,777,216 f32 cells in base64) with room for its envelope. Subscribers of
/// small messages pass their own, smaller limit to [`Service::subscribe_with`].
pub const DEFAULT_MAX_SAMPLE_BYTES: usize = 96 * 1024 * 1024;

/// Payload bytes a queryable works on at once ([`Service::serve_within`]).
#[derive(Debug, Clone)]
pub struct PayloadBudget {
    /// One permit per KiB.
    kib: Arc<Semaphore>,
    total_kib: u32,
}

impl PayloadBudget {
    /// A budget of `bytes` (at least 1 KiB, at most 4 TiB).
    pub fn new(bytes: usize) -> PayloadBudget {
        let total_kib = u32::try_from(bytes.div_ceil(1024))
            .unwrap_or(u32::MAX)
            .max(1);
        PayloadBudget {
            kib: Arc::new(Semaphore::new(total_kib as usize)),
            total_kib,
        }
    }

    /// Waits until `bytes` fit in what is left (all of it for a payload above the whole
    /// budget); the room is given back when the returned permit drops.
    async fn take(&self, bytes: usize) -> Option<tokio::sync::OwnedSemaphorePermit> {
        let kib = u32::try_from(bytes.div_ceil(1024))
            .unwrap_or(u32::MAX)
            .min(self.total_kib);
        self.kib.clone().acquire_many_owned(kib).await.ok()
    }
}

/// How long [`Service::shutdown`] waits for in-flight work by default.
pub const DEFAULT_GRACE: Duration = Duration::from_millis(1500);

/// Why a service could not start or stop cleanly.
#[derive(Debug, thiserror::Error)]
pub enum ServiceError {
    #[error(transparent)]
    Session(#[from] SessionError),
    #[error("invalid name: {0}")]
    Name(#[from] keys::KeyError),
    #[error("cannot declare {what} on '{key}': {reason}")]
    Declare {
        what: &'static str,
        key: String,
        reason: String,
    },
    #[error("{count} task(s) of {service} did not stop within {grace:?}")]
    StopTimeout {
        service: &'static str,
        count: usize,
        grace: Duration,
    },
    #[error("closing the Zenoh session of {service} failed: {reason}")]
    Close {
        service: &'static str,
        reason: String,
    },
    /// The service was given another world than the map server's ([`Service::guard_world`]).
    #[error(transparent)]
    World(#[from] WorldMismatch),
}

/// A started service. Dropping it without [`Service::shutdown`] still closes the
/// session (Zenoh does on drop), but skips the grace period for in-flight work.
#[derive(Debug)]
pub struct Service {
    name: &'static str,
    root: String,
    instance: String,
    session: Session,
    token: Option<LivelinessToken>,
    cancel: CancellationToken,
    tasks: TaskTracker,
    /// What [`Service::guard_world`] found: the service stopped on it, and its shutdown
    /// returns it.
    world_mismatch: Arc<Mutex<Option<WorldMismatch>>>,
}

impl Service {
    /// Opens the session under the root and instance of the service's config
    /// (`common`); `zenoh` is the session's config as layered from it
    /// ([`crate::session`]). The instance defaults to the session's Zenoh id, which is
    /// unique. The service stops when `cancel` is cancelled.
    pub async fn start(
        name: &'static str,
        common: &ServiceConfig,
        zenoh: zenoh::Config,
        cancel: CancellationToken,
    ) -> Result<Self, ServiceError> {
        let (root, instance) = (common.root.as_str(), common.instance.as_deref());
        keys::check_root(root)?;
        keys::check_name("service name", name)?;
        if let Some(instance) = instance {
            keys::check_name("instance name", instance)?;
        }
        let session = session::open(zenoh).await?;
        let instance = instance
            .map(str::to_owned)
            .unwrap_or_else(|| session.zid().to_string());
        Ok(Service {
            name,
            root: root.to_owned(),
            instance,
            session,
            token: None,
            cancel,
            tasks: TaskTracker::new(),
            world_mismatch: Arc::default(),
        })
    }

    /// Checks in the background that the map server holds world `mine`, the world this
    /// service loaded ([`crate::world_check`]): until a map server answers the service
    /// runs (a fleet starts in any order); when its world is another, the service stops
    /// and [`Service::shutdown`] returns [`ServiceError::World`] naming both.
    pub fn guard_world(&self, mine: WorldId) {
        let requester = Requester::new(self.session.clone(), world_check::ASK_EVERY);
        let key = keys::map_index(&self.root);
        let (name, cancel) = (self.name, self.cancel.clone());
        let found = self.world_mismatch.clone();
        self.spawn(async move {
            if let Some(mismatch) = world_check::check(&requester, &key, name, mine, &cancel).await
            {
                tracing::error!("{mismatch}");
                *crate::lock(&found) = Some(mismatch);
                cancel.cancel();
            }
        });
    }

    /// Declares the liveliness token `<root>/@live/<service>/<instance>`: call it once
    /// every queryable and subscriber is declared, so the token means "ready".
    pub async fn announce(&mut self) -> Result<(), ServiceError> {
        let key = keys::liveliness(&self.root, self.name, &self.instance);
        let token = self
            .session
            .liveliness()
            .declare_token(&key)
            .await
            .map_err(|e| ServiceError::Declare {
                what: "liveliness token",
                key: key.clone(),
                reason: e.to_string(),
            })?;
        self.token = Some(token);
        tracing::info!(service = self.name, instance = %self.instance, %key, "service ready");
        Ok(())
    }

    pub fn name(&self) -> &'static str {
        self.name
    }

    pub fn root(&self) -> &str {
        &self.root
    }

    pub fn instance(&self) -> &str {
        &self.instance
    }

    pub fn session(&self) -> &Session {
        &self.session
    }

    /// The token that stops this service; clone it into loops.
    pub fn cancel_token(&self) -> CancellationToken {
        self.cancel.clone()
    }

    /// Resolves when the service has been told to stop.
    pub async fn cancelled(&self) {
        self.cancel.cancelled().await
    }

    /// Spawns a task that [`Service::shutdown`] waits for.
    pub fn spawn<F>(&self, task: F)
    where
        F: Future<Output = ()> + Send + 'static,
    {
        self.tasks.spawn(task);
    }

    /// A tracker for per-request tasks, so shutdown waits for them too.
    pub fn tracker(&self) -> TaskTracker {
        self.tasks.clone()
    }

    /// Declares a queryable, mapping the error to a [`ServiceError`] that names the key.
    pub async fn declare_queryable(
        &self,
        key: &str,
    ) -> Result<
        zenoh::query::Queryable<zenoh::handlers::FifoChannelHandler<zenoh::query::Query>>,
        ServiceError,
    > {
        self.session
            .declare_queryable(key)
            .complete(true)
            .await
            .map_err(|e| ServiceError::Declare {
                what: "queryable",
                key: key.to_owned(),
                reason: e.to_string(),
            })
    }

    /// Runs a queryable's loop: each query is handled by `handler(state, query)` in
    /// its own tracked task, at most [`MAX_IN_FLIGHT`] at once (further queries wait in
    /// Zenoh's channel, which pushes back on senders instead of growing memory). After
    /// cancellation, queries still queued are refused as `unavailable`.
    pub fn serve<S, F, Fut>(
        &self,
        queryable: Queryable<FifoChannelHandler<Query>>,
        state: S,
        handler: F,
    ) where
        S: Clone + Send + Sync + 'static,
        F: Fn(S, Query) -> Fut + Send + Sync + 'static,
        Fut: Future<Output = ()> + Send + 'static,
    {
        self.serve_within(queryable, None, state, handler)
    }

    /// [`Service::serve`] with at most `max_in_flight` queries handled at once instead
    /// of [`MAX_IN_FLIGHT`]: for a service that keeps its own bounded queue of requests
    /// (the planner's), so that each request in its queue holds its query and the ones
    /// beyond are refused by the service at once rather than left in Zenoh's channel.
    pub fn serve_up_to<S, F, Fut>(
        &self,
        queryable: Queryable<FifoChannelHandler<Query>>,
        max_in_flight: usize,
        state: S,
        handler: F,
    ) where
        S: Clone + Send + Sync + 'static,
        F: Fn(S, Query) -> Fut + Send + Sync + 'static,
        Fut: Future<Output = ()> + Send + 'static,
    {
        self.serve_loop(queryable, None, max_in_flight.max(1), state, handler)
    }

    /// [`Service::serve`], with the payloads of the queries being handled at once
    /// bounded by `budget`: a query waits (in Zenoh's channel) until the payloads in work
    /// leave room for its own. Decoding, checking and answering a request costs a few
    /// times its payload, so for a queryable that takes large requests (the map server's
    /// updates, up to `max_request_bytes`) this is what bounds the service's memory under
    /// concurrent large requests. A payload above the whole budget waits for all of it.
    pub fn serve_within<S, F, Fut>(
        &self,
        queryable: Queryable<FifoChannelHandler<Query>>,
        budget: Option<PayloadBudget>,
        state: S,
        handler: F,
    ) where
        S: Clone + Send + Sync + 'static,
        F: Fn(S, Query) -> Fut + Send + Sync + 'static,
        Fut: Future<Output = ()> + Send + 'static,
    {
        self.serve_loop(queryable, budget, MAX_IN_FLIGHT, state, handler)
    }

    fn serve_loop<S, F, Fut>(
        &self,
        queryable: Queryable<FifoChannelHandler<Query>>,
        budget: Option<PayloadBudget>,
        max_in_flight: usize,
        state: S,
        handler: F,
    ) where
        S: Clone + Send + Sync + 'static,
        F: Fn(S, Query) -> Fut + Send + Sync + 'static,
        Fut: Future<Output = ()> + Send + 'static,
    {
        let cancel = self.cancel.clone();
        let tracker = self.tasks.clone();
        let name = self.name;
        let permits = Arc::new(Semaphore::new(max_in_flight));
        self.tasks.spawn(async move {
            loop {
                let permit = tokio::select! {
                    _ = cancel.cancelled() => break,
                    permit = permits.clone().acquire_owned() => match permit {
                        Ok(permit) => permit,
                        Err(_) => break,
                    },
                };
                let query = tokio::select! {
                    _ = cancel.cancelled() => break,
                    next = queryable.recv_async() => match next {
                        Ok(query) => query,
                        Err(_) => break,
                    },
                };
                let room = match &budget {
                    Some(budget) => {
                        let size = query.payload().map_or(0, |p| p.len());
                        tokio::select! {
                            _ = cancel.cancelled() => {
                                reply::refuse_stopping(&query, name).await;
                                break;
                            }
                            room = budget.take(size) => room,
                        }
                    }
                    None => None,
                };
                let work = handler(state.clone(), query);
                tracker.spawn(async move {
                    work.await;
                    drop(room);
                    drop(permit);
                });
            }
            while let Ok(Some(query)) = queryable.try_recv() {
                reply::refuse_stopping(&query, name).await;
            }
        });
    }

    /// Subscribes to `key` and hands every sample that decodes as `T` to
    /// `handler(&state, message)`, with payloads of at most [`DEFAULT_MAX_SAMPLE_BYTES`];
    /// see [`Service::subscribe_with`].
    pub async fn subscribe<T, S, F>(
        &self,
        key: &str,
        state: S,
        handler: F,
    ) -> Result<(), ServiceError>
    where
        T: roam_proto::Message,
        S: Send + Sync + 'static,
        F: Fn(&S, T) + Send + 'static,
    {
        self.subscribe_with(
            key,
            DEFAULT_MAX_SAMPLE_BYTES,
            state,
            move |state: &S, _key: &str, message: T| handler(state, message),
        )
        .await
    }

    /// Subscribes to `key` and hands every sample that decodes as `T` to
    /// `handler(&state, key, message)` on a tracked task, until the service stops; `key`
    /// is the concrete key the sample arrived on (take routing names such as the robot
    /// from it, never from the body: see [`roam_proto::keys::robot_of`]).
    ///
    /// A sample larger than `max_bytes` is dropped before it is decoded; one that does
    /// not decode is dropped too. Both are logged with a bounded, escaped excerpt, at
    /// most a few lines per key per window ([`crate::warn_limit`]): a subscriber has no
    /// one to answer. Handlers run inline, so keep them light.
    pub async fn subscribe_with<T, S, F>(
        &self,
        key: &str,
        max_bytes: usize,
        state: S,
        handler: F,
    ) -> Result<(), ServiceError>
    where
        T: roam_proto::Message,
        S: Send + Sync + 'static,
        F: Fn(&S, &str, T) + Send + 'static,
    {
        let subscriber =
            self.session
                .declare_subscriber(key)
                .await
                .map_err(|e| ServiceError::Declare {
                    what: "subscriber",
                    key: key.to_owned(),
                    reason: e.to_string(),
                })?;
        let cancel = self.cancel.clone();
        let warnings = WarnLimiter::new();
        self.tasks.spawn(async move {
            loop {
                let sample = tokio::select! {
                    _ = cancel.cancelled() => break,
                    sample = subscriber.recv_async() => match sample {
                        Ok(sample) => sample,
                        Err(_) => break,
                    },
                };
                let key = sample.key_expr().as_str();
                let size = sample.payload().len();
                if size > max_bytes {
                    crate::limited_warn!(
                        warnings,
                        key,
                        key = %excerpt(key),
                        "dropping a {} sample of {size} bytes unread: over the limit of {max_bytes} bytes",
                        T::KIND
                    );
                    continue;
                }
                match roam_proto::decode::<T>(&sample.payload().to_bytes()) {
                    Ok(message) => handler(&state, key, message),
                    Err(e) => crate::limited_warn!(
                        warnings,
                        key,
                        key = %excerpt(key),
                        "ignoring a sample that does not decode: {e}"
                    ),
                }
            }
        });
        Ok(())
    }

    /// Waits until the service is told to stop, then stops it with the default grace
    /// period: the tail of every service's `run` that has nothing to do in between.
    pub async fn run_until_stopped(self) -> Result<(), ServiceError> {
        self.cancelled().await;
        self.shutdown(DEFAULT_GRACE).await
    }

    /// Stops the service: cancels its loops, waits up to `grace` for in-flight work,
    /// drops the liveliness token and closes the session. Returns the world mismatch
    /// that stopped it ([`Service::guard_world`]), else an error naming how many tasks
    /// did not stop in time (the session is closed all the same).
    pub async fn shutdown(mut self, grace: Duration) -> Result<(), ServiceError> {
        self.cancel.cancel();
        self.tasks.close();
        let late = tokio::time::timeout(grace, self.tasks.wait())
            .await
            .is_err();
        let pending = self.tasks.len();
        if let Some(token) = self.token.take() {
            if let Err(e) = token.undeclare().await {
                tracing::warn!(
                    service = self.name,
                    "undeclaring the liveliness token failed: {e}"
                );
            }
        }
        self.session
            .close()
            .await
            .map_err(|e| ServiceError::Close {
                service: self.name,
                reason: e.to_string(),
            })?;
        tracing::info!(service = self.name, instance = %self.instance, "service stopped");
        if let Some(mismatch) = crate::lock(&self.world_mismatch).take() {
            return Err(mismatch.into());
        }
        if late {
            return Err(ServiceError::StopTimeout {
                service: self.name,
                count: pending,
                grace,
            });
        }
        Ok(())
    }
}
