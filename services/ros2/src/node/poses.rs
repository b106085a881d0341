//! The robots' latest estimated positions as the node heard them on roam's keys: where a
//! ComputePathToPose goal with `use_start` false starts (Nav2's "the robot's current
//! pose", which Nav2 reads from tf and roam from its own estimates).

use std::collections::BTreeMap;
use std::sync::Mutex;

/// The most robots published (poses, `/tf`, driven paths).
pub const MAX_ROBOTS: usize = 256;

#[derive(Debug, Default)]
pub struct RobotPoses {
    latest: Mutex<BTreeMap<String, [f64; 2]>>,
}

impl RobotPoses {
    /// Keeps `robot`'s latest position (up to [`MAX_ROBOTS`] robots; `false` beyond).
    pub fn record(&self, robot: &str, at: [f64; 2]) -> bool {
        let mut latest = roam_runtime::lock(&self.latest);
        if !latest.contains_key(robot) && latest.len() >= MAX_ROBOTS {
            return false;
        }
        latest.insert(robot.to_owned(), at);
        true
    }

    /// The current position of `robot`, or, with none named, of the one robot heard of;
    /// otherwise why there is none.
    pub fn current(&self, robot: Option<&str>) -> Result<[f64; 2], String> {
        let latest = roam_runtime::lock(&self.latest);
        match robot {
            Some(robot) => latest.get(robot).copied().ok_or_else(|| {
                format!("no estimate of robot '{robot}' yet; set use_start and give a start")
            }),
            None => {
                let mut robots = latest.values();
                match (robots.next(), robots.next()) {
                    (Some(at), None) => Ok(*at),
                    (None, _) => Err(
                        "no robot's estimate heard yet; set use_start and give a start".to_owned(),
                    ),
                    _ => Err(format!(
                        "{} robots are localized and none is named as the planning robot (roam ros2's `robot`); set use_start and give a start",
                        latest.len()
                    )),
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_one_robot_or_the_named_one() {
        let poses = RobotPoses::default();
        assert!(poses.current(None).is_err());
        poses.record("r1", [1.0, 2.0]);
        assert_eq!(poses.current(None), Ok([1.0, 2.0]));
        poses.record("r2", [3.0, 4.0]);
        assert!(poses
            .current(None)
            .expect_err("refused")
            .contains("2 robots"));
        assert_eq!(poses.current(Some("r2")), Ok([3.0, 4.0]));
        assert!(poses
            .current(Some("r3"))
            .expect_err("refused")
            .contains("'r3'"));
    }
}
