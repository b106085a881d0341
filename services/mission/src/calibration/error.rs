//! Why a calibration call was refused.

/// Why a calibration call was refused. Reading a damaged file is not an error: it falls
/// back to the prior (see [`super::store::load`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CalibrationError {
    #[error("calibration field {field}: {reason}")]
    Config { field: String, reason: String },
    #[error(
        "a stretch holds at most {max} samples (limit max_stretch_samples): start a new stretch"
    )]
    TooManySamples { max: usize },
    #[error("cannot write the time calibration {path}: {reason}")]
    Write { path: String, reason: String },
}
