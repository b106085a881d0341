//! Whose plan a request is, and so where its progress goes and where its cancel comes
//! from. A plan asked on a robot's plan key (`<root>/planner/robot/<id>/plan`, or an
//! instance's `…/instance/<instance>/robot/<id>/plan`: the robot's mission executive) is
//! the robot's: its progress and cancel keys are under `<root>/planner/robot/<id>/`. A
//! plan asked on the shared keys (the operator, `roam plan`, the ROS 2 node) keeps the
//! shared `<root>/planner/{progress,cancel}/<request_id>`.
//!
//! The key decides, never the body: a router's access control lets each robot's
//! credentials ask and cancel on their own robot's keys only, and a plan is registered
//! in flight under its cancel key ([`crate::inflight`]), so a cancel put on any other
//! key (another robot's, or the shared one) never reaches it, whatever token it brings.

use roam_proto::keys::{self, KeyError};

/// The robot a plan query is for, read from the key it was asked on: `Some` on a
/// robot's plan key, `None` on the shared ones. A query's key may hold a wildcard where
/// the robot goes (`…/robot/*/plan`): that names no robot and is refused.
pub fn robot_of_query<'k>(root: &str, key: &'k str) -> Result<Option<&'k str>, KeyError> {
    match keys::planner_robot_of(root, key) {
        Some(robot) => keys::check_name("robot", robot).map(|()| Some(robot)),
        None => Ok(None),
    }
}

/// Where one plan's progress is published and where its cancel is heard.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PlanKeys {
    pub progress: String,
    /// Also the key the plan is registered under in flight.
    pub cancel: String,
}

impl PlanKeys {
    /// The keys of the plan `request_id` of `robot` (`None`: asked on the shared keys).
    pub fn new(root: &str, robot: Option<&str>, request_id: &str) -> PlanKeys {
        match robot {
            Some(robot) => PlanKeys {
                progress: keys::planner_robot_progress(root, robot, request_id),
                cancel: keys::planner_robot_cancel(root, robot, request_id),
            },
            None => PlanKeys {
                progress: keys::planner_progress(root, request_id),
                cancel: keys::planner_cancel(root, request_id),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plan_asked_for_a_robot_is_cancelled_on_its_keys_only() {
        for key in [
            keys::planner_robot_plan("roam", "r1"),
            keys::planner_robot_plan_at("roam", "p1", "r1"),
        ] {
            let robot = robot_of_query("roam", &key).expect("a robot's key");
            assert_eq!(robot, Some("r1"));
            let plan = PlanKeys::new("roam", robot, "q1");
            assert_eq!(plan.cancel, keys::planner_robot_cancel("roam", "r1", "q1"));
            assert_eq!(
                plan.progress,
                keys::planner_robot_progress("roam", "r1", "q1")
            );
            assert_ne!(plan.cancel, keys::planner_cancel("roam", "q1"));
            assert_ne!(plan.cancel, keys::planner_robot_cancel("roam", "r2", "q1"));
        }
        for key in [
            keys::planner_plan("roam"),
            keys::planner_plan_at("roam", "p1"),
        ] {
            let robot = robot_of_query("roam", &key).expect("a shared key");
            assert_eq!(robot, None);
            assert_eq!(
                PlanKeys::new("roam", robot, "q1").cancel,
                keys::planner_cancel("roam", "q1")
            );
        }
    }

    #[test]
    fn a_wildcard_names_no_robot() {
        for robot in ["*", "**", "a$*"] {
            let key = keys::planner_robot_plan("roam", robot);
            assert!(robot_of_query("roam", &key).is_err(), "{key}");
        }
    }
}
