//! `roam reproduce`: the papers' experiments, our figures next to theirs with verdicts.

use std::path::PathBuf;

use anyhow::bail;
use clap::{Args, Subcommand};

use super::progress::Progress;

/// `roam reproduce [--quiet] <experiment>`.
#[derive(Debug, Args)]
pub(crate) struct ReproduceArgs {
    /// Show no progress on stderr (it is drawn only when stderr is a terminal; to a
    /// pipe or a file, one line per finished stage).
    #[arg(long, global = true)]
    quiet: bool,
    #[command(subcommand)]
    command: ReproduceCommand,
}

#[derive(Debug, Subcommand)]
pub(crate) enum ReproduceCommand {
    /// The papers joined: downtime missions per coupling, or with --days N the
    /// executive's whole day N times per variant, against the goals.
    ///
    /// Without --days: seeded downtime missions in the built-in world, planned on the
    /// static information map, with the PEB localizability cost, and the shortest path.
    /// With --days N: the executive's whole day (tasks::day() on the day world) N times
    /// per variant (the shipped executive, without each coupling, the paper's planner
    /// alone, the fastest path), driven by the executive's own window machine, against
    /// the goals.
    Mission {
        /// Print {"missions", "variants": [{"variant", "information", "on_time_share", "peb_mean_m"}]};
        /// with --days, the days' report (variants, goals with verdicts, every window).
        #[arg(long)]
        json: bool,
        #[arg(long, default_value_t = 20)]
        missions: usize,
        /// Run the executive's day this many times per variant instead of the missions.
        #[arg(long)]
        days: Option<usize>,
        /// With --days: the variants to run, comma-separated (default
        /// plain,executive,no_change,no_peb,fastest_path; also anytime).
        #[arg(long, value_delimiter = ',')]
        variants: Vec<String>,
        /// With --days: threads the days run on (default: the machine's cores; the
        /// report does not depend on it).
        #[arg(long)]
        jobs: Option<usize>,
        /// With --days: what a curious plan costs, wall seconds, before its deadline
        /// cuts it (the demo's, measured).
        #[arg(long, default_value_t = 0.4, allow_negative_numbers = true)]
        plan_wall: f64,
        /// With --days: what a replan seeded with the route left costs, wall seconds
        /// (`roam bench planner --replans`: p99 48 ms).
        #[arg(long, default_value_t = 0.05, allow_negative_numbers = true)]
        replan_wall: f64,
        /// With --days: the clock's rate, mission seconds per wall second (the demo's).
        #[arg(long, default_value_t = 20.0, allow_negative_numbers = true)]
        rate: f64,
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// GA generations per plan.
        #[arg(long, default_value_t = 1000)]
        generations: u32,
        /// W_loc of the PEB-cost variant.
        #[arg(long, default_value_t = 2000.0)]
        w_loc: f64,
        /// With --days: your own site's Nav2 map, with --tasks (as `roam demo --map`).
        #[arg(long, value_name = "MAP.yaml", requires = "tasks")]
        map: Option<PathBuf>,
        /// With --days: your own site's day file, with --map.
        #[arg(long, value_name = "DAY.yaml", requires = "map")]
        tasks: Option<PathBuf>,
    },
    /// A fleet's week in the warehouse: ten robots' shifts per variant, the late windows,
    /// how soon the fleet sees each change and its map now, against the goals.
    ///
    /// The shifts are repeated --days times, each robot driven by the executive's own
    /// window machine, objects landing in and leaving the aisles and the dock; the
    /// variants are tasks only, the operator's patrol, independent curiosity, roam's
    /// shared news and each part of it off.
    Fleet(super::reproduce_fleet::FleetArgs),
    /// Paper 002 §4: ES1-ES3 for plain APF and the fixed, cutoff, linear and sinusoidal
    /// information-seeking weights.
    Apf {
        /// Print {"es1": [...], "es1_no_guard": [...], "es2": [...], "es3": [...],
        /// "claims": [...]} as JSON.
        #[arg(long)]
        json: bool,
        /// ES1 runs per scheme (the paper: 100).
        #[arg(long, default_value_t = roam_experiments::reproduce::apf::DEFAULT_ES1_RUNS)]
        es1_runs: usize,
        /// ES2 runs per scheme and z_is.
        #[arg(long, default_value_t = roam_experiments::reproduce::apf::DEFAULT_ES2_RUNS)]
        es2_runs: usize,
        /// ES3 random missions (the paper: 10).
        #[arg(long, default_value_t = roam_experiments::reproduce::apf::DEFAULT_ES3_MISSIONS)]
        es3_missions: usize,
        /// ES3 runs per mission (the paper: 100).
        #[arg(long, default_value_t = roam_experiments::reproduce::apf::DEFAULT_ES3_RUNS)]
        es3_runs: usize,
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Where the trajectory and chart pictures go.
        #[arg(long, default_value = "roam-reproduce/apf")]
        out: PathBuf,
    },
    /// Paper 004 §5: curious vs recency-only vs Poisson-only mapping on the grid world,
    /// with roam's uniform mix beside them, and the paper's claims judged.
    Mapper {
        /// Print {"strategies": [{"name", "rate_error_auc", "final_map_quality"}], ...,
        /// "claims": [{"claim", "paper", "ours", "verdict"}]}.
        #[arg(long)]
        json: bool,
        /// Runs per strategy (the paper: 5).
        #[arg(long, default_value_t = 5)]
        repetitions: usize,
        /// Steps per run (one second of sim time each).
        #[arg(long, default_value_t = roam_experiments::reproduce::mapper::experiment::DEFAULT_STEPS)]
        steps: u64,
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Where the Fig. 3-like picture goes.
        #[arg(long, default_value = "roam-reproduce/mapper")]
        out: PathBuf,
    },
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
        /// Which first populations to plan with: roam's and paper 000's own (random
        /// walks only, no shortest-path seed) side by side, or one of them.
        #[arg(long, default_value = "both", value_parser = ["both", "roam", "paper"])]
        init: String,
        /// Shorthand for `--init paper`.
        #[arg(long)]
        paper_init: bool,
    },
}

