//! A user's site from generated Nav2 maps: what loads, what defaults it gets, what is
//! refused and how the refusal names the problem.

use std::path::{Path, PathBuf};

use roam_proto::map::{GridMeta, Origin};
use roam_world::grid::Grid;
use roam_world::ros_map::{save, SaveParams};

use super::*;

/// A 12 × 8 m room at 5 cm with border walls and a wall from the south up to y = 5 m at
/// x = 6 m, written as a Nav2 map (`room.yaml`, `room.pgm`) in `dir`.
fn room_map(dir: &Path) -> PathBuf {
    let (w, h, res) = (240u32, 160u32, 0.05);
    let meta = GridMeta {
        width: w,
        height: h,
        resolution: res,
        origin: Origin::default(),
    };
    let mut grid = Grid::filled(meta, 0i8);
    for y in 0..h as usize {
        for x in 0..w as usize {
            let border = x == 0 || y == 0 || x == w as usize - 1 || y == h as usize - 1;
            let wall = (119..=121).contains(&x) && y < 100;
            if border || wall {
                grid.cells[y * w as usize + x] = 100;
            }
        }
    }
    let path = dir.join("room.yaml");
    save(&grid, &path, SaveParams::default()).expect("save the room");
    path
}

const DAY: &str = "
robot: { at: [1.5, 1.5] }
tasks:
  - { name: east, at: [10.0, 1.5], start_s: 60 }
  - { name: back, at: [1.5, 6.5], start_s: 140, duration_s: 10 }
";

/// The day on the room; the directory holds the map as long as the site is used.
fn load(day: &str) -> (tempfile::TempDir, Result<Site, SiteError>) {
    let dir = tempfile::tempdir().expect("tmp");
    let map = room_map(dir.path());
    let site = Site::from_text(&map, day, "room-day");
    (dir, site)
}

#[test]
fn a_day_on_a_nav2_map_loads_with_its_defaults() {
    let (_dir, site) = load(DAY);
    let site = site.expect("the day loads");
    assert_eq!(site.robot, "robot");
    assert_eq!(site.tasks.len(), 2);
    assert_eq!(site.tasks[1].duration_s, 10.0);
    let scenario = site.scenario().expect("the written scenario parses again");
    assert_eq!(scenario.occupancy.meta.resolution, 0.05);
    assert_eq!(scenario.file.sensing.observation_radius_m, 3.0);
    assert_eq!(scenario.file.robots[0].at, [1.5, 1.5]);
    // Every cell scores the default when the file gives no information.
    assert!(scenario
        .information
        .cells
        .iter()
        .all(|&s| s == DEFAULT_SCORE));
    // 30 m of range over a 12 × 8 m room: the lattice is its four corners.
    assert_eq!(scenario.file.anchors.len(), 4);
    assert!(site.warnings.is_empty(), "{:?}", site.warnings);
}

#[test]
fn the_lattice_gives_every_free_cell_a_fix_where_the_range_is_short() {
    let dir = tempfile::tempdir().expect("tmp");
    let map = room_map(dir.path());
    let scenario = Site::from_text(&map, DAY, "room-day")
        .expect("loads")
        .scenario()
        .expect("parses");
    for range in [2.0, 3.5, 5.0] {
        let anchors = lattice_anchors(&scenario.occupancy, range);
        assert!(
            anchors.len() > 4,
            "range {range}: {} anchors",
            anchors.len()
        );
        assert_eq!(
            uncovered_warning(&scenario.occupancy, &anchors, range),
            None,
            "range {range}"
        );
    }
}

