//! Why a days batch could not run.

use roam_mission::calibration::CalibrationError;

/// Why a batch could not run.
#[derive(Debug, thiserror::Error)]
pub enum DaysError {
    /// An option out of its range, named as [`super::DaysOptions`] spells it.
    #[error("{field} is {value}; give {limit}")]
    Invalid {
        field: &'static str,
        value: String,
        limit: String,
    },
    #[error("the day's world: {0}")]
    World(String),
    #[error("driving: {0}")]
    Drive(#[from] crate::closed_loop::episode::EpisodeError),
    #[error("the time model: {0}")]
    Calibration(#[from] CalibrationError),
    #[error("the change map: {0}")]
    Mapper(String),
    #[error("the executive: {0}")]
    Executive(#[from] crate::reproduce::executive::ExecutiveError),
}