pub(crate) async fn reproduce(args: ReproduceArgs) -> anyhow::Result<()> {
    let quiet = args.quiet;
    match args.command {
        ReproduceCommand::Fleet(args) => super::reproduce_fleet::run(args, quiet).await,
        ReproduceCommand::Mission {
            json,
            days: Some(days),
            variants,
            jobs,
            plan_wall,
            replan_wall,
            rate,
            seed,
            generations,
            w_loc,
            map,
            tasks,
            ..
        } => {
            let site = super::roles::site(map.as_deref(), tasks.as_deref())?;
            for warning in &site.warnings {
                eprintln!("warning: {warning}");
            }
            reproduce_days(
                json,
                days,
                &variants,
                jobs,
                plan_wall,
                replan_wall,
                rate,
                seed,
                generations,
                w_loc,
                site,
                quiet,
            )
            .await
        }
        ReproduceCommand::Mission {
            json,
            missions,
            days: None,
            seed,
            generations,
            w_loc,
            map,
            ..
        } => {
            if map.is_some() {
                bail!("--map and --tasks run the executive's day: give --days N too");
            }
            if missions == 0 || generations == 0 || !(w_loc.is_finite() && w_loc >= 0.0) {
                bail!("--missions and --generations must be at least 1, --w-loc 0 or more");
            }
            let options = roam_experiments::reproduce::mission::missions::MissionExperiment {
                missions,
                seed,
                generations,
                w_loc,
            };
            let result = tokio::task::spawn_blocking(move || {
                let progress = Progress::new("the papers joined", quiet);
                let shown = progress.callback();
                roam_experiments::reproduce::mission::missions::run(&options, &shown)
            })
            .await??;
            let report = roam_experiments::reproduce::mission::runner::MissionReport {
                claims: roam_experiments::reproduce::mission::runner::claims(&result),
                reproduction: result,
            };
            if json {
                println!("{}", serde_json::to_string(&report)?);
            } else {
                print!(
                    "{}",
                    roam_experiments::reproduce::mission::missions::table(&report.reproduction)
                );
                println!("claims, ours judged:");
                print!("{}", roam_experiments::verdict::lines(&report.claims));
            }
            Ok(())
        }
        ReproduceCommand::Apf {
            json,
            es1_runs,
            es2_runs,
            es3_missions,
            es3_runs,
            seed,
            out,
        } => {
            if es1_runs == 0 || es2_runs == 0 || es3_missions == 0 || es3_runs == 0 {
                bail!("--es1-runs, --es2-runs, --es3-missions and --es3-runs must be at least 1");
            }
            let (result, pictures) = tokio::task::spawn_blocking(move || {
                let progress = Progress::new("paper 002", quiet);
                let shown = progress.callback();
                roam_experiments::reproduce::apf::runner::run(
                    &roam_experiments::reproduce::apf::runner::Sizes {
                        es1_runs,
                        es2_runs,
                        es3_missions,
                        es3_runs,
                        seed,
                        out_dir: out,
                    },
                    &shown,
                )
            })
            .await??;
            if json {
                println!("{}", serde_json::to_string(&result)?);
            } else {
                print!("{}", result.text());
                for picture in pictures {
                    println!("picture: {}", picture.display());
                }
            }
            Ok(())
        }
        ReproduceCommand::Mapper {
            json,
            repetitions,
            steps,
            seed,
            out,
        } => {
            if repetitions == 0 || steps == 0 {
                bail!("--repetitions and --steps must be at least 1");
            }
            let options = roam_experiments::reproduce::mapper::experiment::ExperimentOptions {
                repetitions,
                steps,
                seed,
                ..roam_experiments::reproduce::mapper::experiment::ExperimentOptions::default()
            };
            let (result, picture) = tokio::task::spawn_blocking(move || {
                let scenario = roam_experiments::reproduce::mapper::experiment::grid004()?;
                let progress = Progress::new("paper 004", quiet);
                let shown = progress.callback();
                let result = roam_experiments::reproduce::mapper::experiment::run(
                    roam_experiments::reproduce::mapper::experiment::GRID004_NAME,
                    &scenario,
                    &options,
                    &shown,
                )?;
                std::fs::create_dir_all(&out)?;
                let picture = roam_experiments::reproduce::mapper::plot::write_figure(
                    &scenario, &result, &out,
                )?;
                anyhow::Ok((result, picture))
            })
            .await??;
            let judged = roam_experiments::reproduce::mapper::runner::judge(result);
            if json {
                println!("{}", serde_json::to_string(&judged)?);
            } else {
                print!(
                    "{}",
                    roam_experiments::reproduce::mapper::experiment::table(&judged.reproduction)
                );
                println!("claims, ours judged:");
                print!("{}", roam_experiments::verdict::lines(&judged.claims));
                println!("picture: {}", picture.display());
            }
            Ok(())
        }
        ReproduceCommand::Planner {
            json,
            runs,
            total,
            generations_per_t,
            out,
            init,
            paper_init,
        } => {
            use roam_experiments::reproduce::planner::Initialization;
            let initializations = match (paper_init, init.as_str()) {
                (true, _) | (false, "paper") => vec![Initialization::Paper],
                (false, "roam") => vec![Initialization::Roam],
                _ => vec![Initialization::Roam, Initialization::Paper],
            };
            if runs == 0
                || !(total.is_finite() && total > 0.0)
                || !(generations_per_t.is_finite() && generations_per_t >= 1.0)
            {
                bail!("--runs must be at least 1, --total positive and --generations-per-t at least 1");
            }
            let options = roam_experiments::reproduce::planner::ReproduceOptions {
                runs,
                total_s: total,
                generations_per_t,
                out_dir: out,
                initializations,
            };
            let result = tokio::task::spawn_blocking(move || {
                let progress = Progress::new("paper 000", quiet);
                let shown = progress.callback();
                roam_experiments::reproduce::planner::run(&options, &shown)
            })
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

/// `roam reproduce mission --days N`: the days' batch, its table or JSON on stdout and
/// its progress and runtime on stderr (so the JSON repeats bit for bit).
#[allow(clippy::too_many_arguments)]
async fn reproduce_days(
    json: bool,
    days: usize,
    variants: &[String],
    jobs: Option<usize>,
    plan_wall: f64,
    replan_wall: f64,
    rate: f64,
    seed: u64,
    generations: u32,
    w_loc: f64,
    site: roam_mission::site::Site,
    quiet: bool,
) -> anyhow::Result<()> {
    use roam_experiments::reproduce::mission::days::{self, DaysOptions, Variant};
    let mut options = DaysOptions {
        days,
        seed,
        generations,
        w_loc,
        plan_wall_s: plan_wall,
        replan_wall_s: replan_wall,
        rate,
        site,
        ..DaysOptions::default()
    };
    if !variants.is_empty() {
        options.variants = variants
            .iter()
            .map(|name| {
                Variant::parse(name).ok_or_else(|| {
                    let all: Vec<&str> = Variant::ALL.iter().map(|v| v.name()).collect();
                    anyhow::anyhow!("no variant {name:?}; give some of {}", all.join(","))
                })
            })
            .collect::<anyhow::Result<_>>()?;
    }
    if let Some(jobs) = jobs {
        options.jobs = jobs;
    }
    let started = std::time::Instant::now();
    let run = options.clone();
    let progress = std::sync::Arc::new(Progress::new("the executive's", quiet));
    let reporting = progress.clone();
    let report =
        tokio::task::spawn_blocking(move || days::run(&run, &reporting.callback())).await??;
    let wall_s = started.elapsed().as_secs_f64();
    if progress.speaks() {
        eprintln!(
            "{} days x {} variants in {wall_s:.1} s ({:.2} s per day, {} threads)",
            options.days,
            report.variants.len(),
            wall_s / options.days as f64,
            options.jobs
        );
    }
    if json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        print!("{}", days::table::table(&report));
    }
    Ok(())
}
