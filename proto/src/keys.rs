//! Every key expression roam uses, built here and nowhere else.
//!
//! All keys live under one configurable root (default [`DEFAULT_ROOT`]), so two stacks
//! on one network never see each other and a fleet can share one router. Each function
//! says who publishes or answers on the key, what the payload is, and how often.

/// The key root used when none is configured.
pub const DEFAULT_ROOT: &str = "roam";

/// Why a root, layer name, service or instance name cannot be part of a key.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("'{value}' cannot be used as a {what}: use 1 to {MAX_SEGMENT_LEN} characters from a-z, A-Z, 0-9, '_' and '-'{extra}")]
pub struct KeyError {
    pub what: &'static str,
    pub value: String,
    extra: &'static str,
}

/// The longest name accepted for one key segment.
pub const MAX_SEGMENT_LEN: usize = 64;

fn is_segment(s: &str) -> bool {
    !s.is_empty()
        && s.len() <= MAX_SEGMENT_LEN
        && s.bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-')
}

/// Checks a name that becomes one key segment (a layer, a service, an instance, a robot).
pub fn check_name(what: &'static str, value: &str) -> Result<(), KeyError> {
    if is_segment(value) {
        Ok(())
    } else {
        Err(KeyError {
            what,
            value: value.to_owned(),
            extra: "",
        })
    }
}

/// Checks a key root: one or more segments separated by '/'.
pub fn check_root(root: &str) -> Result<(), KeyError> {
    if root.split('/').all(is_segment) {
        Ok(())
    } else {
        Err(KeyError {
            what: "key root",
            value: root.to_owned(),
            extra: ", in segments separated by '/'",
        })
    }
}

/// The robot a per-robot key names: `<root>/robot/<robot>/<leaf>` gives `<robot>` when
/// it is a valid name ([`check_name`]) and the key has exactly that shape, `None`
/// otherwise. Services take the robot from the key a message arrived on, never from its
/// body: on a router with access control by key, the key is what was authorised.
pub fn robot_of<'k>(root: &str, key: &'k str) -> Option<&'k str> {
    let rest = key.strip_prefix(root)?.strip_prefix("/robot/")?;
    let (robot, leaf) = rest.split_once('/')?;
    (is_segment(robot) && is_segment(leaf)).then_some(robot)
}

/// `<root>/@live/<service>/<instance>`: a liveliness token each running service holds
/// for as long as it runs. No payload. Watch `<root>/@live/**` to see who is up.
pub fn liveliness(root: &str, service: &str, instance: &str) -> String {
    format!("{root}/@live/{service}/{instance}")
}

/// `<root>/@live/<service>/*`: every running instance of one service.
pub fn liveliness_of(root: &str, service: &str) -> String {
    format!("{root}/@live/{service}/*")
}

/// `<root>/@live/**`: every running service.
pub fn liveliness_all(root: &str) -> String {
    format!("{root}/@live/**")
}

/// `<root>/map/layer/<layer>`: the map server publishes a
/// [`Layer`](crate::map::Layer) here each time the whole layer changes (a replace, a
/// map load, a change too large for a delta; congestion control `Block`, so large
/// layers are never dropped), and answers a `get` with the latest one. A `set_cells`
/// change is published on [`map_delta`] instead. Rate: on change only.
pub fn map_layer(root: &str, layer: &str) -> String {
    format!("{root}/map/layer/{layer}")
}

/// `<root>/map/layer/*`: subscribe here to follow every layer (with [`map_delta_any`]).
pub fn map_layer_any(root: &str) -> String {
    format!("{root}/map/layer/*")
}

/// `<root>/map/delta/<layer>`: the map server publishes a
/// [`LayerDelta`](crate::layer_delta::LayerDelta) here for each `set_cells` change of the
/// layer (and for the cells its derived layer gains from one): the cells written, the
/// version they apply to and the version they make (congestion control `Block`). A
/// follower holding the layer at the delta's base version applies it; one that does
/// not gets the whole layer with a `get` on [`map_layer`]. Rate: on change only.
pub fn map_delta(root: &str, layer: &str) -> String {
    format!("{root}/map/delta/{layer}")
}

