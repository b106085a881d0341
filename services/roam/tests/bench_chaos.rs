//! `roam bench chaos` as a user runs it: the built-in day with every role a process
//! behind one router, each killed and started again, the planners' and the
//! controller's links cut and a planner frozen; the report read back and held to what
//! the day must keep (no acked update lost, derived layers in step, no layer version
//! gone back, the robot not held, every role back), and its verdicts recomputed from
//! its figures; the same for the warehouse fleet's shortened shift, each robot with its
//! own executive. Bad settings are refused naming the limit.

use std::time::Duration;

use serde_json::Value;

mod run_roam;
use run_roam::roam;

/// The two days run one after the other: each is a stack of a dozen processes, and two
/// at once on two cores would measure the machine.
static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn number(v: &Value) -> Option<f64> {
    v.as_f64()
}

/// `roam bench chaos --json --quiet --seed 1 --partition-s 3 --freeze-s 2 <args>`, one
/// at a time: its report.
fn chaos(args: &[&str]) -> Value {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let mut all = vec![
        "bench",
        "chaos",
        "--json",
        "--quiet",
        "--seed",
        "1",
        "--partition-s",
        "3",
        "--freeze-s",
        "2",
    ];
    all.extend_from_slice(args);
    let (ok, stdout, stderr) = roam(&all, Duration::from_secs(400));
    assert!(ok, "roam {all:?} failed:\n{stderr}");
    serde_json::from_str(&stdout).expect("the report is JSON")
}

#[test]
fn the_day_through_every_fault_keeps_the_map_and_brings_every_role_back() {
    let report = chaos(&["--rate", "4"]);

    // Every role killed once, the router too, both links cut, a planner frozen.
    let faults = report["faults"].as_array().expect("faults");
    let whats: Vec<&str> = faults.iter().filter_map(|f| f["what"].as_str()).collect();
    for role in [
        "router",
        "map-server-m",
        "planner-a",
        "planner-b",
        "sim-w",
        "localization-l",
        "controller-c",
        "mapper-p",
        "mission-robot",
        "ros2-r",
    ] {
        assert!(
            whats.contains(&format!("kill {role}").as_str()),
            "{role} not killed: {whats:?}"
        );
    }
    for fault in [
        "cut the planners link",
        "cut the controller link",
        "freeze planner-a",
    ] {
        assert!(whats.contains(&fault), "{fault} missing: {whats:?}");
    }
    assert_eq!(faults.len(), 13, "{whats:?}");

    // Every role it touched came back: its token and a good answer.
    for f in faults {
        for r in f["roles"].as_array().expect("roles") {
            assert!(
                number(&r["live_again_s"]).is_some() && number(&r["first_answer_s"]).is_some(),
                "{} did not come back after {}: {r}",
                r["role"],
                f["what"]
            );
        }
        assert_eq!(
            f["layers_gone_back"],
            serde_json::json!([]),
            "{}",
            f["what"]
        );
    }
    // The router's restart is watched for every role.
    let router = faults
        .iter()
        .find(|f| f["what"] == "kill router")
        .expect("the router's kill");
    assert_eq!(router["roles"].as_array().map(Vec::len), Some(9));

    // What the map server acked is kept; what it derives is in step.
    let marks = &report["marks"];
    assert!(
        number(&marks["acked"]).is_some_and(|n| n >= 20.0),
        "too few acked updates to judge: {marks}"
    );
    assert_eq!(number(&marks["acked_lost"]), Some(0.0), "{marks}");
    assert_eq!(number(&report["derived_layers_checked"]), Some(2.0));
    assert_eq!(report["derived_layers_out_of_step"], serde_json::json!([]));
    assert_eq!(
        number(&report["robots_held_at_end"]),
        Some(0.0),
        "{}",
        report["controller_states_at_end"]
    );

    // Every task of the day has its window reported.
    let windows = report["windows"].as_array().expect("windows");
    assert_eq!(windows.len(), 4);
    for w in windows {
        assert_eq!(w["reported"], true, "{w}");
    }

    // The verdicts are the figures': each goal holds exactly when its value meets its
    // target (every goal here is "at most").
    let goals = report["goals"].as_array().expect("goals");
    assert_eq!(goals.len(), 6);
    for g in goals {
        let (value, target) = (
            number(&g["value"]).unwrap_or(f64::INFINITY),
            number(&g["target"]).expect("target"),
        );
        assert_eq!(g["holds"], value <= target, "{g}");
    }
    let unexplained = number(&goals[1]["value"]).expect("late windows");
    let late: usize = windows.iter().filter(|w| w["explained"] != true).count();
    assert_eq!(unexplained, late as f64);
}

#[test]
fn the_fleets_shift_through_every_fault_keeps_every_robots_windows() {
    let report = chaos(&[
        "--fleet",
        "--robots",
        "3",
        "--shift-s",
        "300",
        "--rate",
        "5",
    ]);
    assert!(
        report["site"]
            .as_str()
            .is_some_and(|s| s.contains("warehouse")),
        "{}",
        report["site"]
    );
    let faults = report["faults"].as_array().expect("faults");
    assert_eq!(faults.len(), 13);
    // One executive is killed (the first robot with a task), not every one.
    let executives = faults
        .iter()
        .filter(|f| {
            f["what"]
                .as_str()
                .is_some_and(|w| w.starts_with("kill mission-"))
        })
        .count();
    assert_eq!(executives, 1);
    for f in faults {
        for r in f["roles"].as_array().expect("roles") {
            assert!(
                number(&r["first_answer_s"]).is_some(),
                "{} did not answer after {}: {r}",
                r["role"],
                f["what"]
            );
        }
    }
    // Every robot with a task in the shortened shift has its windows reported, and
    // none is held at the end.
    let windows = report["windows"].as_array().expect("windows");
    let robots: std::collections::BTreeSet<&str> =
        windows.iter().filter_map(|w| w["robot"].as_str()).collect();
    assert!(robots.len() >= 2, "{robots:?}");
    for w in windows {
        assert_eq!(w["reported"], true, "{w}");
    }
    assert_eq!(number(&report["robots_held_at_end"]), Some(0.0));
    assert_eq!(number(&report["marks"]["acked_lost"]), Some(0.0));
    assert_eq!(report["derived_layers_out_of_step"], serde_json::json!([]));
}

#[test]
fn settings_out_of_range_are_refused_naming_the_limit() {
    for (flag, value, limit) in [
        ("--rate", "0", "(0, 10]"),
        ("--rate", "11", "(0, 10]"),
        ("--partition-s", "0", "(0, 60]"),
        ("--freeze-s", "61", "(0, 60]"),
        ("--robots", "0", "1 to 10"),
        ("--robots", "11", "1 to 10"),
        ("--shift-s", "0", "more than 0"),
    ] {
        let (ok, _, stderr) = roam(
            &["bench", "chaos", "--quiet", "--fleet", flag, value],
            Duration::from_secs(30),
        );
        assert!(!ok, "{flag} {value} was taken");
        assert!(
            stderr.contains(flag) && stderr.contains(limit),
            "{flag} {value}: {stderr}"
        );
    }
}
