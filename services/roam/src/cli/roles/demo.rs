//! `roam demo`: the day (the built-in one or the user's site), or the warehouse fleet.

use std::path::PathBuf;

use clap::Args;

#[derive(Debug, Args)]
pub(crate) struct DemoArgs {
    /// Where the report goes (world.png, report.json, report.md); default roam-demo, or
    /// roam-demo-fleet with --fleet.
    #[arg(long)]
    out: Option<PathBuf>,
    /// The sim's real-time factor; default 20, or 10 with --fleet.
    #[arg(long)]
    rate: Option<f64>,
    /// The warehouse fleet instead of the day: every robot of the warehouse's shift with
    /// its own mission executive, the planners on the fleet's news, live through Zenoh
    /// for the first --shift-s seconds; the report measures it as `roam reproduce
    /// fleet` measures a week (services/experiments/README.md, "The fleet live").
    #[arg(long, conflicts_with_all = ["map", "tasks"])]
    fleet: bool,
    /// With --fleet: the first N robots of the shift (1 to 10).
    #[arg(long, default_value_t = 10, requires = "fleet")]
    robots: usize,
    /// With --fleet: how much of the shift to run, sim seconds (the tasks that start
    /// within it).
    #[arg(long, default_value_t = 900.0, requires = "fleet")]
    shift_s: f64,
    /// With --fleet: planner instances.
    #[arg(long, default_value_t = 2, requires = "fleet")]
    planners: usize,
    /// With --fleet: the planners plan on the static map only, not around what the
    /// fleet has seen occupied (the mapper's occupied_now); measured: robots drove into
    /// pallets on the dock lanes after every replan, and were late.
    #[arg(long, requires = "fleet")]
    static_map: bool,
    /// The planner's seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Serve the live view here while the demo runs: open ws://ADDR in the Foxglove app
    /// (e.g. 127.0.0.1:8765; --rate 1 to watch at a human pace). An address other than
    /// loopback needs --token-file.
    #[arg(long, value_name = "ADDR")]
    view: Option<std::net::SocketAddr>,
    /// Record the run to this MCAP file (opens in the Foxglove app).
    #[arg(long, value_name = "FILE")]
    record: Option<PathBuf>,
    /// Who may connect to the live view (--view).
    #[command(flatten)]
    view_access: crate::cli::view::AccessArgs,
    /// Offer the demo to ROS 2 over rmw_zenoh (roam's topics and services; see
    /// services/ros2/README.md).
    #[arg(long)]
    ros2: bool,
    #[command(flatten)]
    ros: crate::cli::ros2::RosFlags,
    /// The stack router's endpoint, e.g. tcp/127.0.0.1:7447, where a ROS 2 system
    /// (with --ros2) or any Zenoh client connects; a free loopback port when absent.
    #[arg(long, value_name = "ENDPOINT")]
    listen: Option<String>,
    /// Your own site: a Nav2 map (map.yaml and its image) to run the day on, with
    /// --tasks (services/mission/README.md, "Your own site").
    #[arg(long, value_name = "MAP.yaml", requires = "tasks")]
    map: Option<PathBuf>,
    /// Your own site: the day file (the robot's start, its tasks; optionally zones of
    /// interest, anchors, sensing, moving things), with --map.
    #[arg(long, value_name = "DAY.yaml", requires = "map")]
    tasks: Option<PathBuf>,
}

/// The built-in day, or the user's map and day file, refused with what to fix.
pub(crate) fn site(
    map: Option<&std::path::Path>,
    tasks: Option<&std::path::Path>,
) -> anyhow::Result<roam_mission::site::Site> {
    match (map, tasks) {
        (Some(map), Some(tasks)) => Ok(roam_mission::site::Site::load(map, tasks)?),
        (None, None) => Ok(roam_mission::site::Site::builtin_day()),
        _ => anyhow::bail!("give --map and --tasks together (your Nav2 map and your day file)"),
    }
}

pub(crate) async fn demo(args: DemoArgs) -> anyhow::Result<()> {
    let rate = args.rate.unwrap_or(if args.fleet { 10.0 } else { 20.0 });
    if !(rate.is_finite() && rate > 0.0 && rate <= 100.0) {
        anyhow::bail!("--rate must be more than 0 and at most 100 (times real time)");
    }
    let view = roam::demo::LiveView {
        listen: args.view,
        record: args.record.clone(),
        // Read (and checked) only when there is a live view to guard, and before the
        // stack boots.
        access: match args.view {
            Some(addr) => {
                let access = args.view_access.access()?;
                roam_view::check_exposure(addr, &access)?;
                access
            }
            None => roam_view::Access::default(),
        },
    };
    if args.fleet {
        return fleet_demo(args, rate, view).await;
    }
    let site = site(args.map.as_deref(), args.tasks.as_deref())?;
    let options = roam::demo::DemoOptions {
        out_dir: args.out.unwrap_or_else(|| PathBuf::from("roam-demo")),
        rate,
        seed: args.seed,
        root: None,
        view,
        ros2: args.ros2.then(|| args.ros.config()),
        listen: args.listen,
        site,
    };
    let say = |line: &str| eprintln!("roam demo: {line}");
    let report = roam::demo::run(&options, &say).await?;
    let driven_shares: Vec<String> = report
        .windows
        .iter()
        .map(|w| {
            w.time_model.map_or("-".to_owned(), |m| {
                format!("{:.0}%", m.driven_share * 100.0)
            })
        })
        .collect();
    println!(
        "on time: {}   share of each window driven: {}",
        if report.on_time { "yes" } else { "no" },
        driven_shares.join(" ")
    );
    println!(
        "information: {:.0} (shortest paths: {:.0}; one plan per window planned: {:.0})   mean PEB: {}",
        report.information,
        report.information_shortest_path,
        report.information_baseline_plans,
        report
            .peb_mean_m
            .map_or("-".to_owned(), |p| format!("{p:.3} m"))
    );
    println!("report: {}", options.out_dir.display());
    Ok(())
}

async fn fleet_demo(args: DemoArgs, rate: f64, view: roam::demo::LiveView) -> anyhow::Result<()> {
    let options = roam::demo_fleet::FleetDemoOptions {
        out_dir: args.out.unwrap_or_else(|| PathBuf::from("roam-demo-fleet")),
        rate,
        seed: args.seed,
        robots: args.robots,
        shift_s: args.shift_s,
        planners: args.planners,
        avoid_seen: !args.static_map,
        root: None,
        listen: args.listen,
        view,
        ros2: args.ros2.then(|| args.ros.config()),
    };
    let say = |line: &str| eprintln!("roam demo --fleet: {line}");
    let report = roam::demo_fleet::run(&options, &say).await?;
    let s = &report.summary;
    let num = |x: Option<f64>, unit: &str| x.map_or("-".to_owned(), |v| format!("{v:.0}{unit}"));
    println!(
        "{} robots, {} windows, late: {}   detection median: {}   Brier: {}   plan p50/p99: {} / {}   wall: {:.0} s",
        report.robots,
        s.windows,
        s.late,
        num(s.detection_median_s, " s"),
        s.brier.map_or("-".to_owned(), |b| format!("{b:.4}")),
        num(s.plan_p50_ms, " ms"),
        num(s.plan_p99_ms, " ms"),
        report.wall_s
    );
    for g in &report.goals {
        println!(
            "  {:<24} {:>10} <= {:<8} {}",
            g.goal,
            g.figure.map_or("-".to_owned(), |f| format!("{f:.1}")),
            g.at_most,
            g.verdict()
        );
    }
    println!("report: {}", options.out_dir.display());
    Ok(())
}
