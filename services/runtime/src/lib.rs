//! Shared plumbing for every roam service, and nothing else.
//!
//! - [`session`]: the Zenoh session from the service's config file, `ZENOH_CONFIG` and
//!   command-line flags, layered in that order;
//! - [`service`]: a running service's session, liveliness token, cancellation tree and
//!   graceful stop;
//! - [`signals`]: SIGINT / SIGTERM as a cancellation;
//! - [`config_file`]: reading a service's YAML/JSON config file with errors that name it;
//! - [`service_config`]: the fields every service's config file has (root, instance,
//!   zenoh), embedded in each, and the refusal of fields a config does not name;
//! - [`reply`] and [`client`]: the two ends of a query, with roam's codec and error reply;
//! - [`layer_follow`]: following the map server's layers from outside it (published,
//!   deltas applied, fetched when missed), for the live view and the ROS 2 node;
//! - [`routing`]: the robot a message is for is the one its key names;
//! - [`telemetry`]: tracing from `RUST_LOG`;
//! - [`warn_limit`]: warnings about wire data, a few lines per source and a count;
//! - [`publish`]: put with the congestion control named at each call, failures logged;
//! - [`subscribe`]: a subscriber that keeps the newest samples (a ring, never blocking
//!   the session);
//! - [`lock`]: shared state under a mutex, usable after a panicked holder (from
//!   `roam-world`, so network-free code locks the same way);
//! - [`liveliness`]: waiting until a service's token is seen;
//! - [`world_check`]: a service's check that its world is the map server's;
//! - [`zenoh_threads`]: Zenoh's process-wide thread pools, sized for many sessions.

pub mod client;
pub mod config_file;
pub mod layer_follow;
pub mod liveliness;
pub mod publish;
pub mod reply;
pub mod routing;
pub mod service;
pub mod service_config;
pub mod session;
pub mod signals;
pub mod subscribe;
pub mod telemetry;
pub mod warn_limit;
pub mod world_check;
pub mod zenoh_threads;

pub use client::{ClientError, Requester};
pub use liveliness::{wait_for_liveliness, LivelinessWait};
pub use publish::{publish, publish_bytes, publish_wait, Delivery};
pub use roam_world::lock::lock;
pub use service::{PayloadBudget, Service, ServiceError};
pub use session::{SessionArgs, SessionError};
pub use subscribe::{subscribe_latest, FleetStreams, LatestSamples};
