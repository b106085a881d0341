//! The Foxglove topics the view logs robots and anchors on.

use foxglove::messages::SceneUpdate;

use crate::output::{Outputs, Topic};

/// The fixed topics.
pub const TRUTH_TOPIC: &str = "/robots/truth";
pub const ESTIMATE_TOPIC: &str = "/robots/estimate";
pub const MISSION_TOPIC: &str = "/robots/mission";
pub const DRIVEN_TOPIC: &str = "/robots/driven";
pub const ANCHORS_TOPIC: &str = "/anchors";

/// The fixed robot topics.
pub(super) struct RobotTopics {
    pub(super) truth: Topic,
    pub(super) estimate: Topic,
    pub(super) mission: Topic,
    pub(super) driven: Topic,
}

impl RobotTopics {
    pub(super) fn new(out: &Outputs) -> Self {
        RobotTopics {
            truth: out.topic::<SceneUpdate>(TRUTH_TOPIC, false),
            estimate: out.topic::<SceneUpdate>(ESTIMATE_TOPIC, false),
            mission: out.topic::<SceneUpdate>(MISSION_TOPIC, true),
            driven: out.topic::<SceneUpdate>(DRIVEN_TOPIC, true),
        }
    }
}
