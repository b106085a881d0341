//! The service roles: map server, planner, router, and the whole stack in one process.

use std::path::PathBuf;
use std::time::Duration;

use anyhow::{bail, Context};
use clap::Args;
use roam::report::{self, Mission};
use roam_map_server::MapServerConfig;
use roam_planner::PlannerConfig;
use roam_runtime::{signals, Requester, SessionArgs};
use roam_stack::router::Router;
use roam_stack::stack::{Stack, StackOptions};

use roam_stack::Role;

use super::ServiceArgs;

#[derive(Debug, Args)]
pub(crate) struct MapServerArgs {
    #[command(flatten)]
    service: ServiceArgs,
    /// A ROS map.yaml or a roam scenario (default: the config's, else the built-in world).
    #[arg(long, value_name = "PATH")]
    map: Option<PathBuf>,
    /// Persist layers and versions in this directory.
    #[arg(long, value_name = "DIR")]
    data_dir: Option<PathBuf>,
    /// A directory `<root>/map/load` requests may read from (repeat for more; none:
    /// loads from the wire are off).
    #[arg(long = "load-dir", value_name = "DIR")]
    load_dirs: Vec<PathBuf>,
}

#[derive(Debug, Args)]
pub(crate) struct PlannerArgs {
    #[command(flatten)]
    service: ServiceArgs,
    /// Plans computed at once; more are refused with `busy`.
    #[arg(long)]
    max_concurrent_plans: Option<usize>,
}

#[derive(Debug, Args)]
pub(crate) struct RouterArgs {
    #[command(flatten)]
    session: SessionArgs,
}

#[derive(Debug, Args)]
pub(crate) struct StackArgs {
    /// Key root.
    #[arg(long, env = "ROAM_ROOT")]
    root: Option<String>,
    /// A ROS map.yaml or roam scenario for every service (default: the built-in world);
    /// on a ROS map, the services that need a sim world are left out.
    #[arg(long, visible_alias = "scenario", value_name = "PATH")]
    map: Option<PathBuf>,
    /// Persist the map server's layers here.
    #[arg(long, value_name = "DIR")]
    data_dir: Option<PathBuf>,
    /// A directory the map server's and the sim's `load` requests may read from
    /// (repeat for more; none: loads from the wire are off).
    #[arg(long = "load-dir", value_name = "DIR")]
    load_dirs: Vec<PathBuf>,
    /// The in-process router's endpoint (default: a free port on 127.0.0.1).
    #[arg(long, value_name = "ENDPOINT")]
    listen: Option<String>,
    /// Planner instances to run.
    #[arg(long, default_value_t = 1)]
    planners: usize,
    /// Boot, fetch every layer through Zenoh, write the report and stop.
    #[arg(long)]
    once: bool,
    /// Where --once writes its report.
    #[arg(long, value_name = "DIR", default_value = "roam-report")]
    out: PathBuf,
    /// Offer the stack to ROS 2 over rmw_zenoh (`roam ros2` in the stack; ROS 2 nodes
    /// connect to this stack's router).
    #[arg(long)]
    ros2: bool,
    #[command(flatten)]
    ros: super::ros2::RosFlags,
}

pub(crate) async fn map_server(args: MapServerArgs) -> anyhow::Result<()> {
    let mut config: MapServerConfig = args.service.load_config()?;
    if args.map.is_some() {
        config.map = args.map;
    }
    if args.data_dir.is_some() {
        config.data_dir = args.data_dir;
    }
    if !args.load_dirs.is_empty() {
        config.load_dirs = args.load_dirs;
    }
    args.service.run(Role::from(config)).await
}

pub(crate) async fn planner(args: PlannerArgs) -> anyhow::Result<()> {
    let mut config: PlannerConfig = args.service.load_config()?;
    if let Some(n) = args.max_concurrent_plans {
        config.max_concurrent_plans = n;
    }
    args.service.run(Role::from(config)).await
}

