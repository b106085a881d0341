//! Command-line interface: one subcommand per role, client commands, benchmarks and
//! experiment runners. Each submodule holds one group of commands.

mod bench;
mod client;
mod json;
mod map;
mod plan;
mod progress;
mod reproduce;
mod reproduce_fleet;
mod roles;
mod ros2;
mod service_args;
mod sim;
mod view;

use clap::{Parser, Subcommand};

use bench::BenchArgs;
use map::MapCommand;
use plan::PlanArgs;
use reproduce::ReproduceArgs;
use roles::{MapServerArgs, PlannerArgs, RouterArgs, StackArgs};

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
  localization Position estimates from TOA ranges (weighted least squares) with their
               Cramér-Rao bound and PEB; PEB at points or over a region; a PEB layer.
  controller   The APF controller (paper 002 §3): attractive, repulsive and
               information-seeking forces with adaptive weights; follows a mission's
               waypoints from the position estimates; halts on stale estimates or a
               lost fix and reports local minima.
  mapper       The change-rate mapper (paper 004): two Poisson processes per cell,
               change-probability, rate and recency layers to the map server; with
               --explore, the curious learner drives robots to where the world changes.
  mission      The mission executive: one robot's tasks; in each downtime window a
               curious path from the planner, driven by the controller, watched,
               replanned when blocked, pushed off or late, and reported.
  sim          The sim world: robots (paper 002's motion model), anchors and TOA
               ranges, moving blocks (paper 004), line-of-sight observations, a clock;
               free-running or in lock-step. `roam sim render` draws a scenario.
  router       A Zenoh router: run one per site or fleet; services connect to it.
  ros2         roam in a ROS 2 system over rmw_zenoh (no bridge): /map and the layers,
               each robot's plan, pose, driven path and /tf frame, the planner as ROS 2
               services and Nav2's ComputePathToPose; optionally the occupancy map from
               a ROS 2 topic, Nav2 robots driven through FollowPath, a rosbag2 record.
  stack        Every landed service in one process around an in-process router on
               loopback, multicast off. The embedded default world needs no files.

CLIENTS AND TOOLS
  demo         roam's main job on the demo's day world: one robot's four downtime
               windows on curious paths; a report directory with a framed picture.
  plan         Ask a running planner for a path; --png draws it.
  map          Inspect map files offline; list and load layers of a running stack.
  bench        Benchmarks that print JSON; the long ones show progress on stderr.
  reproduce    The papers' evaluations and roam's own batches, each claim judged;
               progress on stderr (--quiet: none).
  view         The live view in the Foxglove app (Foxglove WebSocket), MCAP recording.

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
  ROAM_VIEW_TOKEN  The token the live view (`roam view`, `roam demo --view`) requires
                of its clients, instead of --token-file.

EXAMPLES
  roam demo                                  roam's main job on the built-in world, with a report
  roam stack --once                          boot the stack, fetch every layer, report
  roam router --listen tcp/0.0.0.0:7447      on the site server
  roam map-server --mode client --connect tcp/10.0.0.5:7447 --map config/maps/depot.yaml
  roam map layers --connect tcp/10.0.0.5:7447
  roam plan --connect tcp/10.0.0.5:7447 --start -8,-8 --goal 6,-7 --budget 60 --png plan.png
  roam map inspect config/maps/depot.yaml --json
  roam view --connect tcp/127.0.0.1:7447      then open ws://127.0.0.1:8765 in the Foxglove app
  roam view --connect tcp/127.0.0.1:7447 --ws 0.0.0.0:8765 --token-file view.token
                                             then ws://HOST:8765/?token=TOKEN from another machine";

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
    /// Run the localization / CRB service (paper 002 §2).
    Localization(roles::LocalizationArgs),
    /// Run the APF controller with adaptive information seeking (paper 002 §3).
    Controller(roles::ControllerArgs),
    /// Run the change-rate mapper and the curious exploration learner (paper 004).
    Mapper(roles::MapperArgs),
    /// Run a mission executive: one robot's tasks, curious downtime paths, reports.
    Mission(roles::MissionArgs),
    /// roam's main job: the whole stack on the demo's day world, one robot's four downtime
    /// windows (one a round trip) on curious paths; writes a report directory (report.md,
    /// report.json, world.png with a legend).
    Demo(roles::DemoArgs),
    /// Run the sim world (papers 002 and 004), or `sim render` a scenario to a PNG.
    Sim(sim::SimArgs),
    /// Ask a running planner for a curious path (a client).
    Plan(PlanArgs),
    /// Run a Zenoh router (no separate zenohd needed).
    ///
    /// It listens on `--listen`, else on the endpoints of the `ZENOH_CONFIG` file, else on
    /// tcp/0.0.0.0:7447.
    Router(RouterArgs),
    /// Run every landed service in one process around an in-process router.
    Stack(StackArgs),
    /// roam in a ROS 2 system over rmw_zenoh: topics, services, the map from ROS 2.
    Ros2(ros2::Ros2Args),
    /// The live view of a running stack in the Foxglove app, and MCAP recording.
    View(view::ViewArgs),
    /// Map files and the map server's layers.
    #[command(subcommand)]
    Map(MapCommand),
    /// Benchmarks, each measuring one thing on this machine: JSON with --json, progress on
    /// stderr for the long ones.
    Bench(BenchArgs),
    /// Reproduce the papers' evaluations and run roam's own batches (the executive's
    /// days, the fleet's week): ours next to the figures, each claim judged.
    Reproduce(ReproduceArgs),
}

pub async fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::MapServer(args) => roles::map_server(args).await,
        Command::Planner(args) => roles::planner(args).await,
        Command::Sim(args) => sim::sim(args).await,
        Command::Localization(args) => roles::localization(args).await,
        Command::Controller(args) => roles::controller(args).await,
        Command::Mapper(args) => roles::mapper(args).await,
        Command::Mission(args) => roles::mission(args).await,
        Command::Demo(args) => roles::demo(args).await,
        Command::Plan(args) => plan::plan(args).await,
        Command::Router(args) => roles::router(args).await,
        Command::Stack(args) => roles::stack(args).await,
        Command::Ros2(args) => ros2::ros2(args).await,
        Command::View(args) => view::view(args).await,
        Command::Map(command) => map::map(command).await,
        Command::Bench(args) => bench::bench(args).await,
        Command::Reproduce(args) => reproduce::reproduce(args).await,
    }
}
