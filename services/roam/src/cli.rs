//! Command-line interface: one subcommand per role, client commands, benchmarks.

use std::path::PathBuf;
use std::time::Duration;

use anyhow::{bail, Context};
use clap::{Args, Parser, Subcommand};
use roam::bench;
use roam::report::{self, Mission};
use roam::router::Router;
use roam::stack::{Stack, StackOptions};
use roam_map_server::grid::Grid;
use roam_map_server::{map_file, render, ros_map, MapServerConfig};
use roam_planner::client::PlannerClient;
use roam_planner::PlannerConfig;
use roam_proto::cells::Cells;
use roam_proto::keys;
use roam_proto::map::Layer;
use roam_proto::map::{LayerList, LoadMap};
use roam_proto::planner::{GaOverrides, Plan, PlanRequest, PlannerModel};
use roam_runtime::{config_file, signals, Requester, SessionArgs};

const ABOUT: &str = "roam: curious, time-aware robot navigation as Zenoh services.";

const LONG_ABOUT: &str = "\
roam turns a robot's downtime between fixed tasks into information: it plans curious \
paths that still arrive on time, drives them while keeping localization uncertainty low, \
and learns where the world changes. Each part is an independent service speaking over \
Zenoh; this one binary runs every role.

ROLES
  map-server   Holds the occupancy, inflated, information and heuristic layers (and the
               layers other services publish), versioned and optionally persisted.
  planner      The curious GA planner (paper 000): a path from here to the next task
               that gathers the most information and still arrives within the budget.
               Run several; clients spread plans over the live instances.
  router       A Zenoh router: run one per site or fleet; services connect to it.
  stack        Every landed service in one process around an in-process router on
               loopback, multicast off. The embedded default world needs no files.

CLIENTS AND TOOLS
  plan         Ask a running planner for a path; --png draws it.
  map          Inspect map files offline; list, load and fetch layers of a running stack.
  bench        Benchmarks that print JSON.

CONFIG FILE
  A service reads its own YAML config with --config (see config/map-server.yaml). Its
  `zenoh:` section is a Zenoh config fragment. Zenoh settings are layered, lowest first:
  the config file's `zenoh:` section, the file named by ZENOH_CONFIG, the flags --mode,
  --connect, --listen, --no-multicast, then each --cfg KEY:VALUE.

ENVIRONMENT
  ZENOH_CONFIG  A Zenoh JSON5 or YAML config file for every session of the process.
  RUST_LOG      Log filter (default: info, Zenoh at warn), e.g. RUST_LOG=debug.
  ROAM_ROOT     The key root (default `roam`); two stacks with different roots never
                see each other.

EXAMPLES
  roam stack --once                          boot the stack, fetch every layer, report
  roam router --listen tcp/0.0.0.0:7447      on the site server
  roam map-server --mode client --connect tcp/10.0.0.5:7447 --map config/maps/depot.yaml
  roam map layers --connect tcp/10.0.0.5:7447
  roam plan --connect tcp/10.0.0.5:7447 --start -8,-8 --goal 6,-7 --budget 60 --png plan.png
  roam map inspect config/maps/depot.yaml --json";

#[derive(Debug, Parser)]
#[command(name = "roam", version, about = ABOUT, long_about = LONG_ABOUT)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run the map server: layers, versions, persistence.
    MapServer(MapServerArgs),
    /// Run a curious GA planner instance (paper 000).
    Planner(PlannerArgs),
    /// Ask a running planner for a curious path (a client).
    Plan(PlanArgs),
    /// Run a Zenoh router (no separate zenohd needed).
    Router(RouterArgs),
    /// Run every landed service in one process around an in-process router.
    Stack(StackArgs),
    /// Map files and the map server's layers.
    #[command(subcommand)]
    Map(MapCommand),
    /// Benchmarks; each prints JSON with --json.
    #[command(subcommand)]
    Bench(BenchCommand),
    /// Reproduce a paper's evaluation and print ours next to its figures.
    #[command(subcommand)]
    Reproduce(ReproduceCommand),
}

