//! The attack test: what a stranger on an open router (or a low-privilege role) tried
//! against running stacks, repeated against real services through Zenoh, with what must
//! hold asserted:
//!
//! - loads read no file outside the load directories, answer a forbidden file as a
//!   missing one (no existence oracle), name the file as the peer gave it and none of
//!   the server's paths (the log keeps them), and never quote a file, in a reply or a
//!   log ([`files`]);
//! - a stranger creating layers is refused once they would hold more than the map
//!   server's `max_total_cell_bytes`, naming it ([`map_memory`]);
//! - keys decide: a body naming another robot is refused, nothing is published on a key
//!   a body chose, a forged mission or scan moves nothing ([`routing`]);
//! - echoes are bounded and escaped: replies to megabyte fields stay under
//!   [`echo::MAX_ECHO_REPLY_BYTES`], a flood of bad puts grows the log by at most
//!   [`echo::MAX_FLOOD_LOG_BYTES`], and names with newlines or terminal escapes forge no
//!   log line ([`echo`]);
//! - a client flooding the planner's queue leaves another its fair share
//!   ([`planner_flood`]);
//! - the ROS 2 node answers every call to its services, one without rmw_zenoh's
//!   attachment, one of 8 MB and a storm of them, and refuses a map whose header
//!   claims 10⁸ cells from its header, and goes on ([`ros2`]);
//! - the live view refuses a page from a foreign Origin and lets a real client in past
//!   hundreds of half-open connections ([`view`]).
//!
//! Oversized payloads, sent by a stranger's Python client to a `roam stack`, are in
//! `services/roam/tests/oversized.rs`.
//!
//! The phases run one after another in one test, because the log is the process's and
//! its growth is measured. The secure site's version of the file attack (the operator
//! loading the router's user dictionary) is in the access-control test.

mod echo;
mod files;
mod logs;
mod map_memory;
mod planner_flood;
mod ros2;
mod routing;
mod view;

use roam_tests::Harness;

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn attacks_on_a_running_stack_find_nothing() {
    let log = logs::capture();
    let harness = Harness::start().await;
    let client = harness.client().await;

    let files = files::Files::new();
    let from = log.len();
    files::map_loads(&harness, &client, &files).await;
    files::sim_loads(&harness, &client, &files).await;
    files::check_log(&log, from, &files);

    map_memory::layers_within_the_budget(&harness, &client).await;

    routing::keys_decide(&harness, &client).await;

    echo::replies(&harness, &client).await;
    echo::logs(&harness, &client, &log).await;
    echo::numbers(&harness, &client, &log).await;

    planner_flood::second_client(&harness).await;

    ros2::services(&harness, &client).await;
    ros2::map_input(&harness, &client, &log).await;

    view::origins(&harness).await;
    view::half_open(&harness).await;

    harness.close().await;
}
