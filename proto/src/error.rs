//! The structured error reply: what every failing request receives (via `reply_err`).

use serde::{Deserialize, Serialize};

use crate::codec::{DecodeError, Message};

/// What kind of failure a request met. Stable strings on the wire (`snake_case`), so a
/// client in any language can branch on them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ErrorCode {
    /// The payload is not valid JSON for the expected message.
    Malformed,
    /// The payload's protocol version is not the one this service speaks.
    UnsupportedVersion,
    /// The payload is a valid roam message, but not the kind this key expects.
    WrongMessage,
    /// The request is well formed but its content is not acceptable (a cell outside the
    /// map, a negative resolution, an unknown layer name...).
    InvalidRequest,
    /// A size, count or time limit was exceeded; [`ErrorReply::limit`] names it.
    LimitExceeded,
    /// The request was based on a version that is no longer the latest.
    StaleVersion,
    /// A named thing (file, layer, robot) does not exist.
    NotFound,
    /// A file exists but its content is damaged or in the wrong format.
    CorruptFile,
    /// The service is shutting down; try again later or elsewhere.
    Unavailable,
    /// The service has as much work in flight as its limit allows, or (a planner)
    /// cannot serve the request from its queue within the request's deadline; try
    /// another instance or later. The refusal is immediate; `expected_wait_s` says how
    /// long the service expects it would have been.
    Busy,
    /// A bug or an I/O failure on the service's side; the message says what failed.
    Internal,
}

impl ErrorCode {
    /// The wire string of this code, for logs and messages.
    pub fn as_str(self) -> &'static str {
        match self {
            ErrorCode::Malformed => "malformed",
            ErrorCode::UnsupportedVersion => "unsupported_version",
            ErrorCode::WrongMessage => "wrong_message",
            ErrorCode::InvalidRequest => "invalid_request",
            ErrorCode::LimitExceeded => "limit_exceeded",
            ErrorCode::StaleVersion => "stale_version",
            ErrorCode::NotFound => "not_found",
            ErrorCode::CorruptFile => "corrupt_file",
            ErrorCode::Unavailable => "unavailable",
            ErrorCode::Busy => "busy",
            ErrorCode::Internal => "internal",
        }
    }
}

/// The limit a request ran into: its name (as in the config and the README), the limit
/// and what the request asked for.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LimitHit {
    /// The limit's name, e.g. `max_layer_cells`.
    pub name: String,
    /// The largest value the service accepts.
    pub max: u64,
    /// The value the request had.
    pub actual: u64,
}

/// The error reply: a code to branch on, a sentence that tells the user what to change,
/// and the limit that was hit where one was.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ErrorReply {
    pub code: ErrorCode,
    pub message: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limit: Option<LimitHit>,
    /// With `busy`: the seconds the service expects before it could serve the request
    /// (a queue's expected wait, a budget's refill), so a client can choose another
    /// instance or retry then.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub expected_wait_s: Option<f64>,
    /// What in the request the refusal is about, where a client may branch on it (a
    /// plan's start or goal off the map or blocked): the message says it to a person,
    /// this says it to a program (roam's ROS 2 node maps it to Nav2's error codes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cause: Option<Cause>,
}

/// What a refused plan request is wrong about ([`ErrorReply::cause`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Cause {
    /// The start is outside the map (or not a finite position).
    StartOffMap,
    /// The goal is outside the map (or not a finite position).
    GoalOffMap,
    /// The start is in an obstacle, its inflation or unknown space.
    StartBlocked,
    /// The goal is in an obstacle, its inflation or unknown space.
    GoalBlocked,
    /// Both ends are free, but no path joins them.
    NoPath,
}

impl ErrorReply {
    pub fn new(code: ErrorCode, message: impl Into<String>) -> Self {
        ErrorReply {
            code,
            message: message.into(),
            limit: None,
            expected_wait_s: None,
            cause: None,
        }
    }

    /// The same reply with what in the request it is about (see `cause`).
    pub fn with_cause(mut self, cause: Cause) -> Self {
        self.cause = Some(cause);
        self
    }

    /// The same reply with another code (e.g. `busy` for a limit on work in flight).
    pub fn with_code(mut self, code: ErrorCode) -> Self {
        self.code = code;
        self
    }

    /// The same reply with the service's expected wait (see `expected_wait_s`).
    pub fn with_expected_wait(mut self, seconds: f64) -> Self {
        self.expected_wait_s = Some(if seconds.is_finite() {
            seconds.max(0.0)
        } else {
            f64::MAX
        });
        self
    }

    /// A [`ErrorCode::LimitExceeded`] reply naming the limit.
    pub fn limit(name: &str, max: u64, actual: u64, message: impl Into<String>) -> Self {
        ErrorReply {
            code: ErrorCode::LimitExceeded,
            message: message.into(),
            limit: Some(LimitHit {
                name: name.to_owned(),
                max,
                actual,
            }),
            expected_wait_s: None,
            cause: None,
        }
    }
}

impl std::fmt::Display for ErrorReply {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.code.as_str(), self.message)?;
        if let Some(limit) = &self.limit {
            write!(
                f,
                " (limit {}: at most {}, got {})",
                limit.name, limit.max, limit.actual
            )?;
        }
        if let Some(wait) = self.expected_wait_s {
            write!(f, " (expected wait {wait:.2} s)")?;
        }
        Ok(())
    }
}

impl std::error::Error for ErrorReply {}

impl Message for ErrorReply {
    const KIND: &'static str = "error";
}

/// Beside the error codes rather than in the codec: the codec knows nothing of replies.
impl DecodeError {
    /// The error reply a service sends for this decode failure.
    pub fn to_reply(&self) -> ErrorReply {
        let code = match self {
            DecodeError::Envelope(_) | DecodeError::Body { .. } => ErrorCode::Malformed,
            DecodeError::UnsupportedVersion { .. } => ErrorCode::UnsupportedVersion,
            DecodeError::WrongKind { .. } => ErrorCode::WrongMessage,
        };
        ErrorReply::new(code, self.to_string())
    }
}
