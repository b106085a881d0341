//! Every shipped scenario and config file parses; the built-in world is what it says.

use std::path::{Path, PathBuf};

use roam_world::grid::{occupancy, world_to_cell, DEFAULT_MAX_CELLS};
use roam_world::scenario::{self, ScenarioError};

fn config_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config")
}

#[test]
fn every_shipped_scenario_loads() {
    let mut seen = 0;
    for entry in std::fs::read_dir(config_dir().join("scenarios")).expect("scenarios dir") {
        let path = entry.expect("entry").path();
        if path.extension().and_then(|e| e.to_str()) == Some("yaml") {
            scenario::load(&path, DEFAULT_MAX_CELLS).unwrap_or_else(|e| panic!("{e}"));
            seen += 1;
        }
    }
    assert!(seen >= 1);
}

#[test]
fn the_builtin_world_has_walls_zones_and_free_places() {
    let parsed = scenario::builtin().expect("builtin");
    let occ = &parsed.occupancy;
    assert_eq!((occ.meta.width, occ.meta.height), (100, 100));
    assert_eq!(occ.get(0, 50), Some(occupancy::OCCUPIED), "border wall");
    let info = &parsed.information;
    let (lx, ly) = world_to_cell(&info.meta, -5.0, 8.0).expect("in map");
    assert_eq!(info.get(lx, ly), Some(90), "the lab zone");
    for place in &parsed.file.places {
        let (x, y) = world_to_cell(&occ.meta, place.at[0], place.at[1]).expect("inside");
        assert_eq!(
            occ.get(x, y),
            Some(occupancy::FREE),
            "{} is free",
            place.name
        );
    }
}

#[test]
fn scenario_errors_name_the_file_and_field() {
    let path = Path::new("/tmp/roam-bad.yaml");
    let text = "name: x\nmap:\n  grid:\n    size_m: [2.0, 2.0]\n    resolution: 0.1\ninformation:\n  zones:\n    - { name: z, score: 120, rect: [0, 0, 1, 1] }\n";
    let err = scenario::parse(path, text, DEFAULT_MAX_CELLS).expect_err("must be refused");
    let msg = err.to_string();
    assert!(matches!(err, ScenarioError::Field { .. }), "{msg}");
    assert!(
        msg.contains("/tmp/roam-bad.yaml") && msg.contains("information.zones[0].score"),
        "{msg}"
    );

    let err = scenario::parse(
        path,
        "name: x\nmap: {grid: {size_m: [1, 1], resolution: 0.1}}\nanchorz: []\n",
        1000,
    )
    .expect_err("must be refused");
    // The error names where and what was expected, never what the file says (a load
    // from the wire must not hand back file content), so the field is found by its line.
    let msg = err.to_string();
    assert!(
        msg.contains("unknown field") && msg.contains("line 3") && !msg.contains("anchorz"),
        "{msg}"
    );

    let err = scenario::parse(
        path,
        "name: x\nmap: {grid: {size_m: [100, 100], resolution: 0.1}}\n",
        1000,
    )
    .expect_err("must be refused");
    assert!(err.to_string().contains("max_layer_cells"), "{err}");
}

/// A 10 x 10 m map of 0.5 m cells with border walls and a wall at x = 5, for the sim
/// sections' checks; `extra` is appended.
fn sim_scenario(extra: &str) -> Result<scenario::Scenario, ScenarioError> {
    let text = format!(
        "name: sim\nmap:\n  grid:\n    size_m: [10.0, 10.0]\n    resolution: 0.5\n    border_walls: true\n    obstacles: [ {{ rect: [5.0, 0.0, 5.4, 10.0] }} ]\n{extra}"
    );
    scenario::parse(Path::new("/tmp/roam-sim.yaml"), &text, DEFAULT_MAX_CELLS)
}

#[test]
fn sim_sections_parse_with_the_papers_defaults() {
    let parsed = sim_scenario(
        "anchors: [ { name: a, at: [5.2, 5.0] } ]\nrobots: [ { name: r, at: [2.0, 2.0] } ]\nblocks: [ { name: b, size_m: [1.0, 0.5], period_steps: 7, path: [[7.0, 7.0], [8.0, 7.0]] } ]\nwalkers: [ { name: w, at: [7.0, 3.0], size_m: 0.5, step_m: 0.5, every_steps: 2 } ]\nwaypoints: [ { name: A, at: [1.0, 1.0] }, { name: B, at: [9.0, 9.0] } ]\nsensing: { k: 3.0 }\n",
    )
    .expect("valid");
    let file = &parsed.file;
    assert_eq!(file.anchors.len(), 1, "an anchor may stand on a wall");
    assert_eq!(file.sensing.range_m, scenario::DEFAULT_RANGE_M);
    assert_eq!(file.sensing.sigma_toa_m, 0.10);
    assert_eq!(file.sensing.d0_m, 15.0);
    assert_eq!(file.sensing.k, 3.0);
    assert_eq!(file.sensing.range_gate, scenario::RangeGate::TrueDistance);
    assert_eq!(file.motion.step_mu, 0.2);
    assert_eq!(file.motion.sigma_tr_m, 0.01);
    assert_eq!(file.motion.model, scenario::MotionModel::Point);
    assert_eq!(file.robots[0].heading_rad, 0.0);
    assert_eq!(file.time.step_s, scenario::DEFAULT_STEP_S);
    assert_eq!(file.blocks[0].size_m, Some([1.0, 0.5]));
    assert_eq!(file.waypoints[1].name, "B");
}

