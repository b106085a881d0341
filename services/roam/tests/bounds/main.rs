//! The bounds test: work within the documented limits never freezes a service, never
//! knocks one off its router and never grows memory without bound. Each role runs as
//! its own `roam` process behind one router, so each one's peak memory is its own, and
//! the test attacks them through Zenoh as a stranger would:
//!
//! - the sim is given every rate it accepts and answers pause, resume and reset within
//!   [`sim::CONTROL_WITHIN`] after each; rates it cannot keep and step requests over its
//!   robot-step limit are refused; two lock-step drivers at once get one answer and one
//!   `busy`;
//! - the map server gets [`map_updates::CONCURRENT`] set_cells of 50 MB (more cells than
//!   an update may carry) and as many replaces of a maximal f32 layer (90 MB) at once:
//!   each is answered, its liveliness token never drops, its peak memory stays under
//!   [`MAP_SERVER_PEAK_MIB`];
//! - the planner gets three maximal requests at once (population 2000, a 600 s
//!   deadline): each is answered within its `max_plan_seconds` (cut there) or refused
//!   `busy` at once;
//! - the controller and the view get three 60 MB missions, missions for 1,000 robots
//!   that do not exist and one with a 1 MB id: nothing is commanded, and their peaks stay
//!   under [`CONTROLLER_PEAK_MIB`] and [`VIEW_PEAK_MIB`].
//!
//! The figures are printed as one JSON line (`bounds: {...}`); services/roam/README.md quotes them.
//! The binary is the test profile's (debug), so the figures are a debug build's.

mod liveliness;
mod map_updates;
mod missions;
mod planner;
mod procs;
mod sim;

use procs::{wait_live, Proc};
use roam_stack::router::free_loopback_port;

/// The map server's peak under the update attack, MiB (measured 1.9 GB): one maximal
/// update in work at a time (its payload budget) costs a few times its 90 MB, the
/// queued requests' payloads wait in Zenoh, and each maximal layer it then holds is
/// kept decoded and encoded (67 + 90 MB). A deployment that keeps `max_request_bytes`
/// at 96 MiB and accepts maximal layers gives the map server this much.
const MAP_SERVER_PEAK_MIB: u64 = 2560;
/// The controller's peak under the mission attack, MiB (measured 36): missions over
/// their size are dropped unread, ghosts' missions wait in a small table.
const CONTROLLER_PEAK_MIB: u64 = 160;
/// The view's peak over the whole test, MiB (measured 715): it also shows the three
/// maximal layers the update attack created (its layer cells are capped at 1 GiB).
const VIEW_PEAK_MIB: u64 = 1024;
/// What the mission attack may add to the view's peak, MiB (measured 64-156): three 60 MB
/// missions are dropped unread, but Zenoh receives each sample whole (defragmented)
/// before any subscriber can see its size, so a few of them are in memory at once.
const VIEW_MISSION_GROWTH_MIB: u64 = 256;

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn work_within_the_limits_is_bounded() {
    let dir = tempfile::tempdir().expect("tmp");
    let root = format!("bounds-{}", std::process::id());
    let endpoint = format!("tcp/127.0.0.1:{}", free_loopback_port().expect("port"));
    let ws = format!("127.0.0.1:{}", free_loopback_port().expect("port"));
    let client = [
        "--mode",
        "client",
        "--connect",
        &endpoint,
        "--no-multicast",
        "--root",
        &root,
    ];
    let with = |role: &str, extra: &[&str]| -> Vec<String> {
        let mut args = vec![role.to_owned()];
        args.extend(client.iter().map(|s| s.to_string()));
        args.extend(extra.iter().map(|s| s.to_string()));
        args
    };
    let start = |name: &str, args: Vec<String>| {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        Proc::start(dir.path(), name, &args)
    };
    let _router = Proc::start(
        dir.path(),
        "router",
        &["router", "--listen", &endpoint, "--no-multicast"],
    );
    let session = procs::connect(&endpoint).await;
    let mut map_server = start("map-server", with("map-server", &[]));
    let mut sim_proc = start("sim", with("sim", &["--paused"]));
    let mut controller = start("controller", with("controller", &[]));
    let planner_config = dir.path().join("planner.yaml");
    std::fs::write(&planner_config, planner::config()).expect("planner config");
    let planner_config = planner_config.display().to_string();
    let mut planner_proc = start("planner", with("planner", &["--config", &planner_config]));
    let mut view = start("view", with("view", &["--ws", &ws]));
    for service in ["map-server", "sim", "controller", "planner"] {
        wait_live(&session, &root, service).await;
    }

    let control_slowest = sim::rates(&session, &root).await;
    sim::concurrent_steps(&session, &root).await;

    let plan_slowest = planner::maximal_plans(&session, &root).await;

    let updates = map_updates::concurrent_big_updates(&session, &root).await;

    let controller_before = controller.peak_mib();
    let view_before = view.peak_mib();
    let acted = missions::attack(&session, &root).await;

    let figures = serde_json::json!({
        "sim_control_slowest_ms": control_slowest.as_millis() as u64,
        "maximal_plan_slowest_s": plan_slowest.as_secs_f64(),
        "planner_max_plan_seconds": planner::MAX_PLAN_SECONDS,
        "planner_peak_mib": planner_proc.peak_mib(),
        "map_updates": updates.requests,
        "map_updates_answered": updates.answered,
        "map_update_slowest_s": updates.slowest.as_secs_f64(),
        "map_server_liveliness_drops": updates.drops,
        "map_server_peak_mib": map_server.peak_mib(),
        "controller_peak_mib": [controller_before, controller.peak_mib()],
        "view_peak_mib": [view_before, view.peak_mib()],
        "view_mission_growth_mib": view.peak_mib().saturating_sub(view_before),
        "view_rss_mib": view.rss_mib(),
        "missions_acted_on": acted,
    });
    println!("bounds: {figures}");
    for p in [
        &mut map_server,
        &mut sim_proc,
        &mut controller,
        &mut view,
        &mut planner_proc,
    ] {
        assert!(
            p.running(),
            "{} died under the attack (see its log)",
            p.name
        );
    }
    assert_eq!(updates.drops, 0, "the map server lost its router");
    assert_eq!(
        updates.answered, updates.requests,
        "every update is answered"
    );
    assert!(map_server.peak_mib() <= MAP_SERVER_PEAK_MIB, "{figures}");
    assert!(controller.peak_mib() <= CONTROLLER_PEAK_MIB, "{figures}");
    assert!(view.peak_mib() <= VIEW_PEAK_MIB, "{figures}");
    assert!(
        view.peak_mib().saturating_sub(view_before) <= VIEW_MISSION_GROWTH_MIB,
        "{figures}"
    );
    assert_eq!(acted, 0, "a stranger's mission was acted on");
}
