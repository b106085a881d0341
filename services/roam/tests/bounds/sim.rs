//! The sim under accepted and refused rates and step requests: it always answers pause,
//! resume and reset at once, whatever rate it was given, and refuses what it cannot do.

use std::time::{Duration, Instant};

use roam_proto::sim::{SimControl, SimStatus};
use roam_proto::{keys, ErrorCode};
use roam_runtime::{ClientError, Requester};
use roam_sim::service::{MAX_RATE, MAX_ROBOT_STEPS_PER_REQUEST, MIN_RATE};

/// How long a pause, resume or reset may take to be answered after any accepted rate.
pub(crate) const CONTROL_WITHIN: Duration = Duration::from_secs(2);

async fn control(client: &Requester, root: &str, op: SimControl) -> Result<SimStatus, ClientError> {
    client
        .request::<SimControl, SimStatus>(&keys::sim_control(root), Some(&op))
        .await
}

/// The slowest answer to a control request after an accepted rate.
pub(crate) async fn rates(session: &zenoh::Session, root: &str) -> Duration {
    let client = Requester::new(session.clone(), Duration::from_secs(30));
    for refused in [4.9e-324, 1e-6, MIN_RATE / 2.0, MAX_RATE * 2.0, -1.0, 1e300] {
        match control(&client, root, SimControl::Resume { rate: refused }).await {
            Err(ClientError::Refused(reply)) => {
                assert_eq!(reply.code, ErrorCode::InvalidRequest, "rate {refused}")
            }
            other => panic!("rate {refused} must be refused: {other:?}"),
        }
    }
    let mut slowest = Duration::ZERO;
    for rate in [MIN_RATE, 0.0, 1.0, MAX_RATE] {
        control(&client, root, SimControl::Resume { rate })
            .await
            .unwrap_or_else(|e| panic!("rate {rate}: {e}"));
        for op in [
            SimControl::Pause,
            SimControl::Resume { rate },
            SimControl::Reset { seed: 1 },
            SimControl::Pause,
        ] {
            let t = Instant::now();
            let status = control(&client, root, op.clone())
                .await
                .unwrap_or_else(|e| panic!("{op:?} after rate {rate}: {e}"));
            let took = t.elapsed();
            slowest = slowest.max(took);
            assert!(
                took <= CONTROL_WITHIN,
                "{op:?} after rate {rate} took {took:?}"
            );
            if matches!(op, SimControl::Pause) {
                assert!(!status.running, "paused after rate {rate}");
            }
        }
    }
    slowest
}

/// Two lock-step drivers at once: one is served, the other told `busy` at once; a
/// request over the robot-step limit is refused before any step.
pub(crate) async fn concurrent_steps(session: &zenoh::Session, root: &str) {
    let client = Requester::new(session.clone(), Duration::from_secs(120));
    let over = u32::try_from(MAX_ROBOT_STEPS_PER_REQUEST + 1).unwrap_or(u32::MAX);
    match control(&client, root, SimControl::Step { n: over }).await {
        Err(ClientError::Refused(reply)) => assert_eq!(reply.code, ErrorCode::LimitExceeded),
        other => panic!("{over} steps must be refused: {other:?}"),
    }
    let n = 2000;
    let (a, b) = tokio::join!(
        control(&client, root, SimControl::Step { n }),
        control(&client, root, SimControl::Step { n }),
    );
    let outcomes = [a, b];
    let served = outcomes.iter().filter(|r| r.is_ok()).count();
    let busy = outcomes
        .iter()
        .filter(|r| matches!(r, Err(ClientError::Refused(e)) if e.code == ErrorCode::Busy))
        .count();
    assert_eq!((served, busy), (1, 1), "{outcomes:?}");
}
