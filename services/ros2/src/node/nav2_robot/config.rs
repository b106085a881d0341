//! A Nav2 robot as `roam ros2`'s config names it, and its check.

use roam_proto::keys;
use serde::Deserialize;

/// A robot on Nav2 that roam drives (`roam ros2`'s `nav2_robots`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Nav2Robot {
    /// The robot's name in roam (its keys `<root>/robot/<id>/…`, the executive's
    /// `robot`).
    pub robot: String,
    /// Its pose topic (geometry_msgs/msg/PoseWithCovarianceStamped).
    pub pose_topic: String,
    /// Its FollowPath action.
    pub follow_path: String,
    /// Nav2's controller plugin and goal checker sent with each path (empty: the
    /// controller server's default).
    pub controller_id: String,
    pub goal_checker_id: String,
    /// No pose for this long holds the robot (its goal is cancelled), seconds.
    pub pose_timeout_s: f64,
    /// How long FollowPath may take to accept or refuse a goal, seconds.
    pub answer_timeout_s: f64,
}

impl Default for Nav2Robot {
    fn default() -> Self {
        Nav2Robot {
            robot: "robot".to_owned(),
            pose_topic: "/amcl_pose".to_owned(),
            follow_path: "/follow_path".to_owned(),
            controller_id: String::new(),
            goal_checker_id: String::new(),
            pose_timeout_s: 2.0,
            answer_timeout_s: 5.0,
        }
    }
}

impl Nav2Robot {
    /// The config's numbers and names, checked.
    pub fn check(&self) -> Result<(), String> {
        keys::check_name("nav2_robots.robot", &self.robot).map_err(|e| e.to_string())?;
        for (name, value) in [
            ("pose_timeout_s", self.pose_timeout_s),
            ("answer_timeout_s", self.answer_timeout_s),
        ] {
            if !(value.is_finite() && value > 0.0 && value <= 3600.0) {
                return Err(format!(
                    "nav2_robots.{name} = {} must be a number of seconds in (0, 3600]",
                    roam_proto::number(value)
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bad_config_is_named() {
        let bad = Nav2Robot {
            pose_timeout_s: f64::NAN,
            ..Nav2Robot::default()
        };
        assert!(bad.check().expect_err("NaN").contains("pose_timeout_s"));
        let bad = Nav2Robot {
            robot: "a/b".into(),
            ..Nav2Robot::default()
        };
        assert!(bad.check().is_err());
        assert!(Nav2Robot::default().check().is_ok());
    }
}
