//! The fleet: `roam bench load`, `roam bench fleet` and `roam demo --fleet`.

use super::*;

#[test]
fn bench_load_answers_or_refuses_every_request_and_none_hangs() {
    let (value, _) = run_json(&["bench", "load", "--json", "--requests", "30"], None);
    let count = |field: &str| value[field].as_u64().expect(field);
    assert_eq!(count("hung"), 0, "{value}");
    assert_eq!(count("failed"), 0, "{value}");
    assert_eq!(count("answered") + count("refused_busy"), 30, "{value}");
    assert!(
        count("answered") >= 2,
        "two planners answer at least one each: {value}"
    );
    assert!(value["peak_rss_mib"].as_f64().is_some());
}

#[test]
fn bench_fleet_closes_the_loop_for_every_robot() {
    let (value, _) = run_json(
        &[
            "bench",
            "fleet",
            "--json",
            "--robots",
            "4",
            "--seconds",
            "2",
        ],
        None,
    );
    let count = |field: &str| value[field].as_u64().expect(field);
    assert!(count("steps") >= 10, "{value}");
    // The loop is closed for every robot: commands answer most steps (a debug build
    // on a loaded machine may miss some of them).
    assert!(count("commands_expected") >= 4 * 10, "{value}");
    assert!(
        2 * count("commands_on_time") >= count("commands_expected"),
        "{value}"
    );
    assert!(
        count("commands_on_time") + count("commands_late") <= count("commands_expected"),
        "{value}"
    );
    assert!(value["cpu_share"].as_f64().is_some_and(|c| c > 0.0));
    assert!(value["rss_per_robot_mib"].as_f64().is_some());
}

/// `roam demo --fleet`, shortened: three robots of the warehouse's shift live through
/// Zenoh for its first 300 s (r1's first task is later, so it stays put), measured as the
/// batch measures a week: every window of the robots with tasks is reported, the
/// summary counts them and their lateness, the map is scored every sim minute, the
/// goals' verdicts follow from their figures, and the picture draws each robot that
/// drove. (Speed and lateness are the release build's, measured in the README, not here.)
#[test]
fn roam_demo_fleet_writes_the_fleets_report_and_pictures() {
    let out = tempfile::tempdir().expect("tmp");
    let output = Command::new(ROAM)
        .args([
            "demo",
            "--fleet",
            "--robots",
            "3",
            "--shift-s",
            "300",
            "--rate",
            "5",
            "--out",
        ])
        .arg(out.path())
        .env("RUST_LOG", "warn")
        .output()
        .expect("run");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.path().join("report.json")).expect("json"))
            .expect("parses");
    assert_eq!(report["robots"], 3, "{report}");
    let windows = report["windows"].as_array().expect("windows");
    // The shift's tasks that start within 300 s: r2's pick-1 (202.2 s), r3's (233.9 s).
    let tasks: Vec<(&str, &str)> = windows
        .iter()
        .map(|w| {
            (
                w["robot"].as_str().expect("robot"),
                w["task"].as_str().expect("task"),
            )
        })
        .collect();
    assert_eq!(tasks, [("r2", "pick-1"), ("r3", "pick-1")], "{report}");
    let summary = &report["summary"];
    assert_eq!(summary["variant"], "news");
    assert_eq!(summary["windows"], 2);
    let late = windows.iter().filter(|w| w["on_time"] == false).count();
    assert_eq!(summary["late"], late as u64, "{summary}");
    assert_eq!(report["on_time"], late == 0);
    // Map samples at 60, 120, ... s of the sim: a Brier score between 0 and 1.
    let brier = summary["brier"].as_f64().expect("the map was scored");
    assert!((0.0..=1.0).contains(&brier), "{summary}");
    // Beside the static map's, the reference a map that never looks gets.
    let never_looks = summary["brier_static"]
        .as_f64()
        .expect("the static map scored");
    assert!((0.0..=1.0).contains(&never_looks), "{summary}");
    // Each curious plan's answer time is counted (none may come back curious in a debug
    // build on a loaded machine: then there is no p99).
    let curious = summary["curious_plans"].as_u64().expect("plans");
    assert_eq!(summary["plan_p99_ms"].is_number(), curious > 0, "{summary}");
    for g in report["goals"].as_array().expect("goals") {
        let (figure, at_most) = (g["figure"].as_f64(), g["at_most"].as_f64().expect("bound"));
        assert_eq!(g["met"].as_bool(), figure.map(|f| f <= at_most), "{g}");
    }
    let svg = std::fs::read_to_string(out.path().join("warehouse-news.svg")).expect("svg");
    assert!(svg.contains("racks and walls") && svg.contains("UWB anchor"));
    assert!(
        svg.matches(r#"class="path""#).count() >= 2,
        "r2 and r3 drove"
    );
    assert!(out.path().join("detection.svg").exists());
    let markdown = std::fs::read_to_string(out.path().join("report.md")).expect("md");
    assert!(markdown.contains("| r2 | 1 | pick-1 |"), "{markdown}");
    assert!(markdown.contains("warehouse-news.svg"));
}
