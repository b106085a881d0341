//! `roam sim`: the sim world service, and `roam sim render` for a picture of a scenario.

use std::path::PathBuf;

use anyhow::Context;
use clap::{Args, Subcommand};
use roam_sim::service::SimConfig;
use roam_sim::Sim;
use roam_world::scenario::load_or_builtin;

use roam_stack::Role;

use super::service_args::ServiceArgs;

#[derive(Debug, Args)]
#[command(args_conflicts_with_subcommands = true)]
pub(crate) struct SimArgs {
    #[command(subcommand)]
    command: Option<SimCommand>,
    #[command(flatten)]
    run: SimRunArgs,
}

#[derive(Debug, Subcommand)]
enum SimCommand {
    /// Draw a scenario: map, zones of interest, anchors with range circles, blocks, robots.
    Render {
        scenario: PathBuf,
        #[arg(long, value_name = "FILE")]
        png: PathBuf,
        /// Pixels per cell (default: about 800 pixels on the longer side).
        #[arg(long)]
        scale: Option<u32>,
    },
}

#[derive(Debug, Args)]
struct SimRunArgs {
    #[command(flatten)]
    service: ServiceArgs,
    /// A scenario file (default: the config's, else the built-in world).
    #[arg(long, value_name = "PATH")]
    scenario: Option<PathBuf>,
    #[arg(long)]
    seed: Option<u64>,
    /// Free-run at this real-time factor (0: as fast as possible).
    #[arg(long, conflicts_with = "paused")]
    rate: Option<f64>,
    /// Start paused: step only on `step` requests (lock-step).
    #[arg(long)]
    paused: bool,
    /// Keep a snapshot of the clock and robots here and resume from it after a restart.
    #[arg(long, value_name = "FILE")]
    state_file: Option<PathBuf>,
    /// A directory control `load` requests may read scenarios from (repeat for more;
    /// none: loads from the wire are off).
    #[arg(long = "load-dir", value_name = "DIR")]
    load_dirs: Vec<PathBuf>,
}

pub(crate) async fn sim(args: SimArgs) -> anyhow::Result<()> {
    match args.command {
        Some(SimCommand::Render {
            scenario,
            png,
            scale,
        }) => render(scenario, png, scale),
        None => run(args.run).await,
    }
}

async fn run(args: SimRunArgs) -> anyhow::Result<()> {
    let mut config: SimConfig = args.service.load_config()?;
    if args.scenario.is_some() {
        config.scenario = args.scenario;
    }
    if let Some(seed) = args.seed {
        config.seed = seed;
    }
    if args.state_file.is_some() {
        config.state_file = args.state_file;
    }
    if !args.load_dirs.is_empty() {
        config.load_dirs = args.load_dirs;
    }
    if args.paused {
        config.rate = None;
    } else if args.rate.is_some() {
        config.rate = args.rate;
    }
    args.service.run(Role::from(config)).await
}

fn render(scenario: PathBuf, png: PathBuf, scale: Option<u32>) -> anyhow::Result<()> {
    let (_, loaded) = load_or_builtin(Some(&scenario))?;
    let sim = Sim::new(&loaded, 0)?;
    let scale = scale.unwrap_or_else(|| roam_sim::render::auto_scale(&sim));
    let meta = loaded.occupancy.meta;
    let frame = roam::pictures::scenario_frame(
        &loaded.file.name,
        (
            f64::from(meta.width) * meta.resolution,
            f64::from(meta.height) * meta.resolution,
        ),
        meta.resolution,
        f64::from(scale) / meta.resolution,
    );
    roam_world::legend::framed(&roam_sim::render::render(&sim, scale), &frame)
        .save(&png)
        .with_context(|| format!("writing {}", png.display()))?;
    println!("picture: {}", png.display());
    Ok(())
}
