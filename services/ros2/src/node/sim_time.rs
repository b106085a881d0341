//! ROS 2's simulated time as roam's mission clock: with `clock: /clock`, each
//! rosgraph_msgs/msg/Clock (what a simulator publishes for nodes with `use_sim_time`)
//! is put on `<root>/sim/clock`, where roam's executive reads its mission clock (task
//! start times are on it), and stamps the Nav2 robots' estimates. Without it, roam's
//! clock is wall time, as for any robot without a sim.

use std::sync::{Arc, Mutex};

use roam_proto::sim::SimClock;
use roam_proto::{encode, keys};
use roam_runtime::{Delivery, Service};

use super::error::Ros2Error;
use super::output::Output;
use crate::msg::Clock;
use crate::names::Qos;
use crate::types;

/// The latest simulated time heard, seconds; `None` without a clock topic or before
/// its first message.
#[derive(Debug, Clone, Default)]
pub struct MissionClock(Arc<Mutex<Option<f64>>>);

impl MissionClock {
    pub fn now_s(&self) -> Option<f64> {
        *roam_runtime::lock(&self.0)
    }
}

/// Follows `topic` and republishes it as roam's clock.
pub(crate) async fn declare(
    service: &Service,
    out: Arc<Output>,
    root: &str,
    topic: &str,
) -> Result<MissionClock, Ros2Error> {
    let (endpoint, clocks, token) = out
        .subscribe("clock subscription", topic, types::CLOCK, Qos::STREAM)
        .await?;
    let clock = MissionClock::default();
    let (shared, key, cancel) = (clock.clone(), keys::sim_clock(root), service.cancel_token());
    service.spawn(async move {
        let _token = token;
        let mut step = 0u64;
        loop {
            let sample = tokio::select! {
                _ = cancel.cancelled() => break,
                sample = clocks.recv_async() => match sample {
                    Ok(sample) => sample,
                    Err(_) => break,
                },
            };
            let Ok(message) =
                crate::cdr::decode::<Clock>(&sample.payload().to_bytes(), "clock", 1024)
            else {
                out.refuse(
                    &endpoint.key,
                    "a clock message that is not a rosgraph_msgs/msg/Clock",
                );
                continue;
            };
            let time_s = message.clock.as_nanos() as f64 * 1e-9;
            *roam_runtime::lock(&shared.0) = Some(time_s);
            step += 1;
            let tick = SimClock { step, time_s };
            roam_runtime::publish_bytes(out.session(), &key, encode(&tick), Delivery::Latest).await;
        }
    });
    tracing::info!(
        topic,
        "roam ros2: roam's mission clock follows ROS 2's simulated time"
    );
    Ok(clock)
}
