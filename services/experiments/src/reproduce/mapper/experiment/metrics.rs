//! What a run is measured by (the rate-estimate error, the map quality) and the curves'
//! arithmetic (means over runs, areas by trapezoids).

use roam_mapper::change_map::ChangeMap;
use roam_sim::Sim;

use crate::reproduce::mapper::truth::TrueRates;

/// Mean over the changing cells of |estimated − true rate|.
pub fn rate_error_of(map: &ChangeMap, truth: &TrueRates) -> f64 {
    if truth.changing.is_empty() {
        return 0.0;
    }
    let processes = map.processes();
    let sum: f64 = truth
        .changing
        .iter()
        .map(|&i| {
            let estimate = processes.get(i).map_or(0.0, |p| p.rate());
            (estimate - truth.rates[i]).abs()
        })
        .sum();
    sum / truth.changing.len() as f64
}

/// Share of cells whose mapped value is the true occupancy now.
pub fn map_quality_of(map: &ChangeMap, sim: &Sim) -> f64 {
    let (w, h) = (map.width() as usize, map.height() as usize);
    let world = sim.world();
    let mut right = 0usize;
    for y in 0..h {
        for x in 0..w {
            let truth = if world.is_blocked((x as i64, y as i64)) {
                100
            } else {
                0
            };
            right += usize::from(map.obstacles()[y * w + x] == truth);
        }
    }
    right as f64 / (w * h).max(1) as f64
}

pub(super) fn mean_curve<'a>(curves: impl Iterator<Item = &'a [f64]>) -> Vec<f64> {
    let mut sum: Vec<f64> = Vec::new();
    let mut n = 0usize;
    for c in curves {
        if sum.is_empty() {
            sum = vec![0.0; c.len()];
        }
        for (s, v) in sum.iter_mut().zip(c) {
            *s += v;
        }
        n += 1;
    }
    sum.iter().map(|s| s / n.max(1) as f64).collect()
}

/// ∫ y dt by trapezoids.
pub fn trapezoid(t: &[f64], y: &[f64]) -> f64 {
    t.windows(2)
        .zip(y.windows(2))
        .map(|(t, y)| (t[1] - t[0]) * (y[0] + y[1]) / 2.0)
        .sum()
}
