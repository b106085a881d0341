//! The roles that run one of roam's services each: map server, planner, localization,
//! controller, mapper, mission executive.

use std::path::PathBuf;

use clap::Args;
use roam_map_server::MapServerConfig;
use roam_planner::PlannerConfig;
use roam_stack::Role;

use crate::cli::service_args::ServiceArgs;

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

pub(crate) async fn localization(args: LocalizationArgs) -> anyhow::Result<()> {
    let mut config: roam_localization::service::LocalizationConfig = args.service.load_config()?;
    if args.scenario.is_some() {
        config.scenario = args.scenario;
    }
    args.service.run(Role::from(config)).await
}
