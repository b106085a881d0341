//! The robot that joins halfway through the timed run.

use std::time::{Duration, Instant};

use roam_proto::controller::Mission;
use roam_proto::sim::{SimControl, SimStatus};
use roam_proto::{encode, keys};
use roam_runtime::Requester;

use crate::{setup, BenchError};

/// The joiner, `delay` into the timed run: its mission first (the controller holds it
/// for the robot's first estimate), then the sim adds it. When the sim was asked.
pub(super) async fn join(
    client: &Requester,
    session: &zenoh::Session,
    root: &str,
    (name, at, mission): (&str, [f64; 2], &Mission),
    delay: Duration,
) -> Result<Instant, BenchError> {
    tokio::time::sleep(delay).await;
    session
        .put(keys::robot_mission(root, name), encode(mission))
        .await
        .map_err(setup)?;
    let asked = Instant::now();
    client
        .request::<SimControl, SimStatus>(
            &keys::sim_control(root),
            Some(&SimControl::AddRobot {
                name: name.to_owned(),
                at,
            }),
        )
        .await?;
    Ok(asked)
}
