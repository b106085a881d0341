//! `roam bench mapper`: can the change map keep up with a large map observed often?
//!
//! A 1000 × 1000 map (1 M cells) and a sensor that sees a disk of radius 50 cells (a
//! 101 × 101 window, about 7 850 cells seen) ten times a second, sweeping the whole map
//! in a lawnmower pattern 5 cells per update. The world has 5 % static obstacles and
//! churns: before each update `churn` of the window's cells flip (things moving), so
//! the number of cells with a rate above zero grows through the run toward the worst
//! case for p. Each update is timed twice: `observe` alone, and `features` (p and r,
//! what the learner needs after every update). At the end the cached features are
//! checked against the plain sum over every cell ([`ChangeMap::features_exact`]); a
//! mismatch is an error, not a number. The full probability layer (what goal sampling
//! needs once per episode) and the exact sum are timed once.

use std::time::Instant;

use rand::Rng;
use roam_proto::map::{GridMeta, Origin};
use serde::{Deserialize, Serialize};

use roam_mapper::change_map::{ChangeMap, MapParams, ObservationWindow};
use roam_mapper::error::MapperError;
use roam_world::seed;

/// The most updates one bench runs (limit `max_bench_updates`).
pub const MAX_BENCH_UPDATES: u64 = 1_000_000;

/// The bench's options.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BenchOptions {
    /// Map side, cells (square map).
    pub map_cells: u32,
    /// Sensor radius, cells.
    pub radius_cells: u32,
    /// Observation updates to run.
    pub updates: u64,
    /// The sensor rate the map must keep up with, Hz (sets the observation times).
    pub rate_hz: f64,
    /// Share of the window's cells that flip before each update.
    pub churn: f64,
    pub seed: u64,
}

impl Default for BenchOptions {
    fn default() -> Self {
        BenchOptions {
            map_cells: 1000,
            radius_cells: 50,
            updates: 4000,
            rate_hz: 10.0,
            churn: 0.01,
            seed: 0,
        }
    }
}

/// What the bench measured.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BenchReport {
    pub options: BenchOptions,
    pub map_cells: u64,
    /// Cells seen per update (the disk), and the window's size.
    pub seen_per_update: u64,
    pub window_cells: u64,
    pub updates: u64,
    /// Observation updates per second of wall time, `observe` alone.
    pub observe_per_s: f64,
    /// Observation updates per second with the features computed after each.
    pub updates_with_features_per_s: f64,
    /// How many times faster than the sensor rate the map keeps up (≥ 1 keeps up).
    pub realtime_factor: f64,
    pub observe_mean_us: f64,
    pub observe_max_us: f64,
    pub features_mean_us: f64,
    pub features_p99_us: f64,
    pub features_max_us: f64,
    /// Cells with a rate above zero at the end.
    pub active_cells_end: u64,
    /// One full probability layer (1 M `exp`s), milliseconds.
    pub probability_layer_ms: f64,
    /// The plain feature sum over every cell, milliseconds (what the cache avoids).
    pub exact_features_ms: f64,
    /// |cached p − exact p| / max(1, exact p) at the end.
    pub p_relative_error: f64,
    pub p_end: f64,
    pub r_end: f64,
}

