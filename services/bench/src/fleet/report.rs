//! What `roam bench fleet` reports.

use serde::Serialize;

#[derive(Debug, Clone, Serialize)]
pub struct FleetBench {
    /// Robots at the end of the timed run: `robots − 1` from its start and the one that
    /// joined halfway.
    pub robots: usize,
    pub rate_hz: f64,
    pub seconds: f64,
    /// Sim steps while running.
    pub steps: u64,
    pub sim_on_time_share: f64,
    /// Commands that answered step k and arrived before step k + 1's clock, over the
    /// commands the steps called for.
    pub loop_on_time_share: f64,
    pub commands_expected: u64,
    pub commands_on_time: u64,
    pub commands_late: u64,
    /// Step k + 1's clock minus step k's, at the subscriber: median and 99th percentile.
    pub step_period_p50_ms: f64,
    pub step_period_p99_ms: f64,
    /// The loop's process (sim, localization, controller, the bench's client; not the
    /// router): CPU time over wall time and cores during the timed run.
    pub cpu_share: f64,
    pub cores: usize,
    pub rss_per_robot_mib: f64,
    pub rss_mib: Option<f64>,
    pub peak_rss_mib: Option<f64>,
    /// The router's process: CPU time over wall time and cores during the timed run.
    pub router_cpu_share: f64,
    /// The router's CPU time per robot and step during the timed run, microseconds
    /// (its share of one core per robot is this × `rate_hz` / 10⁶).
    pub router_cpu_us_per_robot_step: f64,
    /// The router's resident memory at the end of the timed run (`VmRSS`), MiB.
    pub router_rss_mib: Option<f64>,
    /// The router's peak resident memory up to then (`VmHWM`), MiB.
    pub router_peak_rss_mib: Option<f64>,
    /// What the robots added to the router's resident memory, over the robots, MiB.
    pub router_rss_per_robot_mib: f64,
    /// The joining robot: from its first range scan to its first command, both at the
    /// bench's subscriber, ms (`None`: never commanded).
    pub join_ms: Option<f64>,
    /// The joining robot: from the request that added it to its first command, ms.
    pub join_from_add_ms: Option<f64>,
    /// From the router's SIGKILL to the start of the new router, ms ([`ROUTER_DOWN`]
    /// and the time to start a process).
    pub restart_down_ms: f64,
    /// From the new router's start to the first command of any robot after it, ms.
    pub restart_first_command_ms: Option<f64>,
    /// From the new router's start until every robot had been commanded again, ms
    /// (`None`: not every robot within [`RECOVERY_LIMIT`]).
    pub restart_all_commanded_ms: Option<f64>,
    /// The robots commanded again after the restart (of `robots`).
    pub restart_robots_commanded: usize,
    /// The restart phase's steps outside the outage (before the kill, after every
    /// robot was commanded again), and the commands on time in them over robots × steps.
    pub restart_steps_outside: u64,
    pub restart_on_time_share_outside: f64,
    /// The outage's steps (last clock before the kill to the clock when every robot
    /// had been commanded again), and the commands on time in them over robots × steps.
    pub restart_steps_inside: u64,
    pub restart_on_time_share_inside: f64,
}