/// The missions of a scenario: from its `start` place to each other place.
pub(crate) fn scenario_missions(map: Option<&std::path::Path>) -> Vec<Mission> {
    let parsed = match map {
        None => roam_world::scenario::builtin(),
        Some(path) => roam_world::scenario::load(path, roam_world::DEFAULT_MAX_CELLS),
    };
    let Ok(scenario) = parsed else {
        return Vec::new();
    };
    let places = &scenario.file.places;
    let Some(start) = places.iter().find(|p| p.name == "start") else {
        return Vec::new();
    };
    places
        .iter()
        .filter(|p| p.name != "start")
        .map(|p| Mission {
            name: format!("start->{}", p.name),
            start: start.at,
            goal: p.at,
        })
        .collect()
}

pub(crate) async fn router(args: RouterArgs) -> anyhow::Result<()> {
    let mut session = args.session;
    // A Zenoh config file is authoritative about where to listen (the secure router's
    // TLS endpoint, say); the flags' default applies only without one.
    let from_file = std::env::var_os(roam_runtime::session::ZENOH_CONFIG_ENV).is_some();
    if session.listen.is_empty() && !from_file {
        session.listen.push("tcp/0.0.0.0:7447".into());
    }
    let endpoint = if session.listen.is_empty() {
        "the endpoints of the ZENOH_CONFIG file".to_owned()
    } else {
        session.listen.join(", ")
    };
    let router = Router::start(&session, endpoint).await?;
    tracing::info!(listen = %router.endpoint, "router running; stop with Ctrl-C or SIGTERM");
    signals::wait_for_stop_signal().await;
    router.close().await;
    Ok(())
}

pub(crate) async fn stack(args: StackArgs) -> anyhow::Result<()> {
    let missions = scenario_missions(args.map.as_deref());
    let options = StackOptions {
        root: args.root,
        map: args.map,
        data_dir: args.data_dir,
        load_dirs: args.load_dirs,
        listen: args.listen,
        planners: args.planners,
        ros2: args.ros2.then(|| args.ros.config()),
        ..StackOptions::default()
    };
    let mut stack = Stack::start(options, Duration::from_secs(30)).await?;
    for (service, why) in &stack.left_out {
        eprintln!("roam stack: {service} left out: {why}");
    }
    eprintln!(
        "roam stack up: router {} (root '{}'); connect with --connect {}",
        stack.router.endpoint, stack.root, stack.router.endpoint
    );
    if args.once {
        let client = roam_runtime::session::open(
            SessionArgs::client_of(&stack.router.endpoint).zenoh_config(None)?,
        )
        .await?;
        let requester = Requester::new(client.clone(), Duration::from_secs(10));
        let outcome = report::build(
            &requester,
            &stack.root,
            &stack.router.endpoint,
            &missions,
            &args.out,
        )
        .await;
        let _ = client.close().await;
        stack.shutdown().await?;
        let report = outcome?;
        print!("{report}");
        let json_path = args.out.join("report.json");
        std::fs::write(&json_path, serde_json::to_vec_pretty(&report)?)
            .with_context(|| format!("writing {}", json_path.display()))?;
        println!("report: {}", json_path.display());
        return Ok(());
    }
    let cancel = signals::cancel_on_signal();
    tokio::select! {
        _ = cancel.cancelled() => {}
        Some((service, reason)) = stack.next_stopped() => {
            stack.shutdown().await.ok();
            bail!("{service} stopped: {reason}");
        }
    }
    stack.shutdown().await?;
    Ok(())
}

