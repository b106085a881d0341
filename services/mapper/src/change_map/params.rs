//! The change map's parameters: the sensor period and the two choices the paper leaves
//! open.

use serde::{Deserialize, Serialize};

use crate::error::MapperError;
use crate::poisson::Watch;

/// The change map's parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapParams {
    /// The sensor period, seconds: sightings of a cell at most this far apart mean it
    /// was watched the whole time in between (see [`crate::poisson`]). 1 s in the grid
    /// world (one observation per sim step). Give a little more than the nominal
    /// period when the sensor jitters.
    pub observation_period_s: f64,
    /// Whether a change found after a gap longer than the period is a Poisson event
    /// (see [`crate::poisson`]; default false: only watched changes are events).
    #[serde(default)]
    pub events_across_gaps: bool,
    /// Whether the learner's feature r = max_c r^c (paper 004 Eq. 4) runs over the cells
    /// seen at least once only. The paper defines r^c = t_now − t_last^c through the
    /// timestamp "each cell c that is observed" gets, and leaves a cell never observed
    /// open. Default false: a cell never seen counts as the stalest
    /// ([`ChangeMap::unseen_recency`](crate::change_map::ChangeMap::unseen_recency)), as
    /// it does for recency goals; on grid004 four wall corners are never seen, so r is
    /// then the run's clock, t − t_first + 1 s. Leaving them out changed no result there
    /// (the crate doc's reproduction).
    #[serde(default)]
    pub r_over_seen_cells: bool,
}

impl Default for MapParams {
    fn default() -> Self {
        MapParams {
            observation_period_s: 1.0,
            events_across_gaps: false,
            r_over_seen_cells: false,
        }
    }
}

impl MapParams {
    /// The per-cell rule these parameters give.
    pub fn watch(&self) -> Watch {
        Watch {
            period_s: self.observation_period_s,
            events_across_gaps: self.events_across_gaps,
        }
    }
}

impl MapParams {
    pub fn check(&self) -> Result<(), MapperError> {
        let p = self.observation_period_s;
        if !(p.is_finite() && p > 0.0) {
            return Err(MapperError::Param {
                field: "observation_period_s",
                reason: format!("must be a positive number of seconds, got {p}"),
            });
        }
        Ok(())
    }
}
