//! The map now: the fleet's belief that each cell is occupied at a given time, from the
//! cell's last sighting (by any robot) and its two Poisson rates.
//!
//! Not in paper 004, which keeps the last sighting and the rates apart; roam joins them
//! as iMac does (Saarinen et al., IROS 2012: each cell a two-state continuous-time Markov
//! chain whose transitions are paper 004's two Poisson processes). With λ_b the
//! free→blocked rate, λ_f the blocked→free rate (each [`RatePrior`]'s posterior mean,
//! over the time the cell was watched in the state it leaves, see [`crate::poisson`]),
//! π = λ_b / (λ_b + λ_f) the long-run share of time occupied and Δt = t_now − t_last:
//!
//! ```text
//! P(occupied at t | occupied at t_last) = π + (1 − π) · e^{−(λ_b + λ_f) Δt}
//! P(occupied at t | free at t_last)     = π · (1 − e^{−(λ_b + λ_f) Δt})
//! ```
//!
//! At Δt = 0 this is the last sighting itself, so a change is in the map from the first
//! observation after it; as Δt grows the belief relaxes toward π at the cell's own pace.
//!
//! **A cell never seen** takes a stated prior ([`BeliefParams::unseen_occupied`] or the
//! static map's value, see [`belief_layer`]): nothing was observed to relax from.
//!
//! **The layer** is `occupied_now`, ROS occupancy values: i8 0..=100, round(100 · P),
//! never -1 (every cell has a belief, a cell never seen its prior), so a ROS 2 user can
//! take it as a `nav_msgs/OccupancyGrid` and the planner as an occupancy layer.

use roam_world::grid::Grid;
use serde::{Deserialize, Serialize};

use crate::change_map::{percent, ChangeMap};
use crate::error::MapperError;
use crate::poisson::{CellProcess, CellState};
use crate::prior::RatePrior;

/// The map now's rate prior by default: α = 10⁻⁴ pseudo-events over β = 60 s, a mean of
/// 1.7·10⁻⁶ changes per second (about one per cell per week) weighing one minute of
/// watched time. It errs toward the last sighting: most of a warehouse never changes, so
/// a cell never seen to change keeps its state for days (a free cell watched five minutes
/// and unseen for a day is believed 2% occupied), while a cell watched changing is judged
/// by its own events after a minute of watching. The prior is the same for both rates,
/// so a cell with no watched time relaxes toward π = 1/2; a prior weighing a day would
/// keep every little-watched cell there, where weighing a minute lets a few minutes of
/// watching a cell free bring π near 0.
pub const DEFAULT_BELIEF_PRIOR: RatePrior = RatePrior {
    alpha: 1e-4,
    beta_s: 60.0,
};

/// P(occupied) of a cell never seen where no static map says otherwise: 1/2, the belief
/// that favours neither state.
pub const DEFAULT_UNSEEN_OCCUPIED: f64 = 0.5;

/// The map now's parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BeliefParams {
    /// The Gamma prior on λ_b and λ_f (default [`DEFAULT_BELIEF_PRIOR`]).
    pub prior: RatePrior,
    /// P(occupied) of a cell never seen and without a static map value, 0..=1 (default
    /// [`DEFAULT_UNSEEN_OCCUPIED`]).
    pub unseen_occupied: f64,
}

impl Default for BeliefParams {
    fn default() -> Self {
        BeliefParams {
            prior: DEFAULT_BELIEF_PRIOR,
            unseen_occupied: DEFAULT_UNSEEN_OCCUPIED,
        }
    }
}

impl BeliefParams {
    pub fn check(&self) -> Result<(), MapperError> {
        self.prior.check("belief.prior")?;
        let p = self.unseen_occupied;
        if !(0.0..=1.0).contains(&p) {
            return Err(MapperError::Param {
                field: "belief.unseen_occupied",
                reason: format!("must be a probability in 0..=1, got {p}"),
            });
        }
        Ok(())
    }
}

/// P(occupied at `now_s`) of one cell (module doc), or `None` for a cell never seen.
pub fn occupied_probability(cell: &CellProcess, prior: &RatePrior, now_s: f64) -> Option<f64> {
    let state = cell.last_state()?;
    let t_last = cell.t_last()?;
    let (block, free) = (prior.block_rate(cell), prior.free_rate(cell));
    let total = block + free;
    let pi = block / total;
    // 1 − e^{−(λ_b + λ_f)Δt}, accurate for small Δt.
    let mixed = -(-total * (now_s - t_last).max(0.0)).exp_m1();
    Some(match state {
        CellState::Occupied => 1.0 - (1.0 - pi) * mixed,
        CellState::Free => pi * mixed,
    })
}