#[derive(Debug, Subcommand)]
enum ReproduceCommand {
    /// Paper 000 §III: Models 0 / I / II, two goals, three t_plan/t_exec ratios.
    Planner {
        /// Print {"rows": [...], "comparisons": [...], "pictures": [...]} as JSON.
        #[arg(long)]
        json: bool,
        /// Runs per goal, ratio and model (the paper: 20).
        #[arg(long, default_value_t = 20)]
        runs: usize,
        /// Total time T = t_plan + t_exec, seconds.
        #[arg(long, default_value_t = 100.0)]
        total: f64,
        /// Generations that all of T would buy; t_plan = r·T buys r times this.
        #[arg(long, default_value_t = 2500.0)]
        generations_per_t: f64,
        /// Where the per-model pictures go.
        #[arg(long, default_value = "roam-reproduce/planner")]
        out: PathBuf,
    },
}

#[derive(Debug, Args)]
struct ServiceArgs {
    /// The service's YAML config file.
    #[arg(long, value_name = "FILE")]
    config: Option<PathBuf>,
    /// Key root for every key expression.
    #[arg(long, env = "ROAM_ROOT")]
    root: Option<String>,
    /// Instance name in the liveliness token (default: the Zenoh session id).
    #[arg(long)]
    instance: Option<String>,
    #[command(flatten)]
    session: SessionArgs,
}

#[derive(Debug, Args)]
struct MapServerArgs {
    #[command(flatten)]
    service: ServiceArgs,
    /// A ROS map.yaml or a roam scenario (default: the config's, else the built-in world).
    #[arg(long, value_name = "PATH")]
    map: Option<PathBuf>,
    /// Persist layers and versions in this directory.
    #[arg(long, value_name = "DIR")]
    data_dir: Option<PathBuf>,
}

#[derive(Debug, Args)]
struct PlannerArgs {
    #[command(flatten)]
    service: ServiceArgs,
    /// Plans computed at once; more are refused with `busy`.
    #[arg(long)]
    max_concurrent_plans: Option<usize>,
}

#[derive(Debug, Args)]
struct PlanArgs {
    /// Start, world metres: X,Y.
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
    start: [f64; 2],
    /// Goal, world metres: X,Y.
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
    goal: [f64; 2],
    /// Seconds the robot has to drive (t_exec).
    #[arg(long)]
    budget: f64,
    /// Curiosity model: 0, 1, 2 or shortest.
    #[arg(long, default_value = "1", value_parser = parse_model)]
    model: PlannerModel,
    /// Seconds the planner may take (t_plan).
    #[arg(long, default_value_t = 5.0)]
    deadline: f64,
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// GA generations (Table I: 2000).
    #[arg(long)]
    generations: Option<u32>,
    /// Draw the map, the information layer and the path to this PNG.
    #[arg(long, value_name = "FILE")]
    png: Option<PathBuf>,
    /// Print the whole plan as JSON.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    client: ClientArgs,
}

fn parse_point(text: &str) -> Result<[f64; 2], String> {
    let (x, y) = text
        .split_once(',')
        .ok_or_else(|| format!("'{text}' is not X,Y (e.g. -8,-8)"))?;
    let parse = |v: &str| {
        v.trim()
            .parse::<f64>()
            .map_err(|e| format!("'{v}' in '{text}': {e}"))
    };
    Ok([parse(x)?, parse(y)?])
}

fn parse_model(text: &str) -> Result<PlannerModel, String> {
    match text {
        "0" | "model0" => Ok(PlannerModel::Model0),
        "1" | "model1" => Ok(PlannerModel::Model1),
        "2" | "model2" => Ok(PlannerModel::Model2),
        "shortest" => Ok(PlannerModel::Shortest),
        other => Err(format!("'{other}' is not a model; use 0, 1, 2 or shortest")),
    }
}

#[derive(Debug, Args)]
struct RouterArgs {
    #[command(flatten)]
    session: SessionArgs,
}

#[derive(Debug, Args)]
struct StackArgs {
    /// Key root.
    #[arg(long, env = "ROAM_ROOT")]
    root: Option<String>,
    /// A ROS map.yaml or roam scenario for the map server (default: the built-in world).
    #[arg(long, value_name = "PATH")]
    map: Option<PathBuf>,
    /// Persist the map server's layers here.
    #[arg(long, value_name = "DIR")]
    data_dir: Option<PathBuf>,
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
}