#[test]
fn sim_section_errors_name_the_file_and_field() {
    let cases: &[(&str, &str, &str)] = &[
        (
            "robots: [ { name: r, at: [12.0, 2.0] } ]\n",
            "robots[0].at",
            "outside the map",
        ),
        (
            "robots: [ { name: r, at: [5.2, 2.0] } ]\n",
            "robots[0].at",
            "free cell",
        ),
        (
            "robots: [ { name: r, at: [2.0, 2.0] }, { name: r, at: [3.0, 2.0] } ]\n",
            "robots[1].name",
            "used twice",
        ),
        (
            "anchors: [ { name: a, at: [1.0, 1.0] }, { name: b, at: [1.0, -3.0] } ]\n",
            "anchors[1].at",
            "outside the map",
        ),
        (
            "sensing: { sigma_toa_m: -0.1 }\n",
            "sensing.sigma_toa_m",
            "non-negative",
        ),
        ("sensing: { d0_m: 0.0 }\n", "sensing.d0_m", "positive"),
        ("sensing: { range_m: .nan }\n", "sensing.range_m", "positive"),
        (
            "sensing: { observation_radius_m: 100.0 }\n",
            "sensing.observation_radius_m",
            "limit",
        ),
        (
            "motion: { sigma_tr_m: -0.01 }\n",
            "motion.sigma_tr_m",
            "non-negative",
        ),
        (
            "motion: { max_speed_m_per_step: 0.0 }\n",
            "motion.max_speed_m_per_step",
            "positive",
        ),
        ("time: { step_s: -1.0 }\n", "time.step_s", "positive"),
        (
            "robots: [ { name: r, at: [2.0, 2.0], heading_rad: .nan } ]\n",
            "robots[0].heading_rad",
            "finite number of radians",
        ),
        (
            "blocks: [ { name: b, size_cells: [2, 2], period_steps: 7, path: [[7.0, 7.0], [7.0, 11.0]] } ]\n",
            "blocks[0].path[1]",
            "outside the map",
        ),
        (
            "blocks: [ { name: b, period_steps: 7, path: [[7.0, 7.0]] } ]\n",
            "blocks[0]",
            "exactly one of size_cells or size_m",
        ),
        (
            "blocks: [ { name: b, size_cells: [0, 2], period_steps: 7, path: [[7.0, 7.0]] } ]\n",
            "blocks[0].size_cells",
            "at least 1",
        ),
        (
            "blocks: [ { name: b, size_cells: [1, 1], period_steps: 0, path: [[7.0, 7.0]] } ]\n",
            "blocks[0].period_steps",
            "at least 1",
        ),
        (
            "blocks: [ { name: b, size_cells: [1, 1], period_steps: 2, path: [] } ]\n",
            "blocks[0].path",
            "at least one position",
        ),
        (
            "walkers: [ { name: w, at: [7.0, 3.0], size_m: 0.5, step_m: 0.0, every_steps: 2 } ]\n",
            "walkers[0].step_m",
            "positive",
        ),
        (
            "walkers: [ { name: w, at: [7.0, 3.0], size_m: 0.5, step_m: 0.5, every_steps: 0 } ]\n",
            "walkers[0].every_steps",
            "at least 1",
        ),
        (
            "waypoints: [ { name: A, at: [1.0, 1.0] }, { name: B, at: [-1.0, 1.0] } ]\n",
            "waypoints[1].at",
            "outside the map",
        ),
    ];
    for (extra, field, says) in cases {
        let err = sim_scenario(extra).expect_err(extra);
        let msg = err.to_string();
        assert!(matches!(err, ScenarioError::Field { .. }), "{extra}: {msg}");
        assert!(
            msg.contains("/tmp/roam-sim.yaml")
                && msg.contains(&format!("field {field}:"))
                && msg.contains(says),
            "{extra}: {msg}"
        );
    }
    // A typo inside a sim section is refused by name.
    let err = sim_scenario("sensing: { sigma_toa: 0.1 }\n").expect_err("typo");
    assert!(err.to_string().contains("sigma_toa"), "{err}");
}

