//! roam's main job on a user's own site, run as a user runs it: a Nav2 map at 5 cm made
//! here and a day file, through `roam demo --map … --tasks …` and `roam reproduce
//! mission --days 3 --map … --tasks …`; the shipped example (config/maps/depot.yaml
//! with config/days/depot.yaml); and bad files refused when they load, naming what to
//! fix.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use roam_proto::map::{GridMeta, Origin};
use roam_world::grid::Grid;
use roam_world::ros_map::{save, SaveParams};

const ROAM: &str = env!("CARGO_BIN_EXE_roam");

/// The driven path's colour in `world.png` (`roam::demo::DRIVEN`).
const DRIVEN: [u8; 3] = [220, 20, 20];

/// A 12 × 8 m room at 5 cm with border walls and a wall from the south up to y = 5 m at
/// x = 6 m, written as a Nav2 map (`room.yaml`, `room.pgm`) in `dir`.
fn room_map(dir: &Path) -> PathBuf {
    let (w, h) = (240usize, 160usize);
    let meta = GridMeta {
        width: w as u32,
        height: h as u32,
        resolution: 0.05,
        origin: Origin::default(),
    };
    let mut grid = Grid::filled(meta, 0i8);
    for y in 0..h {
        for x in 0..w {
            let border = x == 0 || y == 0 || x == w - 1 || y == h - 1;
            let wall = (119..=121).contains(&x) && y < 100;
            if border || wall {
                grid.cells[y * w + x] = 100;
            }
        }
    }
    let path = dir.join("room.yaml");
    save(&grid, &path, SaveParams::default()).expect("save the room");
    path
}

/// Two windows: east past the wall's end, then back to the north-west.
const DAY: &str = "
robot: { at: [1.5, 1.5] }
tasks:
  - { name: east, at: [10.0, 1.5], start_s: 55 }
  - { name: back, at: [1.5, 6.5], start_s: 125 }
information:
  default_score: 10
  zones:
    - { name: shelves, score: 80, rect: [7.0, 5.5, 11.5, 7.5] }
";

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write");
    path
}

fn roam(args: &[&str], paths: &[&Path]) -> Output {
    let mut command = Command::new(ROAM);
    command.args(args).env("RUST_LOG", "warn");
    for p in paths {
        command.arg(p);
    }
    command.output().expect("run roam")
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).expect("read")).expect("json")
}

#[test]
fn the_demo_runs_a_day_on_a_generated_nav2_map() {
    let dir = tempfile::tempdir().expect("tmp");
    let map = room_map(dir.path());
    let day = write(dir.path(), "room-day.yaml", DAY);
    let out = dir.path().join("report");
    let output = Command::new(ROAM)
        .args(["demo", "--rate", "20", "--map"])
        .arg(&map)
        .arg("--tasks")
        .arg(&day)
        .arg("--out")
        .arg(&out)
        .env("RUST_LOG", "warn")
        .output()
        .expect("run");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    assert!(stderr.contains("window 1 -> east"), "{stderr}");
    let report = json(&out.join("report.json"));
    assert_eq!(report["site"], "room-day", "{report}");
    let windows = report["windows"].as_array().expect("windows");
    assert_eq!(windows.len(), 2, "{report}");
    for (w, task) in windows.iter().zip(["east", "back"]) {
        assert_eq!(w["task"], task, "{w}");
        assert!(w["arrival_s"].as_f64().is_some(), "arrived: {w}");
    }
    // The world every service ran on is the user's map, with the defaults filled in.
    let world = std::fs::read_to_string(out.join("world.yaml")).expect("world.yaml");
    assert!(world.contains(&map.display().to_string()), "{world}");
    assert!(
        world.contains("lattice-0"),
        "anchors by the lattice rule: {world}"
    );
    let markdown = std::fs::read_to_string(out.join("report.md")).expect("md");
    assert!(markdown.contains("the site `room-day`"), "{markdown}");
    // 240 × 160 cells drawn at 3 px a cell (800 px on the longer side at most) inside
    // the picture's frame (title, legend, scale bar), the driven path on it (well
    // beyond the legend's swatch of its colour).
    let picture = image::open(out.join("world.png")).expect("png").to_rgb8();
    assert!(picture.width() >= 720 && picture.height() >= 480);
    let driven = picture.pixels().filter(|p| p.0 == DRIVEN).count();
    assert!(driven > 1000, "{driven} driven pixels");
}

#[test]
fn the_days_batch_runs_on_the_same_files() {
    let dir = tempfile::tempdir().expect("tmp");
    let map = room_map(dir.path());
    let day = write(dir.path(), "room-day.yaml", DAY);
    let output = Command::new(ROAM)
        .args([
            "reproduce",
            "mission",
            "--json",
            "--days",
            "3",
            "--variants",
            "executive,fastest_path",
            "--generations",
            "200",
            "--map",
        ])
        .arg(&map)
        .arg("--tasks")
        .arg(&day)
        .env("RUST_LOG", "warn")
        .output()
        .expect("run");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&output.stdout).expect("json");
    let results = report["results"].as_array().expect("results");
    assert_eq!(results.len(), 6, "three days of two variants");
    for day in results {
        let windows = day["windows"].as_array().expect("windows");
        let tasks: Vec<&str> = windows.iter().filter_map(|w| w["task"].as_str()).collect();
        assert_eq!(tasks, ["east", "back"], "{day}");
    }
}

