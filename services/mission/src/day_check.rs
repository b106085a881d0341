//! A day of tasks checked against a map, before anything is driven: every
//! task's place must be where the robot can stand, and every task must be reachable in
//! time from the previous one.
//!
//! "In time" is paper 000's floor, what the planner checks every budget against: the
//! fastest path by Eq. 2 (`v_lin · Σd + v_ang · Σθ`, turns counted) with the robot's
//! time model, as the robot drives it (on the map's cells when the planner plans at a
//! coarser resolution). The leg from one task to the next has the gap between them:
//! the next task's start less the end of the previous one (its start plus its
//! duration). The first task's leg, when a start position is given, begins there at 0 s
//! on the mission clock. A round trip (the same place twice) takes no time.
//!
//! The paths come from the planner itself ([`roam_planner::plan::plan`] with the
//! `shortest` baseline: its fastest path, with the same refusals of places off the
//! map, in walls or their inflation, or in a pocket no planning cell reaches), so the
//! check agrees with what the planner will later accept. The gap is an upper bound of
//! what a window gives the drive: planning and the arrival margin take their share at
//! run time, so a day that passes may still be tight; a day refused here cannot work.

use std::sync::atomic::AtomicBool;

use roam_planner::params::GaParams;
use roam_planner::plan::{self, PlanError, PlanSpec, MAX_DEADLINE_S, MAX_T_EXEC_S};
use roam_planner::world::World;
use roam_proto::planner::{PlannerModel, ShortestPathUse};

use crate::calibration::TimeModel;
use crate::tasks::{self, LegFrom, Task, TaskError};

/// Checks `tasks` against `world` with the robot's `time_model`: first [`tasks::check`]
/// (a non-empty list, finite places, no overlaps), then that the start (when given) and
/// every task's place are free ([`TaskError::StartBlocked`], [`TaskError::Blocked`]),
/// then each leg in order: the first from `start` (when given) with the gap
/// `tasks[0].start_s`, each next one from the previous task
/// ([`TaskError::NoPath`], [`TaskError::Unreachable`] naming both ends and the seconds
/// missing).
pub fn check_day(
    tasks: &[Task],
    world: &World,
    time_model: TimeModel,
    start: Option<[f64; 2]>,
) -> Result<(), TaskError> {
    tasks::check(tasks)?;
    if let Some(at) = start {
        if !(at[0].is_finite() && at[1].is_finite()) {
            return Err(TaskError::StartBlocked {
                at,
                why: "is not a finite point".into(),
            });
        }
        free_place(world, time_model, at).map_err(|e| match e {
            Leg::Place(why) => TaskError::StartBlocked { at, why },
            Leg::Model(e) => model_error(time_model, e),
            Leg::NoPath => TaskError::StartBlocked {
                at,
                why: "has no path to itself".into(),
            },
        })?;
    }
    for task in tasks {
        free_place(world, time_model, task.at).map_err(|e| match e {
            Leg::Place(why) => TaskError::Blocked {
                name: task.name.clone(),
                at: task.at,
                why,
            },
            Leg::Model(e) => model_error(time_model, e),
            Leg::NoPath => TaskError::Blocked {
                name: task.name.clone(),
                at: task.at,
                why: "has no path to itself".into(),
            },
        })?;
    }
    let first = start.map(|at| (LegFrom::Start { at }, at, 0.0));
    let rest = tasks.windows(2).map(|pair| {
        let prev = &pair[0];
        (
            LegFrom::Task {
                name: prev.name.clone(),
            },
            prev.at,
            prev.start_s + prev.duration_s,
        )
    });
    let legs = first
        .into_iter()
        .chain(rest)
        .zip(if start.is_some() { tasks } else { &tasks[1..] });
    for ((from, from_at, free_at_s), task) in legs {
        let gap_s = task.start_s - free_at_s;
        let fastest = fastest_s(world, time_model, from_at, task.at).map_err(|e| match e {
            Leg::NoPath => TaskError::NoPath {
                name: task.name.clone(),
                at: task.at,
                from: from.clone(),
            },
            // Both places passed alone; kept for completeness.
            Leg::Place(why) => TaskError::Blocked {
                name: task.name.clone(),
                at: task.at,
                why,
            },
            Leg::Model(e) => model_error(time_model, e),
        })?;
        if fastest > gap_s {
            return Err(TaskError::Unreachable {
                name: task.name.clone(),
                at: task.at,
                from,
                fastest_s: fastest,
                gap_s,
                missing_s: fastest - gap_s,
            });
        }
    }
    Ok(())
}

