//! A service's own config file: YAML (or JSON, which YAML reads too), every field named,
//! unknown fields refused, and errors that name the file.

use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;

/// Why a config file could not be used.
#[derive(Debug, thiserror::Error)]
pub enum ConfigFileError {
    #[error("cannot read config file {path}: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("config file {path} is invalid: {reason}")]
    Invalid { path: PathBuf, reason: String },
}

/// Reads and parses a YAML or JSON config file into `T`.
pub fn load<T: DeserializeOwned>(path: &Path) -> Result<T, ConfigFileError> {
    let text = std::fs::read_to_string(path).map_err(|source| ConfigFileError::Read {
        path: path.to_owned(),
        source,
    })?;
    parse(path, &text)
}

/// Parses config text; `path` only names the source in errors.
pub fn parse<T: DeserializeOwned>(path: &Path, text: &str) -> Result<T, ConfigFileError> {
    serde_yaml_ng::from_str(text).map_err(|e| ConfigFileError::Invalid {
        path: path.to_owned(),
        reason: e.to_string(),
    })
}
