//! A fleet's shift: each robot's tasks for one shift, the gaps between them its
//! downtime windows. What `roam reproduce fleet` and a fleet's executives run.
//!
//! ```yaml
//! # config/shifts/warehouse.yaml
//! length_s: 3600            # a shift; the next begins where it ends (a week: 7 of them)
//! robots:
//!   - robot: r1
//!     tasks:
//!       - { name: pick-1, place: aisle-3-south, start_s: 95.0, duration_s: 40.0 }
//!       - { name: dock-1, at: [12.0, 6.5], start_s: 260.0, duration_s: 30.0 }
//! ```
//!
//! A task names a place of the scenario (`place`) or gives its point (`at`, world
//! metres), not both. Every robot is one of the scenario's robots, once. Each robot's
//! tasks are checked as a day is ([`crate::tasks::check`]: order, overlaps) and, given a
//! map, as the executive checks its day ([`crate::day_check`]: places free and reached
//! in time from the one before, the first from the robot's start), so a shift that no
//! robot can keep is refused when it is loaded, naming the robot, the task and the
//! seconds missing.

use roam_planner::world::World;
use roam_world::scenario::{Place, RobotStart};
use serde::Deserialize;

use crate::calibration::TimeModel;
use crate::day_check::check_day;
use crate::tasks::{self, Task, TaskError};

/// The most robots a shift takes (the sim's limit).
pub const MAX_SHIFT_ROBOTS: usize = 1000;
/// The most corners a patrol loop has.
pub const MAX_PATROL_CORNERS: usize = 1000;
/// The longest shift, seconds (a day).
pub const MAX_SHIFT_S: f64 = 86_400.0;

/// The warehouse's shift (`config/shifts/warehouse.yaml`), built in.
pub const WAREHOUSE_SHIFT: &str = include_str!("../../../config/shifts/warehouse.yaml");
/// The warehouse (`config/scenarios/warehouse.yaml`), built in.
pub const WAREHOUSE_SCENARIO: &str = include_str!("../../../config/scenarios/warehouse.yaml");

/// A shift file as written.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShiftFile {
    /// How long one shift is, seconds: the next shift's tasks are these, this much later.
    pub length_s: f64,
    pub robots: Vec<RobotShiftFile>,
    /// The operator's patrol (`roam reproduce fleet`'s `patrol` variant): the corners
    /// of a loop, world metres, driven in order and back to the first. The built-in
    /// warehouse has its own (through every aisle); elsewhere the variant needs it.
    #[serde(default)]
    pub patrol: Vec<[f64; 2]>,
}

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotShiftFile {
    pub robot: String,
    pub tasks: Vec<ShiftTask>,
}

/// A task of a shift file: at a named place or a point.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShiftTask {
    pub name: String,
    #[serde(default)]
    pub place: Option<String>,
    #[serde(default)]
    pub at: Option<[f64; 2]>,
    pub start_s: f64,
    pub duration_s: f64,
}

/// A shift with its places resolved: each robot's tasks, in the file's order.
#[derive(Debug, Clone, PartialEq)]
pub struct Shift {
    pub length_s: f64,
    pub robots: Vec<RobotShift>,
    /// The patrol's corners (empty: none given).
    pub patrol: Vec<[f64; 2]>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct RobotShift {
    pub robot: String,
    /// Where the robot starts the first shift (the scenario's start).
    pub start: [f64; 2],
    pub tasks: Vec<Task>,
}

/// Why a shift is refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ShiftError {
    #[error("the shift file does not parse: {0}")]
    Parse(String),
    #[error("{field}: {reason}")]
    Field { field: String, reason: String },
    #[error("robot {robot:?}: {error}")]
    Tasks { robot: String, error: TaskError },
}

fn field(field: impl Into<String>, reason: impl Into<String>) -> ShiftError {
    ShiftError::Field {
        field: field.into(),
        reason: reason.into(),
    }
}

impl Shift {
    /// Parses `text` and resolves its places against the scenario's `places` and
    /// `robots`, checking everything that needs no map.
    pub fn parse(text: &str, places: &[Place], robots: &[RobotStart]) -> Result<Shift, ShiftError> {
        let file: ShiftFile =
            serde_yaml_ng::from_str(text).map_err(|e| ShiftError::Parse(e.to_string()))?;
        Shift::resolve(file, places, robots)
    }

