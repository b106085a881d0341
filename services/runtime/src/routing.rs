//! Keys decide: the robot a per-robot message is for is the one its key names.
//!
//! Per-robot messages (`range_scan`, `mission`, `position_estimate`, `observation`, ...)
//! also name their robot in the body, for readers that see them outside Zenoh (a log, an
//! MCAP file). A service takes the robot from the key it received the message on,
//! because that is what a router's access control authorised and what a per-robot
//! subscription selected, and refuses a body that names another: otherwise a mission
//! put on `robot/AAA/mission` would drive robot `robot`, and a scan naming `**` would
//! make localization publish on `robot/**/estimate`.

use roam_proto::{excerpt, keys};

/// Why a per-robot message was refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RoutingError {
    #[error("the key '{key}' does not name one robot (<root>/robot/<robot>/<leaf>)")]
    NotPerRobot { key: String },
    #[error("the body names robot '{body}' but it came on robot '{key_robot}''s key; a message is for the robot its key names")]
    Mismatch { key_robot: String, body: String },
}

/// The robot `key` names, when `body_robot` (the robot the body names) agrees.
pub fn robot_for<'k>(root: &str, key: &'k str, body_robot: &str) -> Result<&'k str, RoutingError> {
    let robot = keys::robot_of(root, key).ok_or_else(|| RoutingError::NotPerRobot {
        key: excerpt(key).to_string(),
    })?;
    if robot != body_robot {
        return Err(RoutingError::Mismatch {
            key_robot: robot.to_owned(),
            body: excerpt(body_robot).to_string(),
        });
    }
    Ok(robot)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_key_decides() {
        assert_eq!(robot_for("roam", "roam/robot/r1/mission", "r1"), Ok("r1"));
        assert!(matches!(
            robot_for("roam", "roam/robot/AAA/mission", "robot"),
            Err(RoutingError::Mismatch { .. })
        ));
        assert!(matches!(
            robot_for("roam", "roam/robot/a/b/mission", "a/b"),
            Err(RoutingError::NotPerRobot { .. })
        ));
        let forged = robot_for("roam", "roam/robot/r1/ranges", "r1\n2026 INFO forged")
            .expect_err("mismatch")
            .to_string();
        assert!(!forged.contains('\n'), "{forged}");
    }
}
