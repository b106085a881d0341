//! Why the store refused a change, and the error reply each refusal becomes.

use roam_proto::{ErrorCode, ErrorReply};

use crate::persist::PersistError;

/// Why a change was refused.
#[derive(Debug, thiserror::Error)]
pub enum StoreError {
    #[error("layer '{layer}' is at version {current}, but the {what} was based on version {base}; get the latest layer and {retry}")]
    Stale {
        layer: String,
        base: u64,
        current: u64,
        what: &'static str,
        retry: &'static str,
    },
    #[error("layer '{layer}' is computed from '{source_layer}'; update '{source_layer}' instead")]
    Derived { layer: String, source_layer: String },
    #[error("layer '{0}' does not exist; create it with a replace based on version 0")]
    NotFound(String),
    #[error("layer '{layer}' does not exist, so there is nothing to delete; the map server holds: {held}")]
    NothingToDelete { layer: String, held: String },
    #[error("layer '{layer}' cannot be deleted: {why}")]
    Protected { layer: String, why: String },
    #[error("{0}")]
    Invalid(String),
    #[error("{message}")]
    Limit {
        name: &'static str,
        max: u64,
        actual: u64,
        message: String,
    },
    #[error("the change could not be persisted, so it was not applied: {0}")]
    Persist(#[from] PersistError),
}

impl StoreError {
    pub fn to_reply(&self) -> ErrorReply {
        let message = self.to_string();
        match self {
            StoreError::Stale { .. } => ErrorReply::new(ErrorCode::StaleVersion, message),
            StoreError::Derived { .. } | StoreError::Invalid(_) | StoreError::Protected { .. } => {
                ErrorReply::new(ErrorCode::InvalidRequest, message)
            }
            StoreError::NotFound(_) | StoreError::NothingToDelete { .. } => {
                ErrorReply::new(ErrorCode::NotFound, message)
            }
            StoreError::Limit {
                name, max, actual, ..
            } => ErrorReply::limit(name, *max, *actual, message),
            StoreError::Persist(_) => ErrorReply::new(ErrorCode::Internal, message),
        }
    }
}

/// A [`StoreError::Limit`] whose message says what was over which limit.
pub(crate) fn limit(name: &'static str, max: u64, actual: u64, what: String) -> StoreError {
    StoreError::Limit {
        name,
        max,
        actual,
        message: format!("{what}: {actual} is over the limit {name} = {max}"),
    }
}