    /// A shift file resolved against a scenario's places and robots.
    pub fn resolve(
        file: ShiftFile,
        places: &[Place],
        robots: &[RobotStart],
    ) -> Result<Shift, ShiftError> {
        if !(file.length_s.is_finite() && file.length_s > 0.0 && file.length_s <= MAX_SHIFT_S) {
            return Err(field(
                "length_s",
                format!(
                    "{} s; give a shift of (0, {MAX_SHIFT_S}] seconds",
                    file.length_s
                ),
            ));
        }
        if file.robots.is_empty() || file.robots.len() > MAX_SHIFT_ROBOTS {
            return Err(field(
                "robots",
                format!(
                    "{} robots; give 1..={MAX_SHIFT_ROBOTS} (max_shift_robots)",
                    file.robots.len()
                ),
            ));
        }
        let mut out = Vec::with_capacity(file.robots.len());
        for (i, r) in file.robots.into_iter().enumerate() {
            if out.iter().any(|o: &RobotShift| o.robot == r.robot) {
                return Err(field(
                    format!("robots[{i}].robot"),
                    format!("robot {:?} has two shifts", r.robot),
                ));
            }
            let start = robots
                .iter()
                .find(|s| s.name == r.robot)
                .map(|s| s.at)
                .ok_or_else(|| {
                    field(
                        format!("robots[{i}].robot"),
                        format!("{:?} is not one of the scenario's robots", r.robot),
                    )
                })?;
            let mut tasks = Vec::with_capacity(r.tasks.len());
            for (j, t) in r.tasks.into_iter().enumerate() {
                let f = |name: &str| format!("robots[{i}].tasks[{j}].{name}");
                let at = match (&t.place, t.at) {
                    (Some(name), None) => places
                        .iter()
                        .find(|p| &p.name == name)
                        .map(|p| p.at)
                        .ok_or_else(|| {
                            field(f("place"), format!("no place {name:?} in the scenario"))
                        })?,
                    (None, Some(at)) => at,
                    _ => {
                        return Err(field(
                            f("place"),
                            format!("task {:?}: give a place or an at, one of them", t.name),
                        ))
                    }
                };
                if t.start_s + t.duration_s > file.length_s {
                    return Err(field(
                        f("start_s"),
                        format!(
                            "task {:?} ends at {} s, after the shift's {} s",
                            t.name,
                            t.start_s + t.duration_s,
                            file.length_s
                        ),
                    ));
                }
                tasks.push(Task {
                    name: t.name,
                    at,
                    start_s: t.start_s,
                    duration_s: t.duration_s,
                });
            }
            tasks::check(&tasks).map_err(|error| ShiftError::Tasks {
                robot: r.robot.clone(),
                error,
            })?;
            out.push(RobotShift {
                robot: r.robot,
                start,
                tasks,
            });
        }
        if file.patrol.len() == 1 || file.patrol.len() > MAX_PATROL_CORNERS {
            return Err(field(
                "patrol",
                format!(
                    "{} corners; give none or 2..={MAX_PATROL_CORNERS}",
                    file.patrol.len()
                ),
            ));
        }
        if let Some(i) = file
            .patrol
            .iter()
            .position(|p| !(p[0].is_finite() && p[1].is_finite()))
        {
            return Err(field(format!("patrol[{i}]"), "give a finite point"));
        }
        Ok(Shift {
            length_s: file.length_s,
            robots: out,
            patrol: file.patrol,
        })
    }

    /// Checks every robot's shift on `world` with `time_model` (module doc), and the
    /// move from each shift's last task to the next shift's first.
    pub fn check_on(&self, world: &World, time_model: TimeModel) -> Result<(), ShiftError> {
        for r in &self.robots {
            let two = self.repeated(r, 2);
            check_day(&two, world, time_model, Some(r.start)).map_err(|error| {
                ShiftError::Tasks {
                    robot: r.robot.clone(),
                    error,
                }
            })?;
        }
        Ok(())
    }