#[test]
fn the_shipped_example_runs() {
    let config = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config");
    let out = tempfile::tempdir().expect("tmp");
    let output = Command::new(ROAM)
        .args(["demo", "--rate", "20", "--map"])
        .arg(config.join("maps/depot.yaml"))
        .arg("--tasks")
        .arg(config.join("days/depot.yaml"))
        .arg("--out")
        .arg(out.path())
        .env("RUST_LOG", "warn")
        .output()
        .expect("run");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    assert!(
        !stderr.contains("warning"),
        "every cell has a fix: {stderr}"
    );
    let report = json(&out.path().join("report.json"));
    assert_eq!(report["site"], "depot");
    assert_eq!(report["windows"].as_array().map(Vec::len), Some(4));
}

#[test]
fn bad_files_are_refused_naming_what_to_fix() {
    let dir = tempfile::tempdir().expect("tmp");
    let map = room_map(dir.path());
    for (name, day, needle) in [
        (
            "wall",
            DAY.replace("[10.0, 1.5]", "[6.0, 2.0]"),
            "task \"east\": its place [6.0, 2.0]",
        ),
        (
            "late",
            DAY.replace("start_s: 55", "start_s: 8"),
            "s missing",
        ),
        (
            "overlap",
            DAY.replace("start_s: 125", "start_s: 57"),
            "\"back\"",
        ),
        (
            "anchor",
            format!("{DAY}anchors:\n  - {{ name: far, at: [40.0, 1.0] }}\n"),
            "anchors[0].at",
        ),
        ("unknown", format!("{DAY}speed: 3\n"), "speed"),
    ] {
        let day = write(dir.path(), &format!("{name}.yaml"), &day);
        for command in [
            vec!["demo", "--out", "/nonexistent/never-written"],
            vec!["reproduce", "mission", "--days", "1"],
        ] {
            let output = Command::new(ROAM)
                .args(&command)
                .arg("--map")
                .arg(&map)
                .arg("--tasks")
                .arg(&day)
                .output()
                .expect("run");
            let stderr = String::from_utf8_lossy(&output.stderr);
            assert!(!output.status.success(), "{name}: {command:?} ran");
            assert!(stderr.contains(needle), "{name}: {command:?}: {stderr}");
            assert!(!stderr.contains("panicked"), "{stderr}");
        }
    }
    // One without the other.
    let output = roam(&["demo", "--map"], &[&map]);
    assert!(!output.status.success());
    assert!(String::from_utf8_lossy(&output.stderr).contains("--tasks"));
}

/// The room as a fleet's site: two robots, anchors at its corners, pallets that come and
/// go by the east wall.
const FLEET_SCENARIO: &str = "
name: room-fleet
map:
  ros: room.yaml
robot_radius_m: 0.2
information:
  default_score: 10
anchors:
  - { name: sw, at: [0.2, 0.2] }
  - { name: se, at: [11.8, 0.2] }
  - { name: ne, at: [11.8, 7.8] }
  - { name: nw, at: [0.2, 7.8] }
robots:
  - { name: r1, at: [1.5, 1.5] }
  - { name: r2, at: [1.5, 6.5] }
changes:
  - { name: east-wall, rect: [10.5, 2.0, 11.5, 7.0], size_m: [0.6, 0.6], appear_per_hour: 30.0, mean_stay_s: 200.0, max_present: 2 }
";

const FLEET_SHIFT: &str = "
length_s: 300.0
robots:
  - robot: r1
    tasks:
      - { name: east, at: [10.0, 1.5], start_s: 80.0, duration_s: 10.0 }
      - { name: home, at: [1.5, 1.5], start_s: 200.0, duration_s: 10.0 }
  - robot: r2
    tasks:
      - { name: north-east, at: [10.0, 6.5], start_s: 90.0, duration_s: 10.0 }
      - { name: home, at: [1.5, 6.5], start_s: 210.0, duration_s: 10.0 }
patrol: [[2.0, 7.0], [10.5, 7.0], [10.5, 1.0], [7.0, 1.0], [7.0, 6.0], [2.0, 6.0]]
";

#[test]
fn the_fleets_week_runs_on_a_site_of_ones_own() {
    let dir = tempfile::tempdir().expect("tmp");
    room_map(dir.path());
    let scenario = write(dir.path(), "room-fleet.yaml", FLEET_SCENARIO);
    let shift = write(dir.path(), "room-shift.yaml", FLEET_SHIFT);
    let run = |variants: &str, shift: &Path| {
        Command::new(ROAM)
            .args([
                "reproduce",
                "fleet",
                "--json",
                "--days",
                "1",
                "--variants",
                variants,
            ])
            .arg("--scenario")
            .arg(&scenario)
            .arg("--shift")
            .arg(shift)
            .env("RUST_LOG", "warn")
            .output()
            .expect("run")
    };
    let output = run("tasks_only,patrol,news", &shift);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&output.stdout).expect("json");
    let names: Vec<&str> = report["variants"]
        .as_array()
        .expect("variants")
        .iter()
        .filter_map(|v| v["variant"].as_str())
        .collect();
    assert_eq!(names.len(), 3, "{report}");
    for name in ["tasks_only", "patrol", "news"] {
        assert!(names.contains(&name), "{name} in {names:?}");
    }
    // Without the operator's loop the patrol is refused, saying what to add.
    let no_patrol = write(
        dir.path(),
        "no-patrol.yaml",
        &FLEET_SHIFT.replace("patrol: [[2.0", "# patrol: [[2.0"),
    );
    let output = run("patrol", &no_patrol);
    assert!(!output.status.success());
    assert!(String::from_utf8_lossy(&output.stderr).contains("patrol: [[x, y]"));
}