/// Why a leg could not be timed.
enum Leg {
    /// An end is where no plan begins or ends (off the map, blocked, a pocket): why.
    Place(String),
    /// No path joins the two ends.
    NoPath,
    /// The planner refused the time model.
    Model(PlanError),
}

/// Whether a plan may begin and end at `at`: the planner's round trip there with the
/// `shortest` baseline (which stays: no loop is asked for).
fn free_place(world: &World, time_model: TimeModel, at: [f64; 2]) -> Result<(), Leg> {
    fastest_s(world, time_model, at, at).map(|_| ())
}

/// The planner's fastest path from `from` to `to` (Eq. 2 with turns, as driven), in
/// seconds: the `shortest` baseline of one plan request with the time model's v_lin and
/// v_ang, its budget the largest a request may have and answered with the fastest path
/// whatever the budget (`ShortestPathUse::Fallback`), so only the path decides.
fn fastest_s(
    world: &World,
    time_model: TimeModel,
    from: [f64; 2],
    to: [f64; 2],
) -> Result<f64, Leg> {
    let spec = PlanSpec {
        start: from,
        goal: to,
        t_exec_s: MAX_T_EXEC_S,
        deadline_s: MAX_DEADLINE_S,
        model: PlannerModel::Shortest,
        params: GaParams {
            v_lin: time_model.v_lin,
            v_ang: time_model.v_ang,
            ..GaParams::default()
        },
        seed: 0,
        threads: 1,
        limits: Default::default(),
        shortest: ShortestPathUse::Fallback,
        seed_route: Vec::new(),
    };
    let outcome =
        plan::plan(world, &spec, &AtomicBool::new(false), |_, _| {}).map_err(|e| match e {
            PlanError::NoPath => Leg::NoPath,
            PlanError::OffMap { x0, x1, y0, y1, .. } => Leg::Place(format!(
                "is off the map, which spans x {x0}..{x1} and y {y0}..{y1} m"
            )),
            PlanError::Blocked { .. } => Leg::Place(
                "is in a wall, its inflation or unknown space: move it to free floor".into(),
            ),
            PlanError::Pocket { .. } => Leg::Place(
                "is free on the map but in a pocket of free space that no planning cell \
                 reaches: move it, or plan at a finer planning_resolution_m"
                    .into(),
            ),
            e => Leg::Model(e),
        })?;
    // The fastest path as the robot drives it, what the budget floor is checked
    // against (`Checked::fastest_t_eta_s`); the baseline's own path is the same one.
    Ok(outcome
        .shortest
        .map_or(outcome.t_eta_s, |fastest| fastest.t_eta_s))
}

