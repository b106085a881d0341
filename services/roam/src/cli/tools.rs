//! `roam bench` and `roam reproduce`: benchmarks and the papers' experiments.

use std::path::PathBuf;

use anyhow::bail;
use clap::Subcommand;
use roam::bench;

#[derive(Debug, Subcommand)]
pub(crate) enum BenchCommand {
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
    /// WLS estimates per second with 7 anchors and a 500 x 500 PEB field.
    Localization {
        #[arg(long)]
        json: bool,
        #[arg(long, default_value_t = 200_000)]
        estimates: usize,
    },
    /// Many robots at a fixed sim rate publishing their sensors over Zenoh.
    Sim {
        #[arg(long)]
        json: bool,
        #[arg(long, default_value_t = 100)]
        robots: usize,
        /// Steps per second.
        #[arg(long, default_value_t = 10.0)]
        rate_hz: f64,
        /// How long to run, seconds.
        #[arg(long, default_value_t = 10.0)]
        seconds: f64,
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

#[derive(Debug, Subcommand)]
pub(crate) enum ReproduceCommand {
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

pub(crate) async fn bench(command: BenchCommand) -> anyhow::Result<()> {
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
        BenchCommand::Localization { json, estimates } => {
            if estimates == 0 {
                bail!("--estimates must be at least 1");
            }
            let result = tokio::task::spawn_blocking(move || {
                roam::bench_localization::localization(estimates)
            })
            .await??;
            print_json(&result, json)
        }
        BenchCommand::Sim {
            json,
            robots,
            rate_hz,
            seconds,
        } => {
            if robots == 0
                || robots > roam_sim::sim::MAX_ROBOTS
                || !(rate_hz.is_finite() && rate_hz > 0.0)
                || !(seconds.is_finite() && seconds > 0.0)
            {
                bail!("--robots must be 1..=1000, --rate-hz and --seconds positive");
            }
            let result = roam::bench_sim::sim(robots, rate_hz, seconds).await?;
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

pub(crate) async fn reproduce(command: ReproduceCommand) -> anyhow::Result<()> {
    match command {
        ReproduceCommand::Planner {
            json,
            runs,
            total,
            generations_per_t,
            out,
        } => {
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

fn print_json<T: serde::Serialize>(value: &T, compact: bool) -> anyhow::Result<()> {
    if compact {
        println!("{}", serde_json::to_string(value)?);
    } else {
        println!("{}", serde_json::to_string_pretty(value)?);
    }
    Ok(())
}