/// Runs the bench. Errors when the options are out of range or the cached features do
/// not match the exact ones.
pub fn bench(options: &BenchOptions) -> Result<BenchReport, MapperError> {
    let bad = |field: &'static str, reason: String| MapperError::Param { field, reason };
    if options.updates == 0 || options.updates > MAX_BENCH_UPDATES {
        return Err(bad(
            "updates",
            format!("must be 1 to {MAX_BENCH_UPDATES} (limit max_bench_updates)"),
        ));
    }
    if !(options.rate_hz.is_finite() && options.rate_hz > 0.0) {
        return Err(bad("rate_hz", "must be a positive rate".into()));
    }
    if !(0.0..=1.0).contains(&options.churn) {
        return Err(bad("churn", "must be a share in [0, 1]".into()));
    }
    let n = options.map_cells;
    let r = options.radius_cells.min(n.saturating_sub(1) / 2);
    let side = 2 * r + 1;
    let period = 1.0 / options.rate_hz;
    let meta = GridMeta {
        width: n,
        height: n,
        resolution: 0.05,
        origin: Origin::default(),
    };
    let mut map = ChangeMap::new(
        meta,
        MapParams {
            observation_period_s: period * 1.5,
            ..MapParams::default()
        },
    )?;
    let mut rng = seed::stream(options.seed, "bench");
    let mut world: Vec<bool> = (0..u64::from(n) * u64::from(n))
        .map(|_| rng.random_bool(0.05))
        .collect();
    let disk: Vec<bool> = (0..side * side)
        .map(|k| {
            let (dx, dy) = (
                i64::from(k % side) - i64::from(r),
                i64::from(k / side) - i64::from(r),
            );
            dx * dx + dy * dy <= i64::from(r) * i64::from(r)
        })
        .collect();
    let seen_per_update = disk.iter().filter(|&&d| d).count() as u64;
    let flips = (options.churn * seen_per_update as f64).round() as u64;
    let mut cells = vec![-1i8; (side * side) as usize];
    let (mut observe_total, mut observe_max) = (0.0f64, 0.0f64);
    let mut feature_times = Vec::with_capacity(options.updates as usize);
    let lane = 2 * r.max(1);
    let sweep = (n - side).max(1);
    let mut last = (0.0, 0.0);
    for k in 0..options.updates {
        // Lawnmower: 5 cells per update along x, next lane at the end of a row.
        let along = (k * 5) % (2 * u64::from(sweep));
        let row = (k * 5) / (2 * u64::from(sweep));
        let x0 = if along < u64::from(sweep) {
            along
        } else {
            2 * u64::from(sweep) - along
        } as u32;
        let y0 = ((row * u64::from(lane)) % u64::from((n - side).max(1))) as u32;
        for _ in 0..flips {
            let (dx, dy) = (rng.random_range(0..side), rng.random_range(0..side));
            let i = (y0 + dy) as usize * n as usize + (x0 + dx) as usize;
            if let Some(w) = world.get_mut(i) {
                *w = !*w;
            }
        }
        for (k, v) in cells.iter_mut().enumerate() {
            let (dx, dy) = (k as u32 % side, k as u32 / side);
            *v = if disk[k] {
                let i = (y0 + dy) as usize * n as usize + (x0 + dx) as usize;
                if world.get(i).copied().unwrap_or(false) {
                    100
                } else {
                    0
                }
            } else {
                -1
            };
        }
        let t = k as f64 * period;
        let window = ObservationWindow {
            x0,
            y0,
            width: side,
            height: side,
            cells: &cells,
        };
        let start = Instant::now();
        map.observe(&window, t)?;
        let observed = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let f = map.features(t);
        let featured = start.elapsed().as_secs_f64();
        observe_total += observed;
        observe_max = observe_max.max(observed);
        feature_times.push(featured);
        last = (f.p, f.r);
    }
    let t_end = (options.updates - 1) as f64 * period;
    let start = Instant::now();
    let exact = map.features_exact(t_end);
    let exact_features_ms = start.elapsed().as_secs_f64() * 1e3;
    let start = Instant::now();
    let layer = map.probability_layer(t_end);
    let probability_layer_ms = start.elapsed().as_secs_f64() * 1e3;
    let p_relative_error = (last.0 - exact.p).abs() / exact.p.max(1.0);
    let layer_sum: f64 = layer.cells.iter().sum();
    if p_relative_error > 1e-9
        || (last.1 - exact.r).abs() > 1e-9
        || (layer_sum - exact.p).abs() > 1e-6 * exact.p.max(1.0)
    {
        return Err(bad(
            "features",
            format!(
                "the cached features (p {}, r {}) differ from the exact ones (p {}, r {}): a bug",
                last.0, last.1, exact.p, exact.r
            ),
        ));
    }
    let features_total: f64 = feature_times.iter().sum();
    let mut sorted = feature_times.clone();
    sorted.sort_by(f64::total_cmp);
    let p99 = sorted[((sorted.len() as f64 * 0.99) as usize).min(sorted.len() - 1)];
    let updates = options.updates as f64;
    let with_features = updates / (observe_total + features_total).max(1e-12);
    Ok(BenchReport {
        options: *options,
        map_cells: u64::from(n) * u64::from(n),
        seen_per_update,
        window_cells: u64::from(side) * u64::from(side),
        updates: options.updates,
        observe_per_s: updates / observe_total.max(1e-12),
        updates_with_features_per_s: with_features,
        realtime_factor: with_features / options.rate_hz,
        observe_mean_us: observe_total / updates * 1e6,
        observe_max_us: observe_max * 1e6,
        features_mean_us: features_total / updates * 1e6,
        features_p99_us: p99 * 1e6,
        features_max_us: sorted.last().copied().unwrap_or(0.0) * 1e6,
        active_cells_end: map.stats().active_cells,
        probability_layer_ms,
        exact_features_ms,
        p_relative_error,
        p_end: exact.p,
        r_end: exact.r,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_small_bench_runs_and_checks_itself() {
        let report = bench(&BenchOptions {
            map_cells: 200,
            radius_cells: 20,
            updates: 300,
            churn: 0.05,
            ..BenchOptions::default()
        })
        .expect("bench");
        assert_eq!(report.window_cells, 41 * 41);
        assert!(report.active_cells_end > 100, "{}", report.active_cells_end);
        assert!(report.p_relative_error < 1e-9);
        assert!(report.updates_with_features_per_s > 0.0);
        assert!(bench(&BenchOptions {
            churn: 2.0,
            ..BenchOptions::default()
        })
        .is_err());
    }
}
