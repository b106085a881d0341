//! A stranger's oversized queries cannot take a service off the bus: a Python
//! eclipse-zenoh client (`tests/clients/python/oversized.py`, no roam code) sends four
//! 48 MB queries at once to each service of a `roam stack` that answers queries, as the
//! attack that found the hole did, then asks each service a small query from a new
//! session.
//!
//! - The map server takes requests up to 96 MiB (`max_request_bytes`): each of its four
//!   is answered, a refusal naming what to fix.
//! - Every other service takes small requests (64 KiB to 4 MiB): the router stops a
//!   query above `roam_stack::router::EDGE_QUERY_BYTES` (16 MiB) with Zenoh's final reply,
//!   so each of the four ends at once with no answer and no service's link carries it.
//!   A 1 MB query (above their caps, under the router's) still reaches each service and
//!   is refused there by name (the mapper's status ignores its payload and answers).
//! - Every service answers a small query from a new session within 5 s afterwards.
//!
//! The stack runs as installed (no `ZENOH_RUNTIME` from the test's environment). Before
//! the router stopped them, such queries streamed through the router to the service;
//! in one CI run of two, the mapper answered 1 of 4 and then nothing for a minute. On a
//! failure the test prints the stack's last stderr lines (Zenoh's transport warnings).
//!
//! Needs `python3` with `eclipse-zenoh==1.10.2`; without it the test prints a notice and
//! passes, except in CI (`CI` set), where it fails.

mod clients;

use std::path::PathBuf;
use std::time::Duration;

use clients::{python_has, run_python, RoamProcess};
use roam_proto::keys;
use roam_stack::router::free_loopback_port;

const SCRIPT_TIMEOUT: Duration = Duration::from_secs(300);

#[test]
fn oversized_queries_leave_every_service_on_the_bus() {
    if !python_has(
        "zenoh",
        "oversized_queries_leave_every_service_on_the_bus",
        "eclipse-zenoh==1.10.2",
    ) {
        return;
    }
    let port = free_loopback_port().expect("port");
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let root = format!("oversized-{}", std::process::id());
    let mut stack =
        RoamProcess::start_as_installed(&["stack", "--listen", &endpoint], &root, "roam stack up");
    let map_update = keys::map_update(&root, "x");
    let small = [
        keys::mapper_status(&root),
        keys::localization_peb(&root),
        keys::planner_plan(&root),
        keys::sim_control(&root),
    ];
    let all: Vec<&str> = std::iter::once(map_update.as_str())
        .chain(small.iter().map(String::as_str))
        .collect();
    let huge = flood(&endpoint, 48_000_000, &all);
    let large = flood(&endpoint, 1_000_000, &small.each_ref().map(String::as_str));
    let failure = |what: &str| format!("{what}\nstack stderr:\n{}", stack.stderr_tail(40));

    let seen = &huge[map_update.as_str()];
    if seen["answered"] != seen["sent"] {
        panic!("{}", failure(&format!("{map_update}: {seen}")));
    }
    assert_refusals_say_what_to_fix(&map_update, seen);
    for key in &small {
        let seen = &huge[key.as_str()];
        // Stopped at the router: ended at once, never left hanging to the client's timeout.
        let ended = seen["answered"].as_u64().unwrap_or(0)
            + seen["ended_without_reply"].as_u64().unwrap_or(0);
        if Some(ended) != seen["sent"].as_u64() || seen["slowest_s"].as_f64() > Some(10.0) {
            panic!("{}", failure(&format!("48 MB to {key}: {seen}")));
        }
        let seen = &large[key.as_str()];
        if seen["answered"] != seen["sent"] {
            panic!("{}", failure(&format!("1 MB to {key}: {seen}")));
        }
        assert_refusals_say_what_to_fix(key, seen);
    }
    for (key, seen) in huge.iter().chain(large.iter()) {
        if seen["answered_after"] != true {
            panic!(
                "{}",
                failure(&format!("{key} did not answer afterwards: {seen}"))
            );
        }
    }
    let stopped = stack.stop();
    assert!(stopped.is_some_and(|s| s.success()), "{stopped:?}");
}

/// Runs the stranger's script: four queries of `bytes` at once to each key.
fn flood(
    endpoint: &str,
    bytes: usize,
    keys: &[&str],
) -> serde_json::Map<String, serde_json::Value> {
    let script =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/clients/python/oversized.py");
    let bytes = bytes.to_string();
    let mut args = vec!["--connect", endpoint, "--bytes", bytes.as_str()];
    args.extend(keys);
    let run = run_python(&script, &args, SCRIPT_TIMEOUT);
    assert!(run.status.success(), "{run:?}");
    match serde_json::from_str(&run.stdout) {
        Ok(serde_json::Value::Object(out)) => out,
        other => panic!("the script printed no JSON object: {other:?} ({run:?})"),
    }
}

/// Every refusal the service sent names what to fix.
fn assert_refusals_say_what_to_fix(key: &str, seen: &serde_json::Value) {
    for refusal in seen["refusals"].as_array().into_iter().flatten() {
        let text = refusal.as_str().unwrap_or_default();
        assert!(
            text.contains("bytes") || text.contains("payload") || text.contains("message"),
            "{key}: a refusal that does not say what to fix: {text}"
        );
    }
}