#[test]
fn the_motion_model_is_point_by_default_and_a_unicycle_when_asked() {
    let point = sim_scenario("motion: { model: point, step_mu: 0.5 }\n").expect("point");
    assert_eq!(point.file.motion.model, scenario::MotionModel::Point);
    assert_eq!(point.file.motion.step_mu, 0.5);
    let unicycle = sim_scenario(
        "motion:\n  model: { unicycle: { v_max_m_per_s: 0.8, w_max_rad_per_s: 1.5 } }\nrobots: [ { name: r, at: [2.0, 2.0], heading_rad: 1.5 } ]\n",
    )
    .expect("unicycle");
    assert_eq!(
        unicycle.file.motion.model,
        scenario::MotionModel::Unicycle(scenario::UnicycleSpec {
            v_max_m_per_s: 0.8,
            w_max_rad_per_s: 1.5,
        })
    );
    assert_eq!(unicycle.file.motion.step_mu, scenario::DEFAULT_STEP_MU);
    assert_eq!(unicycle.file.robots[0].heading_rad, 1.5);
    // A unicycle has no default speeds: a robot's top speed is said, not guessed.
    let err = sim_scenario("motion: { model: unicycle }\n").expect_err("no speeds");
    assert!(matches!(err, ScenarioError::Invalid { .. }), "{err}");
    // (Parse errors quote nothing of the file, so the missing field is not named; the
    // section and what it expects are.)
    let err = sim_scenario("motion: { model: { unicycle: { v_max_m_per_s: 0.5 } } }\n")
        .expect_err("no turn rate");
    assert!(
        err.to_string()
            .contains("motion.model.unicycle: missing field"),
        "{err}"
    );
    let err = sim_scenario(
        "motion: { model: { unicycle: { v_max_m_per_s: 0.5, w_max_rad_per_s: 1.0, w: 1 } } }\n",
    )
    .expect_err("typo");
    assert!(
        err.to_string().contains("unknown field") && err.to_string().contains("v_max_m_per_s"),
        "{err}"
    );
    let err = sim_scenario("motion: { model: bicycle }\n").expect_err("no such model");
    assert!(
        err.to_string().contains("expected `point` or `unicycle`"),
        "{err}"
    );
}

#[test]
fn bad_unicycle_speeds_are_refused_naming_the_field_and_the_limit() {
    let v = "motion.model.unicycle.v_max_m_per_s";
    let w = "motion.model.unicycle.w_max_rad_per_s";
    let cases: &[(&str, &str, &str, &str)] = &[
        ("0.0", "1.0", v, "got 0"),
        ("-0.5", "1.0", v, "got -0.5"),
        (".nan", "1.0", v, "got NaN"),
        (".inf", "1.0", v, "got inf"),
        ("25.0", "1.0", v, "got 25"),
        ("0.5", "0.0", w, "got 0"),
        ("0.5", "-1.0", w, "got -1"),
        ("0.5", ".nan", w, "got NaN"),
        ("0.5", "90.0", w, "got 90"),
    ];
    for (v_max, w_max, field, got) in cases {
        let extra = format!(
            "motion: {{ model: {{ unicycle: {{ v_max_m_per_s: {v_max}, w_max_rad_per_s: {w_max} }} }} }}\n"
        );
        let err = sim_scenario(&extra).expect_err(&extra);
        let msg = err.to_string();
        assert!(matches!(err, ScenarioError::Field { .. }), "{extra}: {msg}");
        let limit = if *field == v {
            "greater than 0 and at most 20 (limit max_v_m_per_s)"
        } else {
            "greater than 0 and at most 20 (limit max_w_rad_per_s)"
        };
        assert!(
            msg.contains(&format!("field {field}:")) && msg.contains(limit) && msg.contains(got),
            "{extra}: {msg}"
        );
    }
}

#[test]
fn the_unicycle_downtime_world_is_the_downtime_world_with_a_unicycle() {
    let load = |file: &str| {
        scenario::load(
            &config_dir().join("scenarios").join(file),
            DEFAULT_MAX_CELLS,
        )
        .unwrap_or_else(|e| panic!("{e}"))
    };
    let (point, unicycle) = (load("downtime.yaml"), load("downtime-unicycle.yaml"));
    assert_eq!(point.occupancy.meta, unicycle.occupancy.meta);
    assert_eq!(point.occupancy.cells, unicycle.occupancy.cells);
    assert_eq!(point.information.cells, unicycle.information.cells);
    let (p, u) = (&point.file, &unicycle.file);
    assert_eq!(p.robot_radius_m, u.robot_radius_m);
    assert_eq!(p.places, u.places);
    assert_eq!(p.anchors, u.anchors);
    assert_eq!(p.robots, u.robots);
    assert_eq!(p.sensing, u.sensing);
    assert_eq!(p.time, u.time);
    assert_eq!(p.blocks, u.blocks);
    assert_eq!(p.walkers, u.walkers);
    assert_eq!(p.waypoints, u.waypoints);
    assert_eq!(p.motion.model, scenario::MotionModel::Point);
    assert_eq!(
        u.motion,
        scenario::MotionSpec {
            model: scenario::MotionModel::Unicycle(scenario::UnicycleSpec {
                v_max_m_per_s: 0.5,
                w_max_rad_per_s: 1.0,
            }),
            ..p.motion
        }
    );
}