/// `<root>/map/delta/*`: subscribe here to follow every layer's small changes.
pub fn map_delta_any(root: &str) -> String {
    format!("{root}/map/delta/*")
}

/// `<root>/map/update/<layer>`: the map server answers a `get` carrying a
/// [`LayerUpdate`](crate::map::LayerUpdate) with an [`UpdateAck`](crate::map::UpdateAck),
/// or an error reply (stale version, cell outside the map, limit). Any service that
/// owns a layer (the mapper's change rates, localization's PEB) writes it here.
pub fn map_update(root: &str, layer: &str) -> String {
    format!("{root}/map/update/{layer}")
}

/// `<root>/map/update/*`: the map server's update queryable declaration.
pub fn map_update_any(root: &str) -> String {
    format!("{root}/map/update/*")
}

/// `<root>/map/delete/<layer>`: the map server answers a `get` carrying a
/// [`DeleteLayer`](crate::map::DeleteLayer) by deleting that free layer, with a
/// [`LayerDeleted`](crate::map::LayerDeleted), or an error reply (stale version, a base
/// layer, no such layer). The roles that may update layers may delete them. Nothing is
/// published when a layer is deleted: a `get` then answers `not_found`.
pub fn map_delete(root: &str, layer: &str) -> String {
    format!("{root}/map/delete/{layer}")
}

/// `<root>/map/delete/*`: the map server's delete queryable declaration.
pub fn map_delete_any(root: &str) -> String {
    format!("{root}/map/delete/*")
}

/// `<root>/map/layers`: the map server answers a `get` (no payload) with a
/// [`LayerList`](crate::map::LayerList): every layer's name, version, size and warnings.
pub fn map_index(root: &str) -> String {
    format!("{root}/map/layers")
}

/// `<root>/map/load`: the map server answers a `get` carrying a
/// [`LoadMap`](crate::map::LoadMap) (a ROS `map.yaml` or a roam scenario on the server's
/// file system) by replacing its source layers, with a [`LayerList`](crate::map::LayerList).
pub fn map_load(root: &str) -> String {
    format!("{root}/map/load")
}

/// `<root>/planner/plan`: every planner instance answers a `get` carrying a
/// [`PlanRequest`](crate::planner::PlanRequest) with a [`Plan`](crate::planner::Plan).
/// Zenoh sends such a query to one nearest instance (failover, not load sharing); to
/// share load, pick an instance and use [`planner_plan_at`].
pub fn planner_plan(root: &str) -> String {
    format!("{root}/planner/plan")
}

/// `<root>/planner/instance/<instance>/plan`: the same queryable on one instance's own
/// key. Clients find instances through `<root>/@live/planner/*` and choose among them.
pub fn planner_plan_at(root: &str, instance: &str) -> String {
    format!("{root}/planner/instance/{instance}/plan")
}

/// `<root>/planner/progress/<request_id>`: the planner working on a request publishes
/// [`PlanProgress`](crate::planner::PlanProgress) here, at most every 50 ms. Public:
/// a request id is a name, not a secret (cancelling takes the request's token).
pub fn planner_progress(root: &str, request_id: &str) -> String {
    format!("{root}/planner/progress/{request_id}")
}

/// `<root>/planner/cancel/<request_id>`: put a [`CancelPlan`](crate::planner::CancelPlan)
/// here to stop a plan in flight; every planner instance listens, and honours it only
/// with the request's `cancel_token`.
pub fn planner_cancel(root: &str, request_id: &str) -> String {
    format!("{root}/planner/cancel/{request_id}")
}

/// `<root>/planner/cancel/*`: what planner instances subscribe to.
pub fn planner_cancel_any(root: &str) -> String {
    format!("{root}/planner/cancel/*")
}

/// `<root>/planner/robot/<robot>/plan`: every planner instance answers a `get` carrying
/// a [`PlanRequest`](crate::planner::PlanRequest) for `robot` (its mission executive asks
/// here) as on [`planner_plan`], and keeps the plan's progress and cancel under the
/// robot's keys ([`planner_robot_progress`], [`planner_robot_cancel`]): a router's access
/// control can then give each robot's credentials its own robot's plans only.
pub fn planner_robot_plan(root: &str, robot: &str) -> String {
    format!("{root}/planner/robot/{robot}/plan")
}

