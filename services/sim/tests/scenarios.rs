//! Every shipped scenario makes a sim, and the paper constellations have the properties
//! their comments claim.

mod common;

use std::collections::VecDeque;

use roam_sim::Sim;
use roam_world::scenario::Place;

/// How many anchors are within the sensing range of a point.
fn coverage(sim: &Sim, [x, y]: [f64; 2]) -> usize {
    let range = sim.params().sensing.range_m;
    sim.anchors()
        .iter()
        .filter(|a| (a.at[0] - x).hypot(a.at[1] - y) <= range)
        .count()
}

fn waypoint(places: &[Place], name: &str) -> [f64; 2] {
    places
        .iter()
        .find(|p| p.name == name)
        .unwrap_or_else(|| panic!("waypoint {name}"))
        .at
}

/// The coverage of `n + 1` evenly spaced points from `a` to `b`.
fn along(sim: &Sim, a: [f64; 2], b: [f64; 2], n: u32) -> Vec<usize> {
    (0..=n)
        .map(|i| {
            let t = f64::from(i) / f64::from(n);
            coverage(sim, [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t])
        })
        .collect()
}

#[test]
fn every_shipped_scenario_makes_a_sim_that_steps() {
    let mut seen = 0;
    for entry in std::fs::read_dir(common::scenarios_dir()).expect("scenarios") {
        let path = entry.expect("entry").path();
        if path.extension().and_then(|e| e.to_str()) != Some("yaml") {
            continue;
        }
        let file = path.file_name().and_then(|f| f.to_str()).expect("name");
        let scenario = common::shipped(file);
        let mut sim = Sim::new(&scenario, 3).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert!(sim.robots().count() >= 1, "{file} has a robot");
        for _ in 0..5 {
            let commands: Vec<_> = sim
                .robots()
                .map(|r| roam_sim::Command {
                    robot: r.name().to_owned(),
                    u: [1.0, 0.0],
                })
                .collect();
            let report = sim
                .step(&commands)
                .unwrap_or_else(|e| panic!("{file}: {e}"));
            for robot in &report.robots {
                let cell = sim.world().cell_of(robot.readings.truth).expect("on map");
                assert!(!sim.world().is_blocked(cell), "{file}");
            }
        }
        seen += 1;
    }
    assert!(seen >= 6, "downtime, grid004, es1, es2, es3, depot");
}

#[test]
fn es1_has_sparse_coverage_with_a_covered_detour() {
    let sim = Sim::new(&common::shipped("es1.yaml"), 0).expect("sim");
    assert_eq!(sim.anchors().len(), 5);
    let wp = &sim.scenario().file.waypoints;
    let (a, b) = (waypoint(wp, "A"), waypoint(wp, "B"));
    assert!(coverage(&sim, a) >= 3 && coverage(&sim, b) >= 3);
    let route = along(&sim, a, b, 100);
    let thin = route.iter().filter(|&&c| c < 3).count();
    assert!(
        thin >= 60,
        "most of the straight route have fewer than 3 anchors: {route:?}"
    );
    // North of A the coverage is better than on the straight route.
    assert!(coverage(&sim, [a[0] + 5.0, a[1] + 6.0]) >= 3);
    // A path of cells covered by at least three anchors joins A and B.
    let meta = *sim.world().meta();
    let covered = |(x, y): (i64, i64)| {
        !sim.world().is_blocked((x, y)) && coverage(&sim, sim.world().centre_of((x, y))) >= 3
    };
    let start = sim.world().cell_of(a).expect("A");
    let goal = sim.world().cell_of(b).expect("B");
    let mut seen = vec![false; (meta.width * meta.height) as usize];
    let mut queue = VecDeque::from([start]);
    let mut reached = false;
    while let Some(c) = queue.pop_front() {
        if c == goal {
            reached = true;
            break;
        }
        for (dx, dy) in [(1, 0), (0, 1), (-1, 0), (0, -1)] {
            let n = (c.0 + dx, c.1 + dy);
            if let Some(i) = sim.world().index(n) {
                if !seen[i] && covered(n) {
                    seen[i] = true;
                    queue.push_back(n);
                }
            }
        }
    }
    assert!(reached, "a well-covered detour from A to B");
}

#[test]
fn es2_waypoints_are_covered_and_the_legs_run_along_the_edge() {
    let sim = Sim::new(&common::shipped("es2.yaml"), 0).expect("sim");
    let wp = &sim.scenario().file.waypoints;
    let names: Vec<_> = wp.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["A", "B", "C", "D"]);
    for i in 0..4 {
        let (p, q) = (wp[i].at, wp[(i + 1) % 4].at);
        assert!(coverage(&sim, p) >= 3, "{} is well covered", wp[i].name);
        let leg = along(&sim, p, q, 60);
        assert!(
            leg.contains(&2),
            "leg {} has a stretch with two anchors: {leg:?}",
            wp[i].name
        );
    }
}

#[test]
fn es3_is_a_fully_covered_disk_of_about_2800_m2() {
    let sim = Sim::new(&common::shipped("es3.yaml"), 0).expect("sim");
    let anchors = sim.anchors();
    assert_eq!(anchors.len(), 7);
    let range = sim.params().sensing.range_m;
    let middle = anchors[0].at;
    assert_eq!(middle, [0.0, 0.0]);
    for a in &anchors[1..] {
        let r = (a.at[0] - middle[0]).hypot(a.at[1] - middle[1]);
        assert!((r - range).abs() < 1e-3, "{} on the perimeter: {r}", a.name);
    }
    let area = std::f64::consts::PI * range * range;
    assert!((area - 2800.0).abs() < 50.0, "{area} m2");
    // Inside the disk, every point is covered by three or four anchors.
    let (mut three, mut four, mut cells) = (0, 0, 0);
    let meta = *sim.world().meta();
    for y in 0..i64::from(meta.height) {
        for x in 0..i64::from(meta.width) {
            let p = sim.world().centre_of((x, y));
            if p[0].hypot(p[1]) > range {
                continue;
            }
            cells += 1;
            match coverage(&sim, p) {
                3 => three += 1,
                4 => four += 1,
                n => panic!("({}, {}) covered by {n}", p[0], p[1]),
            }
        }
    }
    assert!(
        three > four && four * 4 > cells,
        "3: {three}, 4: {four} of {cells}"
    );
    let robots: Vec<_> = sim.robots().map(|r| r.start()).collect();
    assert_eq!(robots.len(), 2);
    assert!(robots.iter().any(|p| p[0] < -20.0) && robots.iter().any(|p| p[0] > 20.0));
}

#[test]
fn grid004_is_25_by_25_with_the_robot_in_the_middle() {
    let sim = Sim::new(&common::shipped("grid004.yaml"), 0).expect("sim");
    let meta = sim.world().meta();
    assert_eq!((meta.width, meta.height), (25, 25));
    let robot = sim.robots().next().expect("robot");
    assert_eq!(sim.world().cell_of(robot.position()), Some((12, 12)));
    assert_eq!(
        sim.params().motion.sigma_tr_m,
        0.0,
        "the grid world is deterministic"
    );
}