fn model_error(time_model: TimeModel, e: PlanError) -> TaskError {
    TaskError::TimeModel {
        v_lin: time_model.v_lin,
        v_ang: time_model.v_ang,
        what: e.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use roam_planner::eta::path_eta;
    use roam_planner::search::fastest_path;
    use roam_world::grid::{world_to_cell, Grid};
    use roam_world::layers::inflate;
    use roam_world::scenario::{self, Scenario};
    use roam_world::DEFAULT_MAX_CELLS;

    use super::*;
    use crate::tasks::{day, DAY_SCENARIO};

    /// The day scenario's occupancy and information, as the planner's map cache has
    /// them (the map server's inflation at the scenario's robot radius).
    fn day_maps() -> (Scenario, f64) {
        let scenario = scenario::parse(Path::new("day.yaml"), DAY_SCENARIO, DEFAULT_MAX_CELLS)
            .expect("the day scenario parses");
        let radius = scenario.file.robot_radius_m.unwrap_or(0.2);
        (scenario, radius)
    }

    fn world_of(occupancy: &Grid<i8>, information: &Grid<u8>, radius: f64) -> World {
        World::new(&inflate(occupancy, radius, 65), information, 0.25).expect("a world")
    }

    fn day_world() -> World {
        let (scenario, radius) = day_maps();
        world_of(&scenario.occupancy, &scenario.information, radius)
    }

    fn robot_start() -> [f64; 2] {
        day_maps().0.file.robots[0].at
    }

    #[test]
    fn the_shipped_day_passes_on_its_world() {
        let world = day_world();
        let start = Some(robot_start());
        for model in [
            TimeModel::table_i(),
            TimeModel {
                v_lin: 1.5,
                v_ang: 0.5,
            },
        ] {
            assert_eq!(check_day(&day(), &world, model, start), Ok(()));
            assert_eq!(check_day(&day(), &world, model, None), Ok(()));
        }
    }

    #[test]
    fn a_task_in_a_wall_or_off_the_map_is_refused_naming_it() {
        let world = day_world();
        let mut tasks = day();
        // The wall x ∈ [-0.2, 0.2], y ∈ [-10, -6].
        tasks[1].at = [0.0, -8.0];
        let err = check_day(&tasks, &world, TimeModel::table_i(), None).expect_err("refused");
        assert!(
            matches!(&err, TaskError::Blocked { name, at, .. } if name == "goal2" && *at == [0.0, -8.0]),
            "{err:?}"
        );
        let text = err.to_string();
        assert!(
            text.starts_with("task \"goal2\": its place [0.0, -8.0] is in a wall"),
            "{text}"
        );
        // Its inflation: 0.1 m off the wall's face, within the 0.2 m robot radius.
        tasks[1].at = [0.3, -8.0];
        let err = check_day(&tasks, &world, TimeModel::table_i(), None).expect_err("refused");
        assert!(
            matches!(&err, TaskError::Blocked { name, .. } if name == "goal2"),
            "{err:?}"
        );
        // Off the map.
        let mut tasks = day();
        tasks[3].at = [30.0, 0.0];
        let err = check_day(&tasks, &world, TimeModel::table_i(), None).expect_err("refused");
        assert!(
            matches!(&err, TaskError::Blocked { name, .. } if name == "home"),
            "{err:?}"
        );
        assert!(err.to_string().contains("off the map"), "{err}");
        // A start in a wall.
        let err = check_day(&day(), &world, TimeModel::table_i(), Some([0.0, -8.0]))
            .expect_err("refused");
        assert!(matches!(err, TaskError::StartBlocked { .. }), "{err:?}");
    }

    #[test]
    fn a_task_that_starts_too_soon_is_refused_with_the_seconds_missing() {
        let world = day_world();
        let model = TimeModel::table_i();
        let mut tasks = day();
        let (from, to) = (tasks[0].at, tasks[1].at);
        // The fastest path, computed apart from the check: Eq. 2 with turns at Table I.
        let params = GaParams {
            v_lin: model.v_lin,
            v_ang: model.v_ang,
            ..GaParams::default()
        };
        let cell = |p: [f64; 2]| world.cell_at(p[0], p[1]).expect("on the map");
        let path = fastest_path(&world, &params, cell(from), cell(to)).expect("a path");
        let fastest = path_eta(&world, &params, &path);
        assert!(fastest > 20.0, "{fastest}");
        // goal2 starts 10 s sooner than the fastest drive from the end of goal1.
        let end_of_goal1 = tasks[0].start_s + tasks[0].duration_s;
        tasks[1].start_s = end_of_goal1 + fastest - 10.0;
        let err = check_day(&tasks, &world, model, Some(robot_start())).expect_err("refused");
        let TaskError::Unreachable {
            name,
            at,
            from: leg_from,
            fastest_s,
            gap_s,
            missing_s,
        } = &err
        else {
            panic!("{err:?}");
        };
        assert_eq!(name, "goal2");
        assert_eq!(*at, to);
        assert_eq!(
            *leg_from,
            LegFrom::Task {
                name: "goal1".into()
            }
        );
        assert!(
            (fastest_s - fastest).abs() < 1e-9,
            "{fastest_s} vs {fastest}"
        );
        assert!((gap_s - (fastest - 10.0)).abs() < 1e-9, "{gap_s}");
        assert!((missing_s - 10.0).abs() < 1e-9, "{missing_s}");
        let text = err.to_string();
        assert_eq!(
            text,
            format!(
                "task \"goal2\": its place [6.0, -7.0] cannot be reached from \"goal1\" in time: \
                 the fastest path takes {fastest:.1} s, the gap is {:.1} s (10.0 s missing)",
                fastest - 10.0
            )
        );
        // Exactly the fastest drive fits.
        tasks[1].start_s = end_of_goal1 + fastest;
        assert_eq!(
            check_day(&tasks, &world, model, Some(robot_start())),
            Ok(())
        );
        // A slower robot (its own time model) misses the same day's goal2.
        let slow = TimeModel {
            v_lin: 6.0,
            v_ang: 1.0,
        };
        let err = check_day(&day(), &world, slow, None).expect_err("refused");
        assert!(matches!(&err, TaskError::Unreachable { .. }), "{err:?}");
    }

    #[test]
    fn the_first_task_is_checked_from_the_start() {
        let world = day_world();
        let mut tasks = day();
        tasks[0].start_s = 10.0;
        // Without a start the first task has no leg.
        assert_eq!(
            check_day(&tasks, &world, TimeModel::table_i(), None),
            Ok(())
        );
        let err = check_day(&tasks, &world, TimeModel::table_i(), Some(robot_start()))
            .expect_err("refused");
        assert!(
            matches!(&err, TaskError::Unreachable { name, from: LegFrom::Start { .. }, gap_s, .. }
                if name == "goal1" && *gap_s == 10.0),
            "{err:?}"
        );
        assert!(
            err.to_string()
                .contains("from the start [-8.0, -8.0] in time"),
            "{err}"
        );
    }

    #[test]
    fn an_enclosed_place_is_refused() {
        let (scenario, radius) = day_maps();
        let mut occupancy = scenario.occupancy.clone();
        // A closed 2 x 2 m box of wall around (-6, 0), free inside.
        let meta = occupancy.meta;
        let (cx, cy) = world_to_cell(&meta, -6.0, 0.0).expect("on the map");
        let half = 5usize; // cells of 0.2 m
        for x in cx - half..=cx + half {
            for y in cy - half..=cy + half {
                if x.abs_diff(cx) == half || y.abs_diff(cy) == half {
                    occupancy.cells[y * meta.width as usize + x] = 100;
                }
            }
        }
        let world = world_of(&occupancy, &scenario.information, radius);
        let mut tasks = day();
        tasks[1].at = [-6.0, 0.0];
        let err = check_day(&tasks, &world, TimeModel::table_i(), None).expect_err("refused");
        assert!(
            matches!(&err, TaskError::NoPath { name, from: LegFrom::Task { name: prev }, .. }
                if name == "goal2" && prev == "goal1"),
            "{err:?}"
        );
        assert!(
            err.to_string().contains("cannot be reached from \"goal1\""),
            "{err}"
        );
        // The same place as the first task, from the start.
        let mut tasks = day();
        tasks[0].at = [-6.0, 0.0];
        let err = check_day(&tasks, &world, TimeModel::table_i(), Some(robot_start()))
            .expect_err("refused");
        assert!(
            matches!(&err, TaskError::NoPath { name, from: LegFrom::Start { .. }, .. } if name == "goal1"),
            "{err:?}"
        );
    }
}
