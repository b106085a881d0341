//! What a chaos day runs: the roles of the built-in day or of the warehouse fleet's
//! shift, their configs written where the processes read them, each robot's tasks, and
//! the robot whose executive is killed and whose pulses answer for its roles.

use std::path::Path;

use roam_experiments::reproduce::fleet::week::robot_config;
use roam_experiments::reproduce::fleet::{FleetOptions, FleetVariant, FleetWorld};
use roam_proto::planner::PlannerModel;
use serde_json::json;

use super::watch::Answer;
use crate::{setup, BenchError};

/// Which day the chaos strikes.
#[derive(Debug, Clone, PartialEq)]
pub enum ChaosSite {
    /// The built-in day: one robot, four tasks to 340 s.
    Day,
    /// The warehouse fleet's shift (`config/shifts/warehouse.yaml`): its first `robots`
    /// (1 to 10), each with its own executive, for the tasks that start within
    /// `shift_s`; each executive configured as `roam demo --fleet` configures it (the
    /// batch's `news` variant, the greedy planner), the planners on the fleet's news.
    Fleet { robots: usize, shift_s: f64 },
}

/// The most robots a fleet chaos day runs: the shift's ten.
pub const MAX_FLEET_ROBOTS: usize = 10;

/// One role of the stack: its service name, instance, extra arguments and the link it
/// reaches the router by (`None`: directly).
pub(super) struct RoleSpec {
    pub(super) service: &'static str,
    pub(super) instance: String,
    pub(super) extra: Vec<String>,
    pub(super) link: Option<&'static str>,
    pub(super) answer: Answer,
}

impl RoleSpec {
    pub(super) fn name(&self) -> String {
        format!("{}-{}", self.service, self.instance)
    }
}

/// A task as the chaos day judges its window: its name, start and duration.
pub(super) type TaskTimes = (String, f64, f64);

/// A day's roles and robots.
pub(super) struct Stage {
    pub(super) roles: Vec<RoleSpec>,
    /// Each robot's tasks as (name, start, duration), in order.
    pub(super) tasks: Vec<(String, Vec<TaskTimes>)>,
    /// The robot whose estimates and statuses answer for localization, the controller
    /// and its executive (the one the schedule kills).
    pub(super) watched: String,
    /// The scenario's robots the day does not run: removed from the sim at its start.
    pub(super) absent: Vec<String>,
    pub(super) robot_radius_m: f64,
}

fn role(
    service: &'static str,
    instance: &str,
    extra: Vec<String>,
    link: Option<&'static str>,
    answer: Answer,
) -> RoleSpec {
    RoleSpec {
        service,
        instance: instance.to_owned(),
        extra,
        link,
        answer,
    }
}

fn write(dir: &Path, name: &str, value: &serde_json::Value) -> Result<String, BenchError> {
    let path = dir.join(name);
    // JSON is YAML: the roles read it as their YAML configs.
    let text = serde_json::to_string_pretty(value).map_err(setup)?;
    std::fs::write(&path, text).map_err(setup)?;
    Ok(path.display().to_string())
}

fn config(path: String) -> Vec<String> {
    vec!["--config".into(), path]
}