/// `<root>/planner/robot/*/plan`: what every planner instance declares for robots' plans.
pub fn planner_robot_plan_any(root: &str) -> String {
    format!("{root}/planner/robot/*/plan")
}

/// `<root>/planner/instance/<instance>/robot/<robot>/plan`: [`planner_robot_plan`] on one
/// instance's own key, for clients that choose among instances ([`planner_plan_at`]).
pub fn planner_robot_plan_at(root: &str, instance: &str, robot: &str) -> String {
    format!("{root}/planner/instance/{instance}/robot/{robot}/plan")
}

/// `<root>/planner/instance/<instance>/robot/*/plan`: what one instance declares for
/// robots' plans on its own key.
pub fn planner_robot_plan_at_any(root: &str, instance: &str) -> String {
    format!("{root}/planner/instance/{instance}/robot/*/plan")
}

/// `<root>/planner/robot/<robot>/progress/<request_id>`: [`planner_progress`] of a plan
/// asked on one of the robot's plan keys.
pub fn planner_robot_progress(root: &str, robot: &str, request_id: &str) -> String {
    format!("{root}/planner/robot/{robot}/progress/{request_id}")
}

/// `<root>/planner/robot/<robot>/cancel/<request_id>`: put a
/// [`CancelPlan`](crate::planner::CancelPlan) here to stop a plan asked on one of the
/// robot's plan keys (with the request's `cancel_token`, as on [`planner_cancel`]). Such a
/// plan is cancelled here only: a cancel on another robot's key or on [`planner_cancel`]
/// does not reach it.
pub fn planner_robot_cancel(root: &str, robot: &str, request_id: &str) -> String {
    format!("{root}/planner/robot/{robot}/cancel/{request_id}")
}

/// `<root>/planner/robot/*/cancel/*`: what planner instances subscribe to for robots'
/// plans.
pub fn planner_robot_cancel_any(root: &str) -> String {
    format!("{root}/planner/robot/*/cancel/*")
}

/// The robot a plan query's key is for: `<robot>` of [`planner_robot_plan`] or
/// [`planner_robot_plan_at`], as the key has it (a query's key may hold a wildcard:
/// check it with [`check_name`]); `None` for any other key, [`planner_plan`]'s included.
pub fn planner_robot_of<'k>(root: &str, key: &'k str) -> Option<&'k str> {
    let rest = key.strip_prefix(root)?.strip_prefix("/planner/")?;
    let rest = match rest.strip_prefix("instance/") {
        Some(at_instance) => at_instance.split_once('/')?.1,
        None => rest,
    };
    let robot = rest.strip_prefix("robot/")?.strip_suffix("/plan")?;
    (!robot.is_empty() && !robot.contains('/')).then_some(robot)
}

/// `<root>/sim/control`: the sim answers a `get` carrying a
/// [`SimControl`](crate::sim::SimControl) with a [`SimStatus`](crate::sim::SimStatus).
pub fn sim_control(root: &str) -> String {
    format!("{root}/sim/control")
}

/// `<root>/sim/clock`: the sim publishes a [`SimClock`](crate::sim::SimClock) after
/// every step. Rate: the sim's step rate.
pub fn sim_clock(root: &str) -> String {
    format!("{root}/sim/clock")
}

/// `<root>/sim/objects`: the sim publishes the semi-static objects landed now
/// ([`ObjectsTruth`](crate::sim::ObjectsTruth)) in every step where one lands or leaves,
/// for evaluation only.
pub fn sim_objects(root: &str) -> String {
    format!("{root}/sim/objects")
}

/// `<root>/robot/<robot>/cmd`: a controller puts a
/// [`RobotCommand`](crate::sim::RobotCommand); the sim applies it at its next step.
pub fn robot_command(root: &str, robot: &str) -> String {
    format!("{root}/robot/{robot}/cmd")
}

/// `<root>/robot/*/cmd`: what the sim subscribes to.
pub fn robot_command_any(root: &str) -> String {
    format!("{root}/robot/*/cmd")
}

