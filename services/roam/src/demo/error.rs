//! Why the demo (or the fleet's) failed.

use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum DemoError {
    #[error(transparent)]
    Stack(#[from] roam_stack::stack::StackError),
    #[error(transparent)]
    Executive(#[from] roam_mission::error::ExecutiveError),
    #[error(transparent)]
    Client(#[from] roam_runtime::ClientError),
    #[error("zenoh: {0}")]
    Zenoh(String),
    #[error(transparent)]
    View(#[from] roam_view::ViewError),
    #[error("cannot write {path}: {reason}")]
    Write { path: PathBuf, reason: String },
    #[error("{field} is {value}; give {limit}")]
    Invalid {
        field: &'static str,
        value: String,
        limit: String,
    },
    #[error("the fleet: {0}")]
    Fleet(String),
}

pub(crate) fn write_error(path: &Path, e: impl std::fmt::Display) -> DemoError {
    DemoError::Write {
        path: path.to_owned(),
        reason: e.to_string(),
    }
}