/// P(occupied at `now_s`) of every cell of `map` (`now_s` before the latest observation
/// is taken as it). A cell never seen takes `static_map`'s value as a probability (ROS
/// occupancy / 100: 0 free, 100 occupied) where it has one, else
/// `params.unseen_occupied`. `static_map` must be the change map's size.
pub fn belief_layer(
    map: &ChangeMap,
    now_s: f64,
    params: &BeliefParams,
    static_map: Option<&Grid<i8>>,
) -> Result<Grid<f64>, MapperError> {
    params.check()?;
    if let Some(s) = static_map {
        if (s.meta.width, s.meta.height) != (map.width(), map.height())
            || s.cells.len() != map.processes().len()
        {
            return Err(MapperError::GridMismatch {
                width: map.width(),
                height: map.height(),
                got_width: s.meta.width,
                got_height: s.meta.height,
            });
        }
    }
    let t = map.now(now_s);
    let unseen = |i: usize| match static_map.and_then(|s| s.cells.get(i)) {
        Some(&v) if v >= 0 => f64::from(v.min(100)) / 100.0,
        _ => params.unseen_occupied,
    };
    let cells = map
        .processes()
        .iter()
        .enumerate()
        .map(|(i, c)| occupied_probability(c, &params.prior, t).unwrap_or_else(|| unseen(i)))
        .collect();
    Ok(Grid {
        meta: *map.meta(),
        cells,
    })
}

/// The `occupied_now` layer: [`belief_layer`] as ROS occupancy values, i8
/// round(100 · P) in 0..=100.
pub fn occupied_now(
    map: &ChangeMap,
    now_s: f64,
    params: &BeliefParams,
    static_map: Option<&Grid<i8>>,
) -> Result<Grid<i8>, MapperError> {
    let belief = belief_layer(map, now_s, params, static_map)?;
    Ok(Grid {
        meta: belief.meta,
        cells: ros_occupancy(&belief.cells),
    })
}