#[derive(Debug, Subcommand)]
enum MapCommand {
    /// Read a ROS map.yaml without any network and print its size and cell counts.
    Inspect {
        map: PathBuf,
        /// Print JSON: {"width","height","resolution","origin","occupied","free","unknown"}.
        #[arg(long)]
        json: bool,
    },
    /// List the layers of a running map server.
    Layers(ClientArgs),
    /// Ask a running map server to load a map file from its own file system.
    Load {
        path: String,
        #[command(flatten)]
        client: ClientArgs,
    },
}

#[derive(Debug, Args)]
struct ClientArgs {
    #[arg(long, env = "ROAM_ROOT", default_value = keys::DEFAULT_ROOT)]
    root: String,
    /// Seconds to wait for an answer.
    #[arg(long, default_value_t = 5.0)]
    timeout: f64,
    #[command(flatten)]
    session: SessionArgs,
}

#[derive(Debug, Subcommand)]
enum BenchCommand {
    /// Get and publish of a ~1.7-million-cell layer through Zenoh.
    Map {
        #[arg(long)]
        json: bool,
        /// Map side in cells (1304² ≈ 1.7 million).
        #[arg(long, default_value_t = 1304)]
        side: u32,
        #[arg(long, default_value_t = 20)]
        iterations: usize,
    },
    /// The GA per curiosity model (2000 generations, population 200) and the service overhead.
    Planner {
        #[arg(long)]
        json: bool,
        /// Plans per model.
        #[arg(long, default_value_t = 5)]
        runs: usize,
    },
}

pub async fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::MapServer(args) => map_server(args).await,
        Command::Planner(args) => planner(args).await,
        Command::Plan(args) => plan(args).await,
        Command::Router(args) => router(args).await,
        Command::Stack(args) => stack(args).await,
        Command::Map(command) => map(command).await,
        Command::Bench(command) => bench(command).await,
        Command::Reproduce(ReproduceCommand::Planner {
            json,
            runs,
            total,
            generations_per_t,
            out,
        }) => {
            if runs == 0
                || !(total.is_finite() && total > 0.0)
                || !(generations_per_t.is_finite() && generations_per_t >= 1.0)
            {
                bail!("--runs must be at least 1, --total positive and --generations-per-t at least 1");
            }
            let options = roam::reproduce_planner::ReproduceOptions {
                runs,
                total_s: total,
                generations_per_t,
                out_dir: out,
            };
            let result =
                tokio::task::spawn_blocking(move || roam::reproduce_planner::run(&options))
                    .await??;
            if json {
                println!("{}", serde_json::to_string(&result)?);
            } else {
                print!("{result}");
            }
            Ok(())
        }
    }
}

async fn map_server(args: MapServerArgs) -> anyhow::Result<()> {
    let mut config: MapServerConfig = match &args.service.config {
        Some(path) => config_file::load(path)?,
        None => MapServerConfig::default(),
    };
    if let Some(root) = args.service.root {
        config.root = root;
    }
    if args.service.instance.is_some() {
        config.instance = args.service.instance;
    }
    if args.map.is_some() {
        config.map = args.map;
    }
    if args.data_dir.is_some() {
        config.data_dir = args.data_dir;
    }
    let zenoh = args.service.session.zenoh_config(config.zenoh.as_ref())?;
    let cancel = signals::cancel_on_signal();
    roam_map_server::run(config, zenoh, cancel).await?;
    Ok(())
}

async fn planner(args: PlannerArgs) -> anyhow::Result<()> {
    let mut config: PlannerConfig = match &args.service.config {
        Some(path) => config_file::load(path)?,
        None => PlannerConfig::default(),
    };
    if let Some(root) = args.service.root {
        config.root = root;
    }
    if args.service.instance.is_some() {
        config.instance = args.service.instance;
    }
    if let Some(n) = args.max_concurrent_plans {
        config.max_concurrent_plans = n;
    }
    let zenoh = args.service.session.zenoh_config(config.zenoh.as_ref())?;
    roam_planner::run(config, zenoh, signals::cancel_on_signal()).await?;
    Ok(())
}