#[test]
fn anchors_the_file_gives_are_kept_and_their_gaps_named() {
    let day = format!(
        "{DAY}sensing: {{ range_m: 6.0 }}\nanchors:\n  - {{ name: a, at: [0.5, 0.5] }}\n  - {{ name: b, at: [5.0, 0.5] }}\n  - {{ name: c, at: [0.5, 7.5] }}\n"
    );
    let (_dir, site) = load(&day);
    let site = site.expect("loads");
    let scenario = site.scenario().expect("parses");
    assert_eq!(scenario.file.anchors.len(), 3);
    // The file's sensing is kept, with the default observation radius it leaves out.
    assert_eq!(scenario.file.sensing.range_m, 6.0);
    assert_eq!(scenario.file.sensing.observation_radius_m, 3.0);
    assert_eq!(site.warnings.len(), 1);
    let warning = &site.warnings[0];
    assert!(
        warning.contains("free cells hear fewer than three anchors within 6 m"),
        "{warning}"
    );
    assert!(warning.contains("hears"), "{warning}");
}

#[test]
fn a_task_in_a_wall_is_refused_by_name() {
    let day = DAY.replace("[10.0, 1.5]", "[6.0, 2.0]");
    match load(&day).1 {
        Err(SiteError::Tasks {
            error: TaskError::Blocked { name, .. },
            ..
        }) => assert_eq!(name, "east"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_task_that_cannot_be_reached_in_time_names_the_seconds_missing() {
    let day = DAY.replace("start_s: 60", "start_s: 8");
    match load(&day).1 {
        Err(
            e @ SiteError::Tasks {
                error: TaskError::Unreachable { .. },
                ..
            },
        ) => assert!(e.to_string().contains("s missing"), "{e}"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn overlapping_tasks_are_refused() {
    let day = DAY.replace("start_s: 140, duration_s: 10", "start_s: 62");
    let day = day.replace("start_s: 60 }", "start_s: 60, duration_s: 5 }");
    match load(&day).1 {
        Err(e @ SiteError::Tasks { .. }) => {
            assert!(e.to_string().contains("back"), "{e}")
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_map_without_free_cells_is_refused() {
    let dir = tempfile::tempdir().expect("tmp");
    let meta = GridMeta {
        width: 240,
        height: 160,
        resolution: 0.05,
        origin: Origin::default(),
    };
    let path = dir.path().join("solid.yaml");
    save(&Grid::filled(meta, 100i8), &path, SaveParams::default()).expect("save");
    match Site::from_text(&path, DAY, "solid") {
        Err(e @ SiteError::NoFreeCells { .. }) => {
            assert!(e.to_string().contains("no free cell"), "{e}")
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn an_anchor_off_the_map_is_refused_naming_the_field() {
    let day = format!("{DAY}anchors:\n  - {{ name: far, at: [40.0, 1.0] }}\n");
    match load(&day).1 {
        Err(SiteError::Scenario(message)) => {
            assert!(message.contains("anchors[0].at"), "{message}")
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn unknown_fields_and_a_missing_robot_are_refused() {
    for (day, needle) in [
        (format!("{DAY}speed: 3\n"), "speed"),
        (DAY.replace("robot: { at: [1.5, 1.5] }", ""), "robot"),
    ] {
        match load(&day).1 {
            Err(e @ SiteError::DayFile { .. }) => {
                assert!(e.to_string().contains(needle), "{e}")
            }
            other => panic!("{other:?}"),
        }
    }
}

#[test]
fn the_builtin_day_is_the_demo_day() {
    let site = Site::builtin_day();
    assert_eq!(site.tasks, tasks::day());
    let scenario = site.scenario().expect("the day world parses");
    assert_eq!(scenario.file.name, "downtime-day");
}

#[test]
fn the_shipped_example_loads_and_every_free_cell_has_a_fix() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config");
    let site = Site::load(&root.join("maps/depot.yaml"), &root.join("days/depot.yaml"))
        .expect("config/days/depot.yaml on config/maps/depot.yaml");
    assert_eq!(site.name, "depot");
    assert_eq!(site.tasks.len(), 4);
    assert!(site.warnings.is_empty(), "{:?}", site.warnings);
    let scenario = site.scenario().expect("parses");
    assert_eq!(scenario.file.sensing.range_m, 12.0);
    assert!(
        scenario.file.anchors.len() >= 6,
        "{}",
        scenario.file.anchors.len()
    );
    assert_eq!(scenario.file.blocks.len(), 1);
}
