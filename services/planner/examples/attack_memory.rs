//! The memory attack of issue 20, in process: one plan on a free 1024 × 1024 grid at
//! 5 cm with Model I, by default population 2000, 100,000 generations, the longest
//! budget (86,400 s) and a wall deadline, with the default limits; then the process's
//! peak resident memory (VmHWM of `/proc/self/status`, Linux). A thread samples VmRSS
//! every 100 ms so the peak's time is seen too.
//!
//! ```sh
//! cargo run --release -p roam-planner --example attack_memory -- \
//!     [deadline_s] [population] [max_generations] [t_exec_s]
//! # the largest plan the default limits admit on this grid (2000 × 2000 cells):
//! cargo run --release -p roam-planner --example attack_memory -- 30 2000 1000 199.9
//! ```

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use roam_planner::params::GaParams;
use roam_planner::plan::{plan, PlanSpec};
use roam_planner::world::World;
use roam_proto::map::{GridMeta, Origin};
use roam_proto::planner::{PlannerModel, ShortestPathUse};
use roam_world::grid::{occupancy, Grid};

fn status_kib(field: &str) -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with(field))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

fn mib(kib: Option<u64>) -> String {
    kib.map_or("?".into(), |k| format!("{:.0} MiB", k as f64 / 1024.0))
}

fn main() {
    let mut args = std::env::args().skip(1);
    let deadline_s: f64 = args.next().and_then(|a| a.parse().ok()).unwrap_or(60.0);
    let population: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(2000);
    let max_generations: u32 = args.next().and_then(|a| a.parse().ok()).unwrap_or(100_000);
    let t_exec_s: f64 = args.next().and_then(|a| a.parse().ok()).unwrap_or(86_400.0);
    let meta = GridMeta {
        width: 1024,
        height: 1024,
        resolution: 0.05,
        origin: Origin::default(),
    };
    let world = match World::new(
        &Grid::filled(meta, occupancy::FREE),
        &Grid::filled(meta, 50u8),
        0.25,
    ) {
        Ok(world) => world,
        Err(e) => return eprintln!("cannot build the world: {e}"),
    };
    let before = status_kib("VmHWM:");
    let spec = PlanSpec {
        start: [1.0, 1.0],
        goal: [50.0, 50.0],
        t_exec_s,
        deadline_s,
        model: PlannerModel::Model1,
        params: GaParams {
            population,
            max_generations,
            ..GaParams::default()
        },
        seed: 1,
        threads: roam_planner::ga::default_threads(),
        limits: roam_planner::limits::PlanLimits::default(),
        shortest: ShortestPathUse::Omit,
        seed_route: Vec::new(),
    };
    let done = Arc::new(AtomicBool::new(false));
    let sampler = {
        let done = done.clone();
        std::thread::spawn(move || {
            let started = Instant::now();
            let mut peak = (0u64, 0.0f64);
            while !done.load(Ordering::Relaxed) {
                if let Some(rss) = status_kib("VmRSS:") {
                    if rss > peak.0 {
                        peak = (rss, started.elapsed().as_secs_f64());
                    }
                }
                std::thread::sleep(Duration::from_millis(100));
            }
            peak
        })
    };
    let started = Instant::now();
    let outcome = plan(&world, &spec, &AtomicBool::new(false), |_, _| {});
    let elapsed = started.elapsed().as_secs_f64();
    done.store(true, Ordering::Relaxed);
    let (peak_rss, at) = sampler.join().unwrap_or((0, 0.0));
    match &outcome {
        Ok(o) => println!(
            "planned: {} generations, {} cells, stop {:?}, in {elapsed:.1} s",
            o.generations,
            o.path.len(),
            o.stop_reason
        ),
        Err(e) => println!("refused in {elapsed:.3} s: {e}"),
    }
    println!(
        "VmHWM before the plan {}, after {}; sampled peak VmRSS {} at {at:.1} s; VmRSS after {}",
        mib(before),
        mib(status_kib("VmHWM:")),
        mib(Some(peak_rss)),
        mib(status_kib("VmRSS:"))
    );
}