async fn plan(args: PlanArgs) -> anyhow::Result<()> {
    let (requester, session) = connect(&args.client).await?;
    let planner = PlannerClient::new(session.clone(), &args.client.root);
    let request = PlanRequest {
        request_id: None,
        start: args.start,
        goal: args.goal,
        t_exec_s: args.budget,
        deadline_s: args.deadline,
        model: args.model,
        params: GaOverrides {
            max_generations: args.generations,
            ..GaOverrides::default()
        },
        seed: args.seed,
        map_version: None,
    };
    let outcome = planner.plan(&request).await;
    let picture = match (&outcome, &args.png) {
        (Ok(plan), Some(path)) => Some(draw_plan(&requester, &args.client.root, plan, path).await),
        _ => None,
    };
    let _ = session.close().await;
    let plan = outcome?;
    if let Some(result) = picture {
        result?;
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&plan)?);
    } else {
        println!(
            "{} plan {} by {}: {} cells, ETA {:.1} s of {:.1} s ({}), {} the goal\n  U_ges {:.0}, D {:.1}, distinct information {:.0}, fitness {:.0}, {} generations in {:.0} ms ({:?})",
            plan.model.as_str(),
            plan.request_id,
            plan.instance,
            plan.cells.len(),
            plan.t_eta_s,
            args.budget,
            if plan.within_budget { "within budget" } else { "OVER budget" },
            if plan.reaches_goal { "reaches" } else { "does NOT reach" },
            plan.u_ges,
            plan.density,
            plan.distinct_information,
            plan.fitness.total,
            plan.generations,
            plan.planning_ms,
            plan.stop_reason
        );
    }
    if let Some(path) = &args.png {
        println!("picture: {}", path.display());
    }
    Ok(())
}

/// Fetches occupancy and information from the map server and draws the plan over them.
async fn draw_plan(
    requester: &Requester,
    root: &str,
    plan: &Plan,
    path: &std::path::Path,
) -> anyhow::Result<()> {
    let occupancy: Layer = requester
        .request::<Layer, Layer>(&keys::map_layer(root, "occupancy"), None)
        .await?;
    let information: Layer = requester
        .request::<Layer, Layer>(&keys::map_layer(root, "information"), None)
        .await?;
    let (Cells::I8(occ), Cells::U8(info)) = (occupancy.cells, information.cells) else {
        bail!("the map server's occupancy or information layer has an unexpected type");
    };
    let occ = Grid {
        meta: occupancy.meta,
        cells: occ,
    };
    let info = Grid {
        meta: information.meta,
        cells: info,
    };
    let scale = (800 / occ.meta.width.max(occ.meta.height)).clamp(1, 8);
    let mut image = render::render_map(&occ, Some(&info), scale);
    render::draw_path(
        &mut image,
        occ.meta.height,
        &plan.cells,
        scale,
        render::PATH,
    );
    for end in [plan.cells.first(), plan.cells.last()]
        .into_iter()
        .flatten()
    {
        render::draw_marker(&mut image, occ.meta.height, *end, scale, render::MARKER);
    }
    image
        .save(path)
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}

