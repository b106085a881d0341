//! The router alone, and the whole stack in one process (`roam stack`, its `--once`
//! report).

use std::path::PathBuf;
use std::time::Duration;

use anyhow::{bail, Context};
use clap::Args;
use roam::report::{self, Mission};
use roam_runtime::{signals, Requester, SessionArgs};
use roam_stack::router::Router;
use roam_stack::stack::{Stack, StackOptions};

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
    ros: crate::cli::ros2::RosFlags,
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
