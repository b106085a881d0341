//! `roam bench`: each benchmark measures one thing on this machine and prints JSON.

use anyhow::bail;
use clap::{Args, Subcommand};
use roam_bench as benches;

use super::json::print_json;
use super::progress::Progress;

/// `roam bench [--quiet] <benchmark>`.
#[derive(Debug, Args)]
pub(crate) struct BenchArgs {
    /// Show no progress on stderr (the benchmarks that run longer than a few seconds,
    /// `planner`, `sim` and `fleet`, draw it when stderr is a terminal).
    #[arg(long, global = true)]
    quiet: bool,
    #[command(subcommand)]
    command: BenchCommand,
}

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
    /// Many concurrent plan requests to two planners: answered or refused `busy`, none hung.
    Load {
        #[arg(long)]
        json: bool,
        /// Concurrent plan requests.
        #[arg(long, default_value_t = 100)]
        requests: usize,
        /// Each request's deadline, seconds.
        #[arg(long, default_value_t = 1.0)]
        deadline_s: f64,
    },
    /// Robots in closed loop through Zenoh (sim → localization → controller → sim) at a
    /// fixed rate, the router in its own process: commands on time, the loop's and the
    /// router's CPU and memory per robot, a robot joining, a router restart
    ///
    /// The last of --robots joins halfway through --seconds; after them the router is
    /// killed (SIGKILL) and started again 1 s later, and the run goes on until every
    /// robot is commanded again (at most 30 s) and 2 s more.
    Fleet {
        #[arg(long)]
        json: bool,
        #[arg(long, default_value_t = 100)]
        robots: usize,
        /// Steps per second.
        #[arg(long, default_value_t = 10.0)]
        rate_hz: f64,
        /// How long to run, seconds.
        #[arg(long, default_value_t = 20.0)]
        seconds: f64,
    },
    /// The built-in day (or with --fleet the warehouse shift) through faults: every role
    /// a process behind one router, each
    /// killed (SIGKILL) and started again, the planners' and the controller's links cut,
    /// a planner frozen, on a seeded schedule; per fault the time to recover, per window
    /// whether it was late by more than its faults lasted, acked map updates lost,
    /// derived layers out of step, robots held at the end.
    Chaos {
        #[arg(long)]
        json: bool,
        /// Seeds the faults' order, times and restart delays.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Sim seconds per wall second (at most 10).
        #[arg(long, default_value_t = 2.0)]
        rate: f64,
        /// How long each link stays cut, wall seconds (Zenoh's lease is 10 s).
        #[arg(long, default_value_t = 12.0)]
        partition_s: f64,
        /// How long the frozen planner stays stopped, wall seconds.
        #[arg(long, default_value_t = 4.0)]
        freeze_s: f64,
        /// The warehouse fleet's shift instead of the built-in day: each robot its own
        /// executive, the planners on the fleet's news.
        #[arg(long)]
        fleet: bool,
        /// With --fleet: the shift's first robots (1 to 10).
        #[arg(long, default_value_t = 10)]
        robots: usize,
        /// With --fleet: the tasks that start within this many sim seconds of the shift.
        #[arg(long, default_value_t = 900.0)]
        shift_s: f64,
    },
    /// Change-map observation updates per second on a 1000 x 1000 map (paper 004 §3).
    Mapper {
        #[arg(long)]
        json: bool,
        /// Map side in cells.
        #[arg(long, default_value_t = 1000)]
        side: u32,
        /// Observation updates to run.
        #[arg(long, default_value_t = 4000)]
        updates: u64,
    },
    /// The wire's own latency on loopback: p50/p99 of a put to a subscriber and of a get
    /// to its reply, peer to peer and through a router, over TCP and TLS.
    Wire {
        #[arg(long)]
        json: bool,
        /// Samples per topology, operation and payload size (at most 100000).
        #[arg(long, default_value_t = roam_bench::wire::DEFAULT_SAMPLES)]
        samples: usize,
        /// Payload sizes, bytes (at most 8 sizes, each 8..=4194304).
        #[arg(long, value_delimiter = ',', default_values_t = roam_bench::wire::DEFAULT_PAYLOADS)]
        payloads: Vec<usize>,
    },
    /// The GA per curiosity model (2000 generations, population 200) and the service
    /// overhead; with --scaling or --peer, finer maps or the greedy planner instead;
    /// with --replans the executive's replans over `--runs` days of the day world,
    /// seeded and from scratch, timed.
    Planner {
        #[arg(long)]
        json: bool,
        /// Plans per model.
        #[arg(long, default_value_t = 5)]
        runs: usize,
        /// Plan with paper 000's own initialization (random walks that stop at the goal,
        /// no via-point seeds), to compare with roam's default.
        #[arg(long)]
        paper_init: bool,
        /// Instead: the same world at 0.2, 0.1, 0.05 and 0.03 m and a 1.7-million-cell
        /// warehouse, planned at 0.2 m and at the map's resolution, and the memory of a
        /// planner holding the warehouse.
        #[arg(long, conflicts_with = "peer")]
        scaling: bool,
        /// Instead: model greedy against Model I at equal wall time on several worlds.
        #[arg(long)]
        peer: bool,
        /// Instead: the greedy planner's and Model I's plans at the default deadline
        /// against the exact optimum (distinct information) on small seeded instances.
        #[arg(long, conflicts_with_all = ["scaling", "peer"])]
        optimality: bool,
        /// Seeded instances for --optimality (each at three budgets).
        #[arg(long, default_value_t = 10)]
        instances: u64,
        /// Instead: the anytime planner's plan with each checkpoint as its deadline, on
        /// four trips, against the best any planner finds in 10x the last checkpoint
        /// (--runs seeds each).
        #[arg(long, conflicts_with_all = ["scaling", "peer", "optimality"])]
        anytime: bool,
        /// The deadlines for --anytime, milliseconds, increasing (at most 16, each at
        /// most 60000).
        #[arg(long, value_delimiter = ',', default_values_t = roam_bench::anytime::DEFAULT_CHECKPOINTS_MS)]
        checkpoints: Vec<f64>,
        /// Instead: the executive's replans through --runs days of the day world (at
        /// most 100), each answered seeded with the route left (as the executive asks)
        /// and from scratch, timed: p50/p99 latency against the 50 ms goal.
        #[arg(long, conflicts_with_all = ["scaling", "peer", "optimality", "anytime"])]
        replans: bool,
    },
}

