//! `roam reproduce fleet`: the fleet's week in the warehouse, its table or JSON on stdout,
//! its progress and runtime on stderr.

use roam_experiments::reproduce::fleet::{self, FleetOptions, FleetVariant};
use roam_proto::planner::PlannerModel;

use super::progress::Progress;

#[derive(Debug, clap::Args)]
pub(crate) struct FleetArgs {
    /// Print the report as JSON: the variants' figures, the goals with verdicts, and
    /// every variant's windows, map samples and change events.
    #[arg(long)]
    json: bool,
    /// Shifts in a row (a week: 7).
    #[arg(long, default_value_t = 7)]
    days: usize,
    /// The variants to run, comma-separated (default tasks_only, patrol, independent,
    /// news, news_no_sharing, news_no_reservations, news_no_rates; also
    /// news_map_replans).
    #[arg(long, value_delimiter = ',')]
    variants: Vec<String>,
    /// Threads the variants run on (default: the machine's cores; the report does not
    /// depend on it, but for the plans' computing times).
    #[arg(long)]
    jobs: Option<usize>,
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// GA generations per curious plan (model0, model1, model2).
    #[arg(long, default_value_t = FleetOptions::default().generations)]
    generations: u32,
    /// The curious variants' planner: greedy (default) or a GA model (model0, model1,
    /// model2).
    #[arg(long, default_value = "greedy")]
    model: String,
    /// W_loc, the weight of the PEB cost in the curious variants' plans (0 turns it off;
    /// the larger, the wider the berth around the anchor gaps).
    #[arg(long, default_value_t = FleetOptions::default().w_loc)]
    w_loc: f64,
    /// The PEB (metres) the PEB cost forgives: a cell costs W_loc · max(0, PEB − this).
    #[arg(long, default_value_t = FleetOptions::default().peb_free_m)]
    peb_free_m: f64,
    /// Plan on the static map only: no plan goes around what the fleet has seen (a
    /// pallet left in an aisle), as `roam demo --fleet --static-map`.
    #[arg(long)]
    static_map: bool,
    /// Write the week's pictures into this directory: detection.svg (the share of the
    /// changes seen within t minutes, per variant) and warehouse-<variant>.svg (paths,
    /// changes, zones, anchors).
    #[arg(long)]
    svg: Option<std::path::PathBuf>,
    /// Your own site instead of the built-in warehouse: a scenario file (map, robots,
    /// anchors, zones, changes; services/world/README.md), with --shift.
    #[arg(long, value_name = "SCENARIO.yaml", requires = "shift")]
    scenario: Option<std::path::PathBuf>,
    /// Your own site: its robots' shift file (roam_mission::shift; `patrol:` corners
    /// for the patrol variant), with --scenario.
    #[arg(long, value_name = "SHIFT.yaml", requires = "scenario")]
    shift: Option<std::path::PathBuf>,
}

/// The curious planner named `name`.
fn curious_model(name: &str) -> Option<PlannerModel> {
    [
        PlannerModel::Greedy,
        PlannerModel::Model0,
        PlannerModel::Model1,
        PlannerModel::Model2,
    ]
    .into_iter()
    .find(|m| m.as_str() == name)
}

pub(crate) async fn run(args: FleetArgs, quiet: bool) -> anyhow::Result<()> {
    let mut options = FleetOptions {
        days: args.days,
        seed: args.seed,
        generations: args.generations,
        w_loc: args.w_loc,
        peb_free_m: args.peb_free_m,
        avoid_seen: !args.static_map,
        model: curious_model(&args.model).ok_or_else(|| {
            anyhow::anyhow!(
                "no planner model {:?}; give greedy, model0, model1 or model2",
                args.model
            )
        })?,
        ..FleetOptions::default()
    };
    if !args.variants.is_empty() {
        options.variants = args
            .variants
            .iter()
            .map(|name| {
                FleetVariant::parse(name).ok_or_else(|| {
                    let all: Vec<&str> = FleetVariant::ALL.iter().map(|v| v.name()).collect();
                    anyhow::anyhow!("no variant {name:?}; give some of {}", all.join(","))
                })
            })
            .collect::<anyhow::Result<_>>()?;
    }
    if let Some(jobs) = args.jobs {
        options.jobs = jobs;
    }
    let started = std::time::Instant::now();
    let world = std::sync::Arc::new(match (&args.scenario, &args.shift) {
        (Some(scenario), Some(shift)) => fleet::FleetWorld::from_files(scenario, shift)?,
        _ => fleet::FleetWorld::warehouse()?,
    });
    let run = options.clone();
    let progress = std::sync::Arc::new(Progress::new("the fleet's", quiet));
    let reporting = progress.clone();
    let on = world.clone();
    let report =
        tokio::task::spawn_blocking(move || fleet::run_on(&on, &run, &reporting.callback()))
            .await??;
    if progress.speaks() {
        eprintln!(
            "{} shifts x {} variants in {:.1} s ({} threads)",
            options.days,
            report.variants.len(),
            started.elapsed().as_secs_f64(),
            options.jobs
        );
    }
    if let Some(dir) = &args.svg {
        for path in fleet::picture::write(dir, &world, &report.weeks, options.seed)? {
            if progress.speaks() {
                eprintln!("wrote {}", path.display());
            }
        }
    }
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        print!("{}", report.table());
    }
    Ok(())
}