    /// Robot `r`'s tasks over `shifts` shifts in a row, each shift `length_s` after the
    /// one before; task names carry their shift (`pick-1@2`).
    pub fn repeated(&self, r: &RobotShift, shifts: usize) -> Vec<Task> {
        (0..shifts)
            .flat_map(|d| {
                let offset = d as f64 * self.length_s;
                r.tasks.iter().map(move |t| Task {
                    name: if d == 0 {
                        t.name.clone()
                    } else {
                        format!("{}@{}", t.name, d + 1)
                    },
                    at: t.at,
                    start_s: t.start_s + offset,
                    duration_s: t.duration_s,
                })
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_world::scenario;
    use std::path::Path;

    fn warehouse() -> roam_world::scenario::Scenario {
        scenario::parse(
            Path::new("warehouse.yaml"),
            WAREHOUSE_SCENARIO,
            roam_world::DEFAULT_MAX_CELLS,
        )
        .expect("the warehouse parses")
    }

    fn parse(text: &str) -> Result<Shift, ShiftError> {
        let s = warehouse();
        Shift::parse(text, &s.file.places, &s.file.robots)
    }

    #[test]
    fn the_warehouse_shift_parses_with_ten_robots() {
        let shift = parse(WAREHOUSE_SHIFT).expect("parses");
        assert_eq!(shift.robots.len(), 10);
        assert!(shift.robots.iter().all(|r| r.tasks.len() >= 5));
        let twice = shift.repeated(&shift.robots[0], 2);
        assert_eq!(twice.len(), 2 * shift.robots[0].tasks.len());
        assert!(twice[shift.robots[0].tasks.len()].name.ends_with("@2"));
    }

    #[test]
    fn every_robot_keeps_the_warehouse_shift_two_shifts_in_a_row() {
        let s = warehouse();
        let shift = Shift::parse(WAREHOUSE_SHIFT, &s.file.places, &s.file.robots).expect("parses");
        let inflated = roam_world::layers::inflate(&s.occupancy, 0.25, 65);
        let world = World::at_resolution(&inflated, &s.information, 0.25, 0.2).expect("world");
        shift.check_on(&world, TimeModel::table_i()).expect("kept");
        // A task moved to a wall is refused naming the robot and the task.
        let mut bad = shift.clone();
        bad.robots[3].tasks[2].at = [9.5, 12.0];
        let e = bad
            .check_on(&world, TimeModel::table_i())
            .expect_err("in a rack");
        assert!(e.to_string().contains("r4"), "{e}");
    }

    #[test]
    fn bad_shifts_are_refused_naming_the_field() {
        let refused = |text: &str, what: &str| {
            let e = parse(text).expect_err(text).to_string();
            assert!(e.contains(what), "{e}");
        };
        refused("length_s: 100\nrobots: []\n", "robots");
        refused(
            "length_s: -1\nrobots: [{robot: r1, tasks: []}]\n",
            "length_s",
        );
        refused(
            "length_s: 100\nrobots: [{robot: nobody, tasks: [{name: a, at: [3, 31], start_s: 10, duration_s: 5}]}]\n",
            "not one of the scenario's robots",
        );
        refused(
            "length_s: 100\nrobots: [{robot: r1, tasks: [{name: a, place: nowhere, start_s: 10, duration_s: 5}]}]\n",
            "no place",
        );
        refused(
            "length_s: 100\nrobots: [{robot: r1, tasks: [{name: a, at: [3, 31], start_s: 10, duration_s: 5}, {name: b, at: [3, 31], start_s: 12, duration_s: 5}]}]\n",
            "r1",
        );
        refused(
            "length_s: 100\nrobots: [{robot: r1, tasks: [{name: a, at: [3, 31], start_s: 99, duration_s: 5}]}]\n",
            "after the shift",
        );
        let one = "length_s: 100\nrobots: [{robot: r1, tasks: [{name: a, at: [3, 31], start_s: 10, duration_s: 5}]}]\n";
        refused(&format!("{one}patrol: [[1, 2]]\n"), "patrol");
        refused(&format!("{one}patrol: [[1, 2], [.nan, 3]]\n"), "patrol[1]");
        let loop_ = parse(&format!("{one}patrol: [[1, 2], [3, 4]]\n")).expect("a loop");
        assert_eq!(loop_.patrol, vec![[1.0, 2.0], [3.0, 4.0]]);
    }
}
