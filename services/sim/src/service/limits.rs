//! What one request, one command and one rate may be, and how often a snapshot is
//! written.

use std::time::Duration;

use roam_proto::{ErrorCode, ErrorReply};

/// Steps one `step` request may ask for.
pub const MAX_STEPS_PER_REQUEST: u32 = 100_000;
/// Robot-steps (steps × robots) one `step` request may ask for: what bounds the work and
/// the messages one request causes, whatever the number of robots.
pub const MAX_ROBOT_STEPS_PER_REQUEST: u64 = 200_000;
/// The fastest real-time factor `resume` accepts (0 means as fast as possible).
pub const MAX_RATE: f64 = 1000.0;
/// The slowest real-time factor `resume` accepts: slower would leave minutes between
/// steps (a rate of 1e-6 once meant days).
pub const MIN_RATE: f64 = 0.01;
/// Largest control request, bytes.
pub const MAX_REQUEST_BYTES: usize = 64 * 1024;
/// Largest robot command, bytes (one is about 60).
pub const MAX_COMMAND_BYTES: usize = 1024;
/// How often a stepping sim writes its snapshot (wall time): what a crash can cost.
pub const SNAPSHOT_PERIOD: Duration = Duration::from_millis(500);

pub(super) fn check_rate(rate: f64) -> Result<(), ErrorReply> {
    if rate == 0.0 || (rate.is_finite() && (MIN_RATE..=MAX_RATE).contains(&rate)) {
        Ok(())
    } else {
        Err(ErrorReply::new(
            ErrorCode::InvalidRequest,
            format!("rate {rate} is out of range; use 0 (as fast as possible) or {MIN_RATE} to {MAX_RATE} times real time"),
        ))
    }
}