/// `<root>/robot/<robot>/ranges`: the sim publishes a
/// [`RangeScan`](crate::sim::RangeScan) every step.
pub fn robot_ranges(root: &str, robot: &str) -> String {
    format!("{root}/robot/{robot}/ranges")
}

/// `<root>/robot/<robot>/observation`: the sim publishes a
/// [`LocalObservation`](crate::sim::LocalObservation) every step when the scenario's
/// observation radius is above 0.
pub fn robot_observation(root: &str, robot: &str) -> String {
    format!("{root}/robot/{robot}/observation")
}

/// `<root>/robot/<robot>/truth`: the sim publishes the true position
/// ([`GroundTruth`](crate::sim::GroundTruth)) every step, for evaluation only.
pub fn robot_truth(root: &str, robot: &str) -> String {
    format!("{root}/robot/{robot}/truth")
}

/// `<root>/robot/*/truth`: every robot's, for a subscriber that follows the fleet.
pub fn robot_truth_any(root: &str) -> String {
    format!("{root}/robot/*/truth")
}

/// `<root>/robot/<robot>/events`: the sim publishes
/// [`RobotEvents`](crate::sim::RobotEvents) in the steps that have some (collisions,
/// clipped speed, displacement).
pub fn robot_events(root: &str, robot: &str) -> String {
    format!("{root}/robot/{robot}/events")
}

/// `<root>/robot/*/events`: every robot's, for a subscriber that follows the fleet.
pub fn robot_events_any(root: &str) -> String {
    format!("{root}/robot/*/events")
}

/// `<root>/robot/<robot>/estimate`: the localization service publishes a
/// [`PositionEstimate`](crate::localization::PositionEstimate) for every range scan.
pub fn robot_estimate(root: &str, robot: &str) -> String {
    format!("{root}/robot/{robot}/estimate")
}

/// `<root>/robot/*/ranges`: what the localization service subscribes to.
pub fn robot_ranges_any(root: &str) -> String {
    format!("{root}/robot/*/ranges")
}

/// `<root>/localization/peb`: the localization service answers a `get` carrying a
/// [`PebQuery`](crate::localization::PebQuery) with a
/// [`PebReply`](crate::localization::PebReply).
pub fn localization_peb(root: &str) -> String {
    format!("{root}/localization/peb")
}

/// `<root>/robot/<robot>/mission`: put a [`Mission`](crate::controller::Mission) here
/// to give the robot's controller its waypoints (replacing any it had).
pub fn robot_mission(root: &str, robot: &str) -> String {
    format!("{root}/robot/{robot}/mission")
}

/// `<root>/robot/*/mission`: what the controller subscribes to, and the mapper (it
/// counts each robot's current mission as seen ahead for the news value).
pub fn robot_mission_any(root: &str) -> String {
    format!("{root}/robot/*/mission")
}

/// `<root>/robot/*/estimate`: what the controller subscribes to.
pub fn robot_estimate_any(root: &str) -> String {
    format!("{root}/robot/*/estimate")
}

/// `<root>/robot/<robot>/controller`: the controller publishes a
/// [`ControllerStatus`](crate::controller::ControllerStatus) after every estimate and
/// whenever the mission's state changes.
pub fn robot_controller(root: &str, robot: &str) -> String {
    format!("{root}/robot/{robot}/controller")
}

/// `<root>/robot/*/controller`: every robot's, for a subscriber that follows the fleet.
pub fn robot_controller_any(root: &str) -> String {
    format!("{root}/robot/*/controller")
}

/// `<root>/robot/*/observation`: what the mapper subscribes to.
pub fn robot_observation_any(root: &str) -> String {
    format!("{root}/robot/*/observation")
}

/// `<root>/robot/<robot>/goal`: the mapper's learner publishes an
/// [`ExplorationGoal`](crate::mapper::ExplorationGoal) each time it picks one.
pub fn robot_goal(root: &str, robot: &str) -> String {
    format!("{root}/robot/{robot}/goal")
}

