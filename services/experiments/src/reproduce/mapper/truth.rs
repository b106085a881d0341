//! The true change rates of a scripted world, for scoring the estimates (paper 004 §5's
//! "rate of change of a grid cell").
//!
//! The blocks follow their scripts ([`roam_sim::world::Block`]): a block holds each
//! position of its path for `period_steps` steps and cycles. Over the least common
//! multiple L of the blocks' cycles (period × positions) the whole world repeats, so a
//! cell's true rate is the number of its free→blocked transitions between consecutive
//! steps over one such cycle (counted cyclically) divided by L · step_s. That is the
//! rate of one of the cell's two processes, the quantity the estimate 1/T^c of Eq. 1
//! converges to (the two processes of a cell alternate, so they have the same rate).
//! On grid004 L = lcm(7·6, 2·20) = 840 steps; a cell the top block covers has one block
//! event per 42 s; a cell in the middle of the bottom block's shuttle two per 40 s.
//!
//! Random walkers have no script, so a world with walkers has no true rates here.

use roam_sim::world::World;
use roam_world::scenario::{is_blocked, Scenario};

/// The longest world cycle scored (limit `max_cycle_steps`).
pub const MAX_CYCLE_STEPS: u64 = 1_000_000;

/// Why the true rates cannot be had.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TruthError {
    #[error("the scenario has random walkers: their change rates are not scripted")]
    Walkers,
    #[error(
        "the blocks' cycles repeat together only every {steps} steps; at most \
         {MAX_CYCLE_STEPS} (limit max_cycle_steps): use periods and path lengths with \
         a smaller common multiple"
    )]
    CycleTooLong { steps: u64 },
    #[error("the world cannot be built: {0}")]
    World(String),
    #[error("step_s {0} must be a positive number of seconds")]
    BadStep(f64),
}

/// Every cell's true rate.
#[derive(Debug, Clone, PartialEq)]
pub struct TrueRates {
    /// Events per second of one process, per cell, row-major.
    pub rates: Vec<f64>,
    /// The indices of the cells whose rate is above zero, ascending.
    pub changing: Vec<usize>,
    /// The world's cycle L, steps.
    pub cycle_steps: u64,
}

impl TrueRates {
    /// The mean true rate over the changing cells (0 if none).
    pub fn mean_changing(&self) -> f64 {
        if self.changing.is_empty() {
            return 0.0;
        }
        self.changing.iter().map(|&i| self.rates[i]).sum::<f64>() / self.changing.len() as f64
    }
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// The true rates of `scenario`'s cells with `step_s` seconds per step.
pub fn true_rates(scenario: &Scenario, step_s: f64) -> Result<TrueRates, TruthError> {
    if !(step_s.is_finite() && step_s > 0.0) {
        return Err(TruthError::BadStep(step_s));
    }
    if !scenario.file.walkers.is_empty() {
        return Err(TruthError::Walkers);
    }
    let world = World::new(scenario, 0).map_err(|e| TruthError::World(e.to_string()))?;
    let meta = *world.meta();
    let mut cycle: u64 = 1;
    for b in world.blocks() {
        let own = u64::from(b.period_steps.max(1)) * b.path.len().max(1) as u64;
        cycle = (cycle / gcd(cycle, own)).saturating_mul(own);
        if cycle > MAX_CYCLE_STEPS {
            return Err(TruthError::CycleTooLong { steps: cycle });
        }
    }
    let n = meta.width as usize * meta.height as usize;
    let index = |(x, y): (i64, i64)| {
        (x >= 0 && y >= 0 && x < i64::from(meta.width) && y < i64::from(meta.height))
            .then(|| y as usize * meta.width as usize + x as usize)
    };
    // Only cells some block ever covers can change; static walls never do.
    let mut candidate = vec![false; n];
    for b in world.blocks() {
        for &centre in &b.path {
            for c in b.footprint.cells(centre) {
                if let Some(i) = index(c) {
                    candidate[i] = scenario
                        .occupancy
                        .cells
                        .get(i)
                        .is_some_and(|&v| !is_blocked(v));
                }
            }
        }
    }
    let cells: Vec<usize> = (0..n).filter(|&i| candidate[i]).collect();
    let slot: std::collections::HashMap<usize, usize> =
        cells.iter().enumerate().map(|(k, &i)| (i, k)).collect();
    let occupied_at = |step: u64, out: &mut Vec<bool>| {
        out.iter_mut().for_each(|o| *o = false);
        for b in world.blocks() {
            for c in b.footprint.cells(b.centre_at(step)) {
                if let Some(k) = index(c).and_then(|i| slot.get(&i)) {
                    out[*k] = true;
                }
            }
        }
    };
    let mut previous = vec![false; cells.len()];
    let mut current = vec![false; cells.len()];
    occupied_at(cycle - 1, &mut previous);
    let mut blocks = vec![0u64; cells.len()];
    for step in 0..cycle {
        occupied_at(step, &mut current);
        for k in 0..cells.len() {
            if current[k] && !previous[k] {
                blocks[k] += 1;
            }
        }
        std::mem::swap(&mut previous, &mut current);
    }
    let mut rates = vec![0.0; n];
    let duration = cycle as f64 * step_s;
    for (k, &i) in cells.iter().enumerate() {
        rates[i] = blocks[k] as f64 / duration;
    }
    let changing = (0..n).filter(|&i| rates[i] > 0.0).collect();
    Ok(TrueRates {
        rates,
        changing,
        cycle_steps: cycle,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid004_rates_by_hand() {
        let scenario = crate::reproduce::mapper::experiment::grid004().expect("grid004");
        let truth = true_rates(&scenario, 1.0).expect("rates");
        assert_eq!(truth.cycle_steps, 840); // lcm(7 · 6, 2 · 20)
                                            // 24 cells under the top block's six places, 24 along the bottom wall.
        assert_eq!(truth.changing.len(), 48);
        let rate = |x: usize, y: usize| truth.rates[y * 25 + x];
        // The top block covers each of its cells for one stretch of 7 steps per 42.
        for (x, y) in [(4, 16), (5, 17), (10, 20), (17, 21)] {
            assert!((rate(x, y) - 1.0 / 42.0).abs() < 1e-12, "({x}, {y})");
        }
        // The bottom block (2 wide, centre from x = 7 to 17 and back, 2 steps each):
        // the two end columns on each side are covered once per 40-step cycle (at the
        // turn), the columns between twice (going and coming back).
        for x in [7, 8, 17, 18] {
            assert!((rate(x, 1) - 1.0 / 40.0).abs() < 1e-12, "x {x}");
        }
        for x in 9..=16 {
            assert!((rate(x, 2) - 2.0 / 40.0).abs() < 1e-12, "x {x}");
        }
        assert_eq!(rate(12, 12), 0.0);
        assert_eq!(rate(0, 0), 0.0, "a wall never changes");
        // The same world at 0.5 s per step changes twice as fast.
        let fast = true_rates(&scenario, 0.5).expect("rates");
        assert!((fast.rates[16 * 25 + 4] - 2.0 / 42.0).abs() < 1e-12);
    }
}
