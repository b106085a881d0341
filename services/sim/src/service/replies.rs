//! The sim's and a scenario's errors as the replies a peer is given.

use roam_proto::{ErrorCode, ErrorReply};
use roam_world::load_dirs::LoadDirs;
use roam_world::scenario::ScenarioError;

use crate::sim::SimError;

pub(super) fn sim_error(e: &SimError) -> ErrorReply {
    let message = e.to_string();
    match e {
        SimError::UnknownRobot(_) => ErrorReply::new(ErrorCode::NotFound, message),
        SimError::TooManyRobots { max } => {
            ErrorReply::limit("max_robots", *max as u64, *max as u64 + 1, message)
        }
        _ => ErrorReply::new(ErrorCode::InvalidRequest, message),
    }
}

/// The reply to a peer's load of `requested`: refusals name the file as the peer gave
/// it, other errors name files relative to their load directory.
pub(super) fn scenario_error(e: &ScenarioError, requested: &str, dirs: &LoadDirs) -> ErrorReply {
    let message = dirs.redact(&e.to_string());
    match e {
        ScenarioError::Refused(refused)
        | ScenarioError::Map {
            source: roam_world::ros_map::RosMapError::Refused(refused),
            ..
        } => refused.to_reply(requested),
        ScenarioError::Missing { .. } => ErrorReply::new(ErrorCode::NotFound, message),
        ScenarioError::Io { .. } => ErrorReply::new(ErrorCode::Internal, message),
        ScenarioError::Map { .. } => ErrorReply::new(ErrorCode::CorruptFile, message),
        _ => ErrorReply::new(ErrorCode::InvalidRequest, message),
    }
}
