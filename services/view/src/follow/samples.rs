//! What both loops take samples with: the rings, the sim's robot names, and the checks
//! a sample passes before it is believed.

use std::collections::BTreeSet;
use std::sync::Arc;

use roam_proto::{keys, Message};
use roam_runtime::LatestSamples;
use zenoh::sample::Sample;

use crate::output::Outputs;
use crate::wire::{decode_bounded, shown};

pub(super) type Ring = LatestSamples;

/// The names of the robots in the sim's last status.
pub(super) type SimRobots = Arc<BTreeSet<String>>;

/// Decodes a sample's payload of at most `max` bytes, or counts it dropped.
pub(super) fn decode_sample<T: Message>(out: &Outputs, sample: &Sample, max: usize) -> Option<T> {
    match decode_bounded::<T>(sample.payload(), max) {
        Ok(message) => Some(message),
        Err(e) => {
            out.counters.unread(sample.key_expr().as_str(), &e);
            None
        }
    }
}

/// Checks that `robot` is a valid robot name and the one `key` (`<root>/robot/<id>/…`)
/// is for: a message about robot A put on robot B's key is not believed.
pub(super) fn check_robot(root: &str, key: &str, robot: &str) -> Result<(), String> {
    if keys::check_name("robot", robot).is_err() {
        return Err(format!(
            "the robot name \"{}\" is not a key segment (1 to {} of a-z, A-Z, 0-9, '_', '-')",
            shown(robot),
            keys::MAX_SEGMENT_LEN
        ));
    }
    let named = key
        .strip_prefix(root)
        .and_then(|k| k.strip_prefix("/robot/"))
        .and_then(|k| k.split('/').next());
    if named != Some(robot) {
        return Err(format!(
            "a message about robot \"{}\" on another robot's key",
            shown(robot)
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_robot_must_be_a_key_segment_and_the_key_s_robot() {
        let root = "roam/site-1";
        assert_eq!(
            check_robot(root, "roam/site-1/robot/r1/mission", "r1"),
            Ok(())
        );
        let other = check_robot(root, "roam/site-1/robot/r2/mission", "r1");
        assert!(other.is_err_and(|e| e.contains("another robot's key")));
        let evil = "r1\n\u{1b}[2J";
        let refused = check_robot(root, "roam/site-1/robot/r1/mission", evil).expect_err("evil");
        assert!(
            !refused.contains('\n') && !refused.contains('\u{1b}'),
            "{refused}"
        );
        let long = "r".repeat(1 << 20);
        let refused = check_robot(root, "roam/site-1/robot/r/mission", &long).expect_err("long");
        assert!(refused.len() < 300, "{} bytes", refused.len());
        assert!(check_robot(root, "other/robot/r1/mission", "r1").is_err());
    }
}