/// The missions of a scenario: from its `start` place to each other place.
fn scenario_missions(map: Option<&std::path::Path>) -> Vec<Mission> {
    let max = roam_map_server::store::DEFAULT_LIMITS.max_layer_cells;
    let parsed = match map {
        None => roam_map_server::scenario::parse(
            std::path::Path::new(map_file::BUILTIN_NAME),
            map_file::BUILTIN_SCENARIO,
            max,
        )
        .ok(),
        Some(path) => roam_map_server::scenario::load(path, max).ok(),
    };
    let Some(scenario) = parsed else {
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

async fn router(args: RouterArgs) -> anyhow::Result<()> {
    let mut session = args.session;
    if session.listen.is_empty() {
        session.listen.push("tcp/0.0.0.0:7447".into());
    }
    let endpoint = session.listen.join(", ");
    let router = Router::start(&session, endpoint).await?;
    tracing::info!(listen = %router.endpoint, "router running; stop with Ctrl-C or SIGTERM");
    signals::wait_for_stop_signal().await;
    router.close().await;
    Ok(())
}

async fn stack(args: StackArgs) -> anyhow::Result<()> {
    let missions = scenario_missions(args.map.as_deref());
    let options = StackOptions {
        root: args.root,
        map: args.map,
        data_dir: args.data_dir,
        listen: args.listen,
        planners: args.planners,
    };
    let mut stack = Stack::start(options, Duration::from_secs(30)).await?;
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

async fn map(command: MapCommand) -> anyhow::Result<()> {
    match command {
        MapCommand::Inspect { map, json } => {
            let loaded =
                ros_map::load(&map, roam_map_server::store::DEFAULT_LIMITS.max_layer_cells)?;
            let counts = ros_map::count_cells(&loaded.grid);
            let meta = loaded.grid.meta;
            let value = serde_json::json!({
                "width": meta.width,
                "height": meta.height,
                "resolution": meta.resolution,
                "origin": [meta.origin.x, meta.origin.y, meta.origin.yaw],
                "occupied": counts.occupied,
                "free": counts.free,
                "unknown": counts.unknown,
            });
            if json {
                println!("{value}");
            } else {
                println!(
                    "{}: {}x{} cells at {} m/cell, origin ({}, {}, {}), mode {}\n  occupied {}  free {}  unknown {}",
                    map.display(),
                    meta.width,
                    meta.height,
                    meta.resolution,
                    meta.origin.x,
                    meta.origin.y,
                    meta.origin.yaw,
                    loaded.params.mode.as_str(),
                    counts.occupied,
                    counts.free,
                    counts.unknown
                );
            }
            Ok(())
        }
        MapCommand::Layers(client) => {
            let (requester, session) = connect(&client).await?;
            let list: Result<LayerList, _> = requester
                .request::<LayerList, LayerList>(&keys::map_index(&client.root), None)
                .await;
            let _ = session.close().await;
            println!("{}", serde_json::to_string_pretty(&list?)?);
            Ok(())
        }
        MapCommand::Load { path, client } => {
            let (requester, session) = connect(&client).await?;
            let request = LoadMap {
                path,
                base_version: None,
            };
            let list: Result<LayerList, _> = requester
                .request(&keys::map_load(&client.root), Some(&request))
                .await;
            let _ = session.close().await;
            println!("{}", serde_json::to_string_pretty(&list?)?);
            Ok(())
        }
    }
}

async fn connect(client: &ClientArgs) -> anyhow::Result<(Requester, zenoh::Session)> {
    if !(client.timeout.is_finite() && client.timeout > 0.0) {
        bail!("--timeout must be a positive number of seconds");
    }
    let session = roam_runtime::session::open(client.session.zenoh_config(None)?).await?;
    Ok((
        Requester::new(session.clone(), Duration::from_secs_f64(client.timeout)),
        session,
    ))
}

async fn bench(command: BenchCommand) -> anyhow::Result<()> {
    match command {
        BenchCommand::Map {
            json,
            side,
            iterations,
        } => {
            if iterations == 0 || side < 8 {
                bail!("--iterations must be at least 1 and --side at least 8");
            }
            let dir = std::env::temp_dir().join(format!("roam-bench-map-{}", std::process::id()));
            std::fs::create_dir_all(&dir)?;
            let result = bench::map(side, iterations, &dir).await;
            let _ = std::fs::remove_dir_all(&dir);
            let result = result?;
            print_json(&result, json)
        }
        BenchCommand::Planner { json, runs } => {
            if runs == 0 {
                bail!("--runs must be at least 1");
            }
            let result = roam::bench_planner::planner(runs).await?;
            print_json(&result, json)
        }
    }
}

fn print_json<T: serde::Serialize>(value: &T, compact: bool) -> anyhow::Result<()> {
    if compact {
        println!("{}", serde_json::to_string(value)?);
    } else {
        println!("{}", serde_json::to_string_pretty(value)?);
    }
    Ok(())
}