/// `<root>/robot/<robot>/mission_report`: the mission executive publishes a
/// [`WindowReport`](crate::mission::WindowReport) at the end of each downtime window.
pub fn robot_mission_report(root: &str, robot: &str) -> String {
    format!("{root}/robot/{robot}/mission_report")
}

/// `<root>/robot/<robot>/executive`: the mission executive publishes an
/// [`ExecutiveStatus`](crate::mission::ExecutiveStatus) after each estimate, controller
/// status and plan reply it handled (what it is doing; a lock-step driver waits on it).
pub fn robot_executive(root: &str, robot: &str) -> String {
    format!("{root}/robot/{robot}/executive")
}

/// `<root>/mapper/status`: the mapper answers a `get` (no payload) with a
/// [`MapperStatus`](crate::mapper::MapperStatus).
pub fn mapper_status(root: &str) -> String {
    format!("{root}/mapper/status")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_with_key_syntax_are_refused() {
        for bad in ["", "a/b", "a*", "$x", "a b", "ü", &"x".repeat(65)] {
            assert!(check_name("layer", bad).is_err(), "{bad:?} accepted");
        }
        assert!(check_name("layer", "change_rate-2").is_ok());
    }

    #[test]
    fn roots_may_have_segments() {
        assert!(check_root("roam").is_ok());
        assert!(check_root("site-a/roam").is_ok());
        assert!(check_root("site-a//roam").is_err());
        assert!(check_root("roam/**").is_err());
    }

    #[test]
    fn the_robot_comes_from_a_per_robot_key_only() {
        assert_eq!(robot_of("roam", "roam/robot/r1/mission"), Some("r1"));
        assert_eq!(
            robot_of("site/roam", "site/roam/robot/r-2/ranges"),
            Some("r-2")
        );
        for bad in [
            "roam/robot/r1",
            "roam/robot/r1/a/b",
            "roam/robot/*/mission",
            "roam/robot/a$b/mission",
            "other/robot/r1/mission",
            "roamx/robot/r1/mission",
        ] {
            assert_eq!(robot_of("roam", bad), None, "{bad}");
        }
    }

    #[test]
    fn a_robots_plan_keys_name_it() {
        assert_eq!(planner_robot_plan("r", "r1"), "r/planner/robot/r1/plan");
        assert_eq!(
            planner_robot_plan_at("r", "p1", "r1"),
            "r/planner/instance/p1/robot/r1/plan"
        );
        assert_eq!(
            planner_robot_cancel("r", "r1", "q"),
            "r/planner/robot/r1/cancel/q"
        );
        assert_eq!(
            planner_robot_progress("r", "r1", "q"),
            "r/planner/robot/r1/progress/q"
        );
        for key in [
            planner_robot_plan("site/r", "r-1"),
            planner_robot_plan_at("site/r", "p1", "r-1"),
        ] {
            assert_eq!(planner_robot_of("site/r", &key), Some("r-1"), "{key}");
        }
        assert_eq!(
            planner_robot_of("r", &planner_robot_plan("r", "*")),
            Some("*")
        );
        for other in [
            planner_plan("r"),
            planner_plan_at("r", "p1"),
            "r/planner/robot/a/b/plan".to_owned(),
            "r/planner/robot//plan".to_owned(),
            "r/planner/instance/p1/plan/robot/r1/plan".to_owned(),
            "rx/planner/robot/r1/plan".to_owned(),
        ] {
            assert_eq!(planner_robot_of("r", &other), None, "{other}");
        }
    }

    #[test]
    fn keys_have_the_documented_shape() {
        assert_eq!(
            liveliness("roam", "map-server", "a1"),
            "roam/@live/map-server/a1"
        );
        assert_eq!(map_layer("r", "occupancy"), "r/map/layer/occupancy");
        assert_eq!(map_delta("r", "peb"), "r/map/delta/peb");
        assert_eq!(map_delta_any("r"), "r/map/delta/*");
        assert_eq!(map_update("r", "peb"), "r/map/update/peb");
        assert_eq!(map_delete("r", "peb"), "r/map/delete/peb");
        assert_eq!(map_delete_any("r"), "r/map/delete/*");
        assert_eq!(map_index("r"), "r/map/layers");
        assert_eq!(map_load("r"), "r/map/load");
    }
}
