//! Why an experiment could not run.

use crate::closed_loop::episode::EpisodeError;
use roam_controller::params::ParamError;

/// Why an experiment could not run.
#[derive(Debug, thiserror::Error)]
pub enum ApfError {
    #[error(transparent)]
    Episode(#[from] EpisodeError),
    #[error(transparent)]
    Params(#[from] ParamError),
    #[error("{name} is {value}: {expected}")]
    BadOption {
        name: &'static str,
        value: usize,
        expected: &'static str,
    },
    #[error("scenario {scenario}: {reason}")]
    Scenario { scenario: String, reason: String },
}