/// The roles every day runs besides its executives: the map server, two planners (both
/// behind the `planners` link), the sim, localization, the controller (behind the
/// `controller` link), the mapper and the ROS 2 node, each with its config file.
fn common_roles(
    dir: &Path,
    scenario: Option<&str>,
    rate: f64,
    planner: serde_json::Value,
    apf: serde_json::Value,
    probe: ([f64; 2], [f64; 2]),
) -> Result<Vec<RoleSpec>, BenchError> {
    let path = |name: &str| dir.join(name).display().to_string();
    // Each role's config: the world's scenario where the role takes one.
    let on_world = |fields: serde_json::Value| -> serde_json::Value {
        match (fields, scenario) {
            (serde_json::Value::Object(mut map), Some(s)) => {
                map.insert("scenario".into(), json!(s));
                serde_json::Value::Object(map)
            }
            (fields, _) => fields,
        }
    };
    let map_server = match scenario {
        Some(s) => json!({ "data_dir": path("map-data"), "map": s }),
        None => json!({ "data_dir": path("map-data") }),
    };
    let map_server = write(dir, "map-server.yaml", &map_server)?;
    let planner = write(dir, "planner.yaml", &planner)?;
    let sim = on_world(json!({ "rate": rate, "state_file": path("sim.json") }));
    let sim = write(dir, "sim.yaml", &sim)?;
    let localization = write(dir, "localization.yaml", &on_world(json!({})))?;
    let controller = on_world(json!({ "stale_after_s": 1.0, "apf": apf }));
    let controller = write(dir, "controller.yaml", &controller)?;
    let mapper = write(dir, "mapper.yaml", &on_world(json!({})))?;
    let plan = |instance: &str| Answer::Plan {
        instance: instance.into(),
        start: probe.0,
        goal: probe.1,
    };
    Ok(vec![
        role("map-server", "m", config(map_server), None, Answer::Layers),
        role(
            "planner",
            "a",
            config(planner.clone()),
            Some("planners"),
            plan("a"),
        ),
        role("planner", "b", config(planner), Some("planners"), plan("b")),
        role("sim", "w", config(sim), None, Answer::Publishes("clock")),
        role(
            "localization",
            "l",
            config(localization),
            None,
            Answer::Publishes("estimate"),
        ),
        role(
            "controller",
            "c",
            config(controller),
            Some("controller"),
            Answer::Publishes("controller"),
        ),
        role("mapper", "p", config(mapper), None, Answer::MapperStatus),
        role("ros2", "r", Vec::new(), None, Answer::Token),
    ])
}

/// The executive's config file for `executive` (an `ExecutiveConfig`), with a
/// calibration file and a resume file of its own.
fn executive_role(
    dir: &Path,
    mut executive: roam_mission::config::ExecutiveConfig,
) -> Result<RoleSpec, BenchError> {
    let robot = executive.robot.clone();
    executive.calibration_file = Some(dir.join(format!("{robot}.calibration.json")));
    executive.resume_file = Some(dir.join(format!("{robot}.resume.json")));
    let value = json!({ "executive": serde_json::to_value(&executive).map_err(setup)? });
    let file = write(dir, &format!("mission-{robot}.yaml"), &value)?;
    Ok(role(
        "mission",
        &robot,
        config(file),
        None,
        Answer::Publishes("executive"),
    ))
}

/// The built-in day: config/mission.yaml's executive on the day's four tasks, and
/// config/controller.yaml's controller.
pub(super) fn day(dir: &Path, rate: f64) -> Result<Stage, BenchError> {
    #[derive(serde::Deserialize)]
    struct Shipped {
        executive: roam_mission::config::ExecutiveConfig,
    }
    #[derive(serde::Deserialize)]
    struct Controller {
        apf: serde_json::Value,
    }
    let shipped: Shipped =
        serde_yaml_ng::from_str(include_str!("../../../../config/mission.yaml")).map_err(setup)?;
    let controller: Controller =
        serde_yaml_ng::from_str(include_str!("../../../../config/controller.yaml"))
            .map_err(setup)?;
    let mut executive = shipped.executive;
    executive.tasks = roam_mission::tasks::day();
    let robot = executive.robot.clone();
    let tasks = tasks_of(&executive);
    let mut roles = common_roles(
        dir,
        None,
        rate,
        json!({}),
        controller.apf,
        ([-8.0, -8.0], [-2.0, 4.0]),
    )?;
    roles.push(executive_role(dir, executive)?);
    let radius = roam_world::scenario::builtin()
        .ok()
        .and_then(|s| s.file.robot_radius_m)
        .unwrap_or(roam_map_server::store::DerivedParams::default().robot_radius_m);
    Ok(Stage {
        roles,
        tasks: vec![(robot.clone(), tasks)],
        watched: robot,
        absent: Vec::new(),
        robot_radius_m: radius,
    })
}

