//! What one sim step showed of a robot: what the caller hands each executive, and what
//! a track records.

use roam_controller::controller::Decision;
use roam_proto::localization::PositionEstimate;

/// What one sim step showed of a robot.
#[derive(Debug, Clone)]
pub struct Step {
    /// Sim time at the end of the step, seconds.
    pub time_s: f64,
    /// Its true position.
    pub truth: [f64; 2],
    /// The localization's estimate (what the executive hears); `None` when the scan
    /// was refused.
    pub estimate: Option<PositionEstimate>,
    /// The controller's decision on this step.
    pub decision: Option<Decision>,
}
