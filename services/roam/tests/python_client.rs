//! The Python client `tests/clients/python/roam_plan.py` against a real `roam stack`
//! process: a plan it asks for reaches the goal within the budget, and a goal inside a
//! wall comes back as an `invalid_request` error with exit code 2.
//!
//! Needs `python3` with `eclipse-zenoh` (`pip install eclipse-zenoh==1.10.2`). Without
//! it the test prints a notice and passes, except in CI (`CI` set), where it fails.

mod clients;

use std::path::PathBuf;
use std::time::Duration;

use clients::{python_has, run_python, RoamProcess, ScriptRun};
use roam_stack::router::free_loopback_port;

const SCRIPT_TIMEOUT: Duration = Duration::from_secs(60);

fn script() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/clients/python/roam_plan.py")
}

fn run_script(args: &[&str]) -> ScriptRun {
    run_python(&script(), args, SCRIPT_TIMEOUT)
}

#[test]
fn the_python_client_plans_and_reports_errors() {
    if !python_has(
        "zenoh",
        "the_python_client_plans_and_reports_errors",
        "eclipse-zenoh==1.10.2",
    ) {
        return;
    }

    let port = free_loopback_port().expect("port");
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let root = format!("py-{}", std::process::id());
    let _stack = RoamProcess::start(&["stack", "--listen", &endpoint], &root, "roam stack up");

    // A debug build plans slower than a release one: a generous planning deadline.
    let common = [
        "--connect",
        endpoint.as_str(),
        "--root",
        root.as_str(),
        "--start=-8,-8",
        "--budget",
        "80",
        "--deadline",
        "20",
    ];

    let plan = run_script(
        &[
            &common[..],
            &["--goal=6,-7", "--json", "--generations", "100"],
        ]
        .concat(),
    );
    assert!(
        plan.status.success(),
        "exit {:?}\nstdout:\n{}\nstderr:\n{}",
        plan.status,
        plan.stdout,
        plan.stderr
    );
    let body: serde_json::Value = serde_json::from_str(&plan.stdout)
        .unwrap_or_else(|e| panic!("not JSON ({e}):\n{}", plan.stdout));
    assert_eq!(body["reaches_goal"], true, "{body}");
    assert_eq!(body["within_budget"], true, "{body}");
    assert_eq!(body["model"], "model1");
    assert_eq!(body["instance"], "planner-0");
    let cells = body["cells"].as_array().expect("cells");
    assert!(!cells.is_empty(), "no cells: {body}");
    let first = body["points"][0].as_array().expect("points[0]");
    let (x, y) = (first[0].as_f64().expect("x"), first[1].as_f64().expect("y"));
    assert!(
        (x + 8.0).hypot(y + 8.0) < 0.5,
        "the first point ({x}, {y}) is not near the start (-8, -8)"
    );

    let blocked = run_script(&[&common[..], &["--goal=-9.9,0"]].concat());
    assert_eq!(
        blocked.status.code(),
        Some(2),
        "stdout:\n{}\nstderr:\n{}",
        blocked.stdout,
        blocked.stderr
    );
    assert!(
        blocked.stderr.contains("error invalid_request:"),
        "stderr:\n{}",
        blocked.stderr
    );
}
