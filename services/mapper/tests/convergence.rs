//! The estimated rates converge to the true ones (paper 004 §3, Eq. 1) as the
//! observation time grows.
//!
//! A row of cells, each an alternating free/blocked process with its own mean sojourn
//! times a (free) and b (blocked), in steps of one second: every second the cell leaves
//! its state with probability 1/a (or 1/b), so each sojourn is at least one step and
//! geometric (the discrete-time Poisson process). One process's true rate is then one
//! free→blocked event per cycle, 1/(a + b) per second. The cells are observed every
//! second, the sensor period, so no change is ever missed. The mean relative error
//! over the cells must fall from a short horizon to a long one and be small at the long
//! one: with at least 250 cycles per cell, each estimate is within about 6 %.

use proptest::prelude::*;
use rand::Rng;
use roam_mapper::change_map::{ChangeMap, MapParams, ObservationWindow};
use roam_mapper::seed;
use roam_proto::map::{GridMeta, Origin};

const CELLS: usize = 12;
const SHORT: u32 = 200;
const LONG: u32 = 20_000;

/// The mean relative rate error over the cells after SHORT and after LONG seconds.
fn errors(seed: u64, means: &[(u32, u32)]) -> (f64, f64) {
    let meta = GridMeta {
        width: CELLS as u32,
        height: 1,
        resolution: 1.0,
        origin: Origin::default(),
    };
    let mut map = ChangeMap::new(meta, MapParams::default()).expect("map");
    let mut rng = seed::stream(seed, "cells");
    let mut blocked: Vec<bool> = (0..CELLS).map(|_| rng.random_bool(0.5)).collect();
    let truth: Vec<f64> = means.iter().map(|&(a, b)| 1.0 / f64::from(a + b)).collect();
    let error = |map: &ChangeMap| {
        let rates = map.rate_layer();
        rates
            .cells
            .iter()
            .zip(&truth)
            .map(|(e, t)| (e - t).abs() / t)
            .sum::<f64>()
            / CELLS as f64
    };
    let mut short = f64::NAN;
    let mut cells = vec![0i8; CELLS];
    for t in 0..=LONG {
        if t > 0 {
            for (k, b) in blocked.iter_mut().enumerate() {
                let mean = if *b { means[k].1 } else { means[k].0 };
                if rng.random_bool(1.0 / f64::from(mean)) {
                    *b = !*b;
                }
            }
        }
        for (v, &b) in cells.iter_mut().zip(&blocked) {
            *v = if b { 100 } else { 0 };
        }
        let window = ObservationWindow {
            x0: 0,
            y0: 0,
            width: CELLS as u32,
            height: 1,
            cells: &cells,
        };
        map.observe(&window, f64::from(t)).expect("observe");
        if t == SHORT {
            short = error(&map);
        }
    }
    (short, error(&map))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, ..ProptestConfig::default() })]

    #[test]
    fn estimated_rates_converge_to_the_true_ones(
        seed in any::<u64>(),
        means in proptest::collection::vec((2u32..40, 2u32..40), CELLS),
    ) {
        let (short, long) = errors(seed, &means);
        prop_assert!(long < short, "the error shrinks: {short} → {long}");
        prop_assert!(long < 0.12, "within 12 % at {LONG} s: {long}");
    }
}
