//! The view's memory against 60 MB missions, measured: this binary holds this one test,
//! so the process's peak resident size (`VmHWM` in /proc/self/status) is the view's, the
//! router's and the publisher's alone.

mod common;

use common::{mission, put, start_view, until_stats, Stack};
use roam_proto::{encode, keys};
use roam_view::Access;

/// A field of /proc/self/status in KiB (`VmRSS`, `VmHWM`).
fn status_kib(field: &str) -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").expect("/proc/self/status");
    status
        .lines()
        .find_map(|line| line.strip_prefix(field)?.strip_prefix(':'))
        .and_then(|rest| rest.trim().trim_end_matches("kB").trim().parse().ok())
        .unwrap_or_else(|| panic!("no {field} in /proc/self/status"))
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn three_60_mb_missions_leave_the_view_s_memory_flat() {
    let stack = Stack::start().await;
    let (view, cancel) = start_view(&stack.router, &stack.root, Access::default(), None).await;
    let client = stack.client().await;
    let key = keys::robot_mission(&stack.root, "r1");
    put(&client, key.clone(), encode(&mission("r1", "small", 10))).await;
    until_stats(&view, "a small mission", |s| s.robots == 1).await;

    let huge = encode(&mission("r1", "huge", 4_000_000));
    assert!(huge.len() >= 60_000_000, "{} bytes", huge.len());
    let (rss, peak) = (status_kib("VmRSS"), status_kib("VmHWM"));
    for n in 1..=3 {
        put(&client, key.clone(), huge.clone()).await;
        until_stats(&view, "a huge mission", |s| s.oversized == n).await;
    }
    let (rss_after, peak_after) = (status_kib("VmRSS"), status_kib("VmHWM"));
    eprintln!(
        "60 MB missions x3: VmRSS {} -> {} MiB, VmHWM {} -> {} MiB",
        rss / 1024,
        rss_after / 1024,
        peak / 1024,
        peak_after / 1024
    );
    // Each payload passes through Zenoh (the publisher's copy, the router's reassembly)
    // before the view drops it unread; drawing one was gigabytes.
    let grown_mib = peak_after.saturating_sub(peak.max(rss)) / 1024;
    assert!(grown_mib < 512, "the peak grew by {grown_mib} MiB");
    assert_eq!(view.stats().robots, 1);

    cancel.cancel();
    common::within("view stop", view.join())
        .await
        .expect("a clean stop");
    let _ = common::within("client close", client.close()).await;
    stack.stop().await;
}