pub(crate) async fn bench(args: BenchArgs) -> anyhow::Result<()> {
    let quiet = args.quiet;
    match args.command {
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
            let result = benches::map::map(side, iterations, &dir).await;
            let _ = std::fs::remove_dir_all(&dir);
            let result = result?;
            print_json(&result, json)
        }
        BenchCommand::Localization { json, estimates } => {
            if estimates == 0 {
                bail!("--estimates must be at least 1");
            }
            let result = tokio::task::spawn_blocking(move || {
                roam_bench::localization::localization(estimates)
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
            check_robots_run(robots, rate_hz, seconds)?;
            let progress = Progress::new("bench sim", quiet);
            let shown = progress.callback();
            let result = roam_bench::sim::sim(robots, rate_hz, seconds, &shown).await?;
            print_json(&result, json)
        }
        BenchCommand::Load {
            json,
            requests,
            deadline_s,
        } => {
            if requests == 0 || requests > roam_bench::load::MAX_REQUESTS {
                bail!("--requests must be 1..={}", roam_bench::load::MAX_REQUESTS);
            }
            if !(deadline_s.is_finite() && deadline_s > 0.0 && deadline_s <= 600.0) {
                bail!("--deadline-s must be in (0, 600] seconds");
            }
            let result = roam_bench::load::load(requests, deadline_s).await?;
            print_json(&result, json)
        }
        BenchCommand::Fleet {
            json,
            robots,
            rate_hz,
            seconds,
        } => {
            check_robots_run(robots, rate_hz, seconds)?;
            let progress = Progress::new("bench fleet", quiet);
            let shown = progress.callback();
            // The router runs as this binary's `router` role, in its own process.
            let program = std::env::current_exe()?;
            let result =
                roam_bench::fleet::fleet(robots, rate_hz, seconds, &program, &shown).await?;
            print_json(&result, json)
        }
        BenchCommand::Chaos {
            json,
            seed,
            rate,
            partition_s,
            freeze_s,
            fleet,
            robots,
            shift_s,
        } => {
            let progress = Progress::new("bench chaos", quiet);
            let shown = progress.callback();
            // Every role runs as this binary, in a process of its own.
            let options = roam_bench::chaos::ChaosOptions {
                seed,
                rate,
                partition_s,
                freeze_s,
                program: std::env::current_exe()?,
                site: if fleet {
                    roam_bench::chaos::ChaosSite::Fleet { robots, shift_s }
                } else {
                    roam_bench::chaos::ChaosSite::Day
                },
            };
            let result = roam_bench::chaos::chaos(&options, &shown).await?;
            print_json(&result, json)
        }
        BenchCommand::Mapper {
            json,
            side,
            updates,
        } => {
            if updates == 0 || !(128..=2048).contains(&side) {
                bail!("--updates must be at least 1 and --side 128..=2048 cells");
            }
            let options = roam_bench::mapper::BenchOptions {
                map_cells: side,
                updates,
                ..roam_bench::mapper::BenchOptions::default()
            };
            let result =
                tokio::task::spawn_blocking(move || roam_bench::mapper::bench(&options)).await??;
            print_json(&result, json)
        }
        BenchCommand::Wire {
            json,
            samples,
            payloads,
        } => {
            roam_bench::wire::check(samples, &payloads)?;
            let result = roam_bench::wire::wire(samples, &payloads).await?;
            print_json(&result, json)
        }
        BenchCommand::Planner {
            json,
            runs,
            paper_init,
            scaling,
            peer,
            optimality,
            instances,
            anytime,
            checkpoints,
            replans,
        } => {
            if runs == 0 {
                bail!("--runs must be at least 1");
            }
            if replans {
                let result = tokio::task::spawn_blocking(move || {
                    let progress = Progress::new("bench planner --replans", quiet);
                    let shown = progress.callback();
                    roam_bench::replans::replans(runs, &shown)
                })
                .await??;
                return print_json(&result, json);
            }
            if anytime {
                if let Err(e) = roam_bench::anytime::check_checkpoints(&checkpoints) {
                    bail!("--checkpoints: {e}");
                }
                let result = tokio::task::spawn_blocking(move || {
                    let progress = Progress::new("bench planner --anytime", quiet);
                    let shown = progress.callback();
                    roam_bench::anytime::anytime(&checkpoints, runs, &shown)
                })
                .await??;
                return print_json(&result, json);
            }
            if optimality {
                if instances == 0 {
                    bail!("--instances must be at least 1");
                }
                let result = tokio::task::spawn_blocking(move || {
                    let progress = Progress::new("bench planner --optimality", quiet);
                    let shown = progress.callback();
                    roam_bench::optimality::optimality(instances, &shown)
                })
                .await??;
                return print_json(&result, json);
            }
            if scaling {
                let result = tokio::task::spawn_blocking(move || {
                    let progress = Progress::new("bench planner --scaling", quiet);
                    let shown = progress.callback();
                    roam_bench::scaling::scaling(runs, &shown)
                })
                .await??;
                return print_json(&result, json);
            }
            if peer {
                let result = tokio::task::spawn_blocking(move || {
                    let progress = Progress::new("bench planner --peer", quiet);
                    let shown = progress.callback();
                    roam_bench::peer::peer(runs, &shown)
                })
                .await??;
                return print_json(&result, json);
            }
            let progress = Progress::new("bench planner", quiet);
            let shown = progress.callback();
            let result = roam_bench::planner::planner(runs, paper_init, &shown).await?;
            print_json(&result, json)
        }
    }
}

/// The arguments of the benchmarks that run robots in the sim (`sim`, `fleet`): at most
/// the sim's robot limit, a positive rate and duration.
fn check_robots_run(robots: usize, rate_hz: f64, seconds: f64) -> anyhow::Result<()> {
    let most = roam_sim::sim::MAX_ROBOTS;
    if robots == 0 || robots > most {
        bail!("--robots must be 1..={most} (the sim's robot limit), not {robots}");
    }
    let positive = |x: f64| x.is_finite() && x > 0.0;
    if !positive(rate_hz) || !positive(seconds) {
        bail!("--rate-hz and --seconds must be positive, not {rate_hz} and {seconds}");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::check_robots_run;

    #[test]
    fn a_robots_run_outside_its_limits_is_refused_naming_them() {
        assert!(check_robots_run(100, 10.0, 20.0).is_ok());
        let limit = roam_sim::sim::MAX_ROBOTS;
        let too_many = check_robots_run(limit + 1, 10.0, 20.0).expect_err("too many");
        assert!(
            too_many.to_string().contains(&format!("1..={limit}")),
            "{too_many}"
        );
        assert!(check_robots_run(0, 10.0, 20.0).is_err());
        for (rate_hz, seconds) in [
            (0.0, 1.0),
            (f64::NAN, 1.0),
            (1.0, -1.0),
            (1.0, f64::INFINITY),
        ] {
            let e = check_robots_run(1, rate_hz, seconds).expect_err("refused");
            assert!(e.to_string().contains("must be positive"), "{e}");
        }
    }
}