#[derive(Debug, Args)]
pub(crate) struct LocalizationArgs {
    #[command(flatten)]
    service: ServiceArgs,
    /// The scenario whose sensing model and anchors to use (default: the built-in world).
    #[arg(long, value_name = "PATH")]
    scenario: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub(crate) struct ControllerArgs {
    #[command(flatten)]
    service: ServiceArgs,
    /// The scenario whose obstacles, anchors and sensing model to use (default: the
    /// built-in world).
    #[arg(long, value_name = "PATH")]
    scenario: Option<PathBuf>,
    /// The information-seeking weighting scheme (paper 002 Eq. 2).
    #[arg(long, value_enum)]
    scheme: Option<SchemeArg>,
    /// The information-seeking weight z_is.
    #[arg(long)]
    z_is: Option<f64>,
    /// Drive only this robot (repeat for several); default: every robot given a
    /// mission. A controller on board a robot names its own.
    #[arg(long = "robot", value_name = "ROBOT")]
    robots: Vec<String>,
}

/// Paper 002's weighting schemes, as the command line spells them.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub(crate) enum SchemeArg {
    Plain,
    Fixed,
    Cutoff,
    Linear,
    Sinusoidal,
}

impl From<SchemeArg> for roam_controller::weights::Scheme {
    fn from(s: SchemeArg) -> Self {
        use roam_controller::weights::Scheme;
        match s {
            SchemeArg::Plain => Scheme::Plain,
            SchemeArg::Fixed => Scheme::Fixed,
            SchemeArg::Cutoff => Scheme::Cutoff,
            SchemeArg::Linear => Scheme::Linear,
            SchemeArg::Sinusoidal => Scheme::Sinusoidal,
        }
    }
}

pub(crate) async fn controller(args: ControllerArgs) -> anyhow::Result<()> {
    let mut config: roam_controller::service::ControllerConfig = args.service.load_config()?;
    if args.scenario.is_some() {
        config.scenario = args.scenario;
    }
    if let Some(scheme) = args.scheme {
        config.apf.scheme = scheme.into();
    }
    if let Some(z_is) = args.z_is {
        config.apf.z_is = z_is;
    }
    if !args.robots.is_empty() {
        config.robots = args.robots;
    }
    args.service.run(Role::from(config)).await
}

#[derive(Debug, Args)]
pub(crate) struct MapperArgs {
    #[command(flatten)]
    service: ServiceArgs,
    /// The scenario whose map the change layers cover (default: the built-in world).
    #[arg(long, value_name = "PATH")]
    scenario: Option<PathBuf>,
    /// A robot the learner drives (paper 004's curious exploration); repeat for more.
    #[arg(long, value_name = "ROBOT")]
    explore: Vec<String>,
}

pub(crate) async fn mapper(args: MapperArgs) -> anyhow::Result<()> {
    let mut config: roam_mapper::service::MapperConfig = args.service.load_config()?;
    if args.scenario.is_some() {
        config.scenario = args.scenario;
    }
    if !args.explore.is_empty() {
        config.explore = args.explore;
    }
    args.service.run(Role::from(config)).await
}

#[derive(Debug, Args)]
pub(crate) struct MissionArgs {
    #[command(flatten)]
    service: ServiceArgs,
    /// The robot to drive (default: the config's, or `robot`).
    #[arg(long)]
    robot: Option<String>,
}

pub(crate) async fn mission(args: MissionArgs) -> anyhow::Result<()> {
    let mut config: roam_mission::service::MissionConfig = args.service.load_config()?;
    if let Some(robot) = args.robot {
        config.executive.robot = robot;
    }
    args.service.run(Role::from(config)).await
}

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
    view_access: super::view::AccessArgs,
    /// Offer the demo to ROS 2 over rmw_zenoh (roam's topics and services; see
    /// services/ros2/README.md).
    #[arg(long)]
    ros2: bool,
    #[command(flatten)]
    ros: super::ros2::RosFlags,
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

pub(crate) async fn localization(args: LocalizationArgs) -> anyhow::Result<()> {
    let mut config: roam_localization::service::LocalizationConfig = args.service.load_config()?;
    if args.scenario.is_some() {
        config.scenario = args.scenario;
    }
    args.service.run(Role::from(config)).await
}