/// The warehouse fleet's shift: the first `robots` robots with tasks within `shift_s`.
pub(super) fn fleet(
    dir: &Path,
    rate: f64,
    robots: usize,
    shift_s: f64,
    seed: u64,
) -> Result<Stage, BenchError> {
    let world = FleetWorld::warehouse().map_err(setup)?;
    if robots == 0 || robots > MAX_FLEET_ROBOTS.min(world.shift.robots.len()) {
        return Err(BenchError::Setup(format!(
            "--robots must be 1 to {MAX_FLEET_ROBOTS}, got {robots}"
        )));
    }
    if !(shift_s > 0.0 && shift_s <= world.shift.length_s) {
        return Err(BenchError::Setup(format!(
            "--shift-s must be in (0, {}] seconds (the shift's length), got {shift_s}",
            world.shift.length_s
        )));
    }
    let scenario = dir.join("warehouse.yaml");
    std::fs::write(&scenario, roam_mission::shift::WAREHOUSE_SCENARIO).map_err(setup)?;
    let scenario = scenario.display().to_string();
    let batch = FleetOptions {
        seed,
        w_loc: 2000.0,
        model: PlannerModel::Greedy,
        avoid_seen: true,
        ..FleetOptions::default()
    };
    let executives: Vec<roam_mission::config::ExecutiveConfig> = world.shift.robots[..robots]
        .iter()
        .enumerate()
        .map(|(index, r)| {
            let tasks = r
                .tasks
                .iter()
                .filter(|t| t.start_s <= shift_s)
                .cloned()
                .collect();
            robot_config(FleetVariant::News, &r.robot, index, tasks, &batch)
        })
        .filter(|c| !c.tasks.is_empty())
        .collect();
    let first = executives
        .first()
        .ok_or_else(|| BenchError::Setup(format!("no robot has a task within {shift_s} s")))?;
    let watched = first.robot.clone();
    // The planners' probe: the watched robot's way from its start to its first task.
    let start = world
        .shift
        .robots
        .iter()
        .find(|r| r.robot == watched)
        .map_or([0.0, 0.0], |r| r.start);
    let probe = (start, first.tasks.first().map_or(start, |t| t.at));
    let planner = json!({
        "change_layer": roam_proto::mapper::NEWS_LAYER,
        "coupling": "news",
        "obstacles_layer": roam_proto::mapper::OCCUPIED_NOW_LAYER,
    });
    let apf = serde_json::to_value(roam_controller::params::ApfParams::fleet()).map_err(setup)?;
    let mut roles = common_roles(dir, Some(&scenario), rate, planner, apf, probe)?;
    let tasks = executives
        .iter()
        .map(|c| (c.robot.clone(), tasks_of(c)))
        .collect();
    for executive in executives {
        roles.push(executive_role(dir, executive)?);
    }
    let text = roam_mission::shift::WAREHOUSE_SCENARIO;
    let radius =
        roam_world::scenario::parse(Path::new(&scenario), text, roam_world::DEFAULT_MAX_CELLS)
            .ok()
            .and_then(|s| s.file.robot_radius_m)
            .unwrap_or(roam_map_server::store::DerivedParams::default().robot_radius_m);
    Ok(Stage {
        roles,
        tasks,
        watched,
        absent: world.shift.robots[robots..]
            .iter()
            .map(|r| r.robot.clone())
            .collect(),
        robot_radius_m: radius,
    })
}

fn tasks_of(executive: &roam_mission::config::ExecutiveConfig) -> Vec<TaskTimes> {
    executive
        .tasks
        .iter()
        .map(|t| (t.name.clone(), t.start_s, t.duration_s))
        .collect()
}
