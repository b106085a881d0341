//! `roam bench fleet` as a user runs it, on a small fleet: the router in its own
//! process, a robot joining halfway, the router killed and started again under the
//! fleet; and its bad input refused naming the sim's limit.

use std::time::Duration;

use serde_json::Value;

mod run_roam;
use run_roam::roam;

fn number(report: &Value, field: &str) -> f64 {
    report[field]
        .as_f64()
        .unwrap_or_else(|| panic!("{field} is not a number in {report:#}"))
}

#[test]
fn a_small_fleet_commands_its_joiner_and_every_robot_again_after_a_router_restart() {
    let (ok, stdout, stderr) = roam(
        &[
            "bench",
            "--quiet",
            "fleet",
            "--json",
            "--robots",
            "5",
            "--seconds",
            "4",
        ],
        Duration::from_secs(120),
    );
    assert!(ok, "roam bench fleet failed:\n{stderr}");
    let report: Value = serde_json::from_str(&stdout).expect("JSON on stdout");
    assert_eq!(report["robots"], 5, "{report:#}");
    // The loop ran: commands came, most on time (a debug build on a loaded machine
    // still answers 5 robots at 10 Hz).
    assert!(number(&report, "commands_on_time") > 0.0, "{report:#}");
    assert!(number(&report, "loop_on_time_share") > 0.5, "{report:#}");
    // The router is a process of its own, read from its /proc: memory it holds, and CPU
    // time (in 10 ms ticks, so a few seconds of 5 robots may be none).
    assert!(number(&report, "router_rss_mib") > 1.0, "{report:#}");
    let router_cpu = number(&report, "router_cpu_share");
    assert!((0.0..=1.0).contains(&router_cpu), "{report:#}");
    assert!(number(&report, "router_cpu_us_per_robot_step") >= 0.0);
    assert!(number(&report, "router_peak_rss_mib") >= number(&report, "router_rss_mib"));
    // The joiner was commanded, after its first scan and after it was added.
    let join = number(&report, "join_ms");
    assert!(join.is_finite() && join >= 0.0, "{report:#}");
    assert!(number(&report, "join_from_add_ms") >= join, "{report:#}");
    // Every robot, the joiner too, was commanded again after the router's restart.
    assert_eq!(report["restart_robots_commanded"], 5, "{report:#}");
    let down = number(&report, "restart_down_ms");
    assert!(down >= 1000.0, "{report:#}");
    let (first, all) = (
        number(&report, "restart_first_command_ms"),
        number(&report, "restart_all_commanded_ms"),
    );
    assert!(0.0 <= first && first <= all && all < 30_000.0, "{report:#}");
    // The outage had steps without commands; the steps around it had commands on time.
    assert!(number(&report, "restart_steps_inside") > 0.0, "{report:#}");
    assert!(number(&report, "restart_steps_outside") > 0.0, "{report:#}");
    assert!(
        number(&report, "restart_on_time_share_outside")
            > number(&report, "restart_on_time_share_inside"),
        "{report:#}"
    );
}

#[test]
fn a_fleet_of_none_or_beyond_the_sims_limit_is_refused_naming_the_limit() {
    for robots in ["0", "1001"] {
        let (ok, _, stderr) = roam(
            &["bench", "--quiet", "fleet", "--robots", robots],
            Duration::from_secs(30),
        );
        assert!(!ok, "--robots {robots} was run");
        assert!(
            stderr.contains("1..=1000") && stderr.contains("the sim's robot limit"),
            "{stderr}"
        );
    }
}