/// Probabilities as ROS occupancy: [`percent`] of each, NaN as 1/2 (50, as unsure as a
/// cell can be).
pub fn ros_occupancy(probabilities: &[f64]) -> Vec<i8> {
    probabilities
        .iter()
        .map(|&p| percent(if p.is_nan() { 0.5 } else { p }) as i8)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::change_map::{MapParams, ObservationWindow};
    use roam_proto::map::{GridMeta, Origin};

    fn meta(width: u32) -> GridMeta {
        GridMeta {
            width,
            height: 1,
            resolution: 1.0,
            origin: Origin::default(),
        }
    }

    const PRIOR: RatePrior = RatePrior {
        alpha: 1.0,
        beta_s: 10.0,
    };

    fn params(prior: RatePrior) -> BeliefParams {
        BeliefParams {
            prior,
            ..BeliefParams::default()
        }
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    /// A one-row map, each row of `seen` one observation of every cell at t = its index
    /// (-1 not seen, 0 free, 100 occupied).
    fn watched(width: u32, seen: &[&[i8]]) -> ChangeMap {
        let mut map = ChangeMap::new(meta(width), MapParams::default()).expect("map");
        for (t, cells) in seen.iter().enumerate() {
            let window = ObservationWindow {
                x0: 0,
                y0: 0,
                width,
                height: 1,
                cells,
            };
            map.observe(&window, t as f64).expect("observe");
        }
        map
    }

    #[test]
    fn the_two_state_chain_by_hand() {
        // Occupied at t = 0..=4, free at 5..=10: one blocked→free event; watched 4.5 s
        // occupied and 5.5 s free (the change's second split).
        let seen: Vec<&[i8]> = (0..=10)
            .map(|t| if t < 5 { &[100][..] } else { &[0][..] })
            .collect();
        let map = watched(1, &seen);
        let cell = &map.processes()[0];
        let (block, free): (f64, f64) = (1.0 / 15.5, 2.0 / 14.5);
        assert!(close(PRIOR.block_rate(cell), block));
        assert!(close(PRIOR.free_rate(cell), free));
        let (k, pi) = (block + free, block / (block + free));
        // Free at t_last = 10; at t = 20: π (1 − e^{−kΔt}).
        let p = occupied_probability(cell, &PRIOR, 20.0).expect("seen");
        assert!(close(p, pi * (1.0 - (-k * 10.0).exp())), "{p}");
        // Long after: the share of time occupied, π.
        assert!(close(
            occupied_probability(cell, &PRIOR, 1e6).expect("seen"),
            pi
        ));
        // Seen occupied last: π + (1 − π) e^{−kΔt}.
        let seen: Vec<&[i8]> = (0..=10)
            .map(|t| if t < 5 { &[0][..] } else { &[100][..] })
            .collect();
        let map = watched(1, &seen);
        let cell = &map.processes()[0];
        let (block, free): (f64, f64) = (2.0 / 14.5, 1.0 / 15.5);
        let (k, pi) = (block + free, block / (block + free));
        let p = occupied_probability(cell, &PRIOR, 13.0).expect("seen");
        assert!(close(p, pi + (1.0 - pi) * (-k * 3.0).exp()), "{p}");
        assert_eq!(
            occupied_probability(&CellProcess::UNOBSERVED, &PRIOR, 5.0),
            None
        );
    }

    #[test]
    fn a_change_is_in_the_map_from_the_first_observation_after_it() {
        // Cell 0 is free for ten seconds and blocked at t = 10 (a pallet put down); cell
        // 1 stays free; cell 2 is never seen.
        let mut seen: Vec<&[i8]> = vec![&[0, 0, -1]; 10];
        seen.push(&[100, 0, -1]);
        let map = watched(3, &seen);
        let now = occupied_now(&map, 10.0, &BeliefParams::default(), None).expect("layer");
        assert_eq!(now.cells, vec![100, 0, 50]);
        // A moment before the change was seen, the belief was free.
        let before = watched(3, &seen[..10]);
        let then = occupied_now(&before, 9.0, &BeliefParams::default(), None).expect("layer");
        assert_eq!(then.cells[0], 0);
        // With the default prior a day later the pallet is still believed there (it
        // was watched arriving, never leaving), and the cell watched free for only ten
        // seconds has begun to relax toward 1/2 (11%).
        let later = belief_layer(&map, 86_400.0, &BeliefParams::default(), None).expect("layer");
        assert!(later.cells[0] > 0.99, "{}", later.cells[0]);
        assert!((0.1..0.12).contains(&later.cells[1]), "{}", later.cells[1]);
        // A quick prior relaxes faster.
        let quick = belief_layer(&map, 86_400.0, &params(PRIOR), None).expect("layer");
        assert!(quick.cells[0] < later.cells[0]);
    }

    #[test]
    fn a_cell_never_seen_takes_the_static_map_or_the_stated_prior() {
        let map = watched(4, &[&[0, -1, -1, -1]]);
        let static_map = Grid {
            meta: meta(4),
            cells: vec![100, 100, 0, -1],
        };
        let unseen = BeliefParams {
            unseen_occupied: 0.3,
            ..BeliefParams::default()
        };
        let b = belief_layer(&map, 0.0, &unseen, Some(&static_map)).expect("layer");
        // Cell 0 was seen free: the observation wins over the static map.
        assert_eq!(b.cells, vec![0.0, 1.0, 0.0, 0.3]);
        let wrong = Grid {
            meta: meta(3),
            cells: vec![0; 3],
        };
        assert!(matches!(
            belief_layer(&map, 0.0, &unseen, Some(&wrong)),
            Err(MapperError::GridMismatch { .. })
        ));
        let bad = BeliefParams {
            unseen_occupied: 1.5,
            ..BeliefParams::default()
        };
        assert!(matches!(
            belief_layer(&map, 0.0, &bad, None),
            Err(MapperError::Param {
                field: "belief.unseen_occupied",
                ..
            })
        ));
    }

    #[test]
    fn the_default_prior_keeps_a_watched_free_cell_free_for_a_day() {
        // Watched free for five minutes, then unseen for a day: about 2%.
        let mut c = CellProcess::UNOBSERVED;
        for t in 0..=300 {
            c.observe(f64::from(t), false, crate::poisson::Watch::every(1.0));
        }
        let p = occupied_probability(&c, &DEFAULT_BELIEF_PRIOR, 300.0 + 86_400.0).expect("seen");
        assert!((0.015..0.025).contains(&p), "{p}");
    }
}
