//! Why a fleet batch could not run.

/// Why the batch could not run.
#[derive(Debug, thiserror::Error)]
pub enum FleetError {
    #[error("{field} is {value}; give {limit}")]
    Invalid {
        field: &'static str,
        value: String,
        limit: String,
    },
    #[error("the warehouse: {0}")]
    World(String),
    #[error("driving: {0}")]
    Drive(#[from] crate::closed_loop::episode::EpisodeError),
    #[error("the executive: {0}")]
    Executive(#[from] crate::reproduce::executive::ExecutiveError),
    #[error("the fleet's map: {0}")]
    Mapper(String),
}
