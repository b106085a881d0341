//! The Gamma prior on a cell's change rates, for the news value ([`crate::news`]) and the
//! map now ([`crate::belief`]).
//!
//! Paper 004's rate 1/T^c (Eq. 1) is 0 until a cell shows its first event, and a rate of
//! 0 makes P(changed) = 0 however long the cell went unseen: early in a week nothing
//! would ever be news, and a cell seen once would be believed as it was forever. roam's
//! choice (not in paper 004): a Gamma(α, β) prior on each Poisson rate, α pseudo-events
//! over β pseudo-seconds of watched time. With n events in D watched seconds the
//! posterior is Gamma(α + n, β + D) (the conjugate Gamma–Poisson model), and roam uses
//! its mean
//!
//! ```text
//! λ̂ = (n + α) / (D + β)
//! ```
//!
//! as the rate, plugged into the exponentials of the news value and the Markov chain.
//! (The posterior predictive P(no event in Δt) = (1 + Δt/(D + β))^−(n + α) would be less
//! sure over long gaps; the plug-in keeps the formulas of the papers' form.)
//!
//! α/β is the rate believed before a cell was watched at all, and β says how much
//! watched time the prior weighs as: once a cell has been watched much longer than β,
//! its own events decide. The two products ask different questions and so take different
//! defaults, each argued next to its product: the news value errs toward looking
//! ([`crate::news::DEFAULT_NEWS_PRIOR`], about one change per cell per day), the map now
//! toward the last sighting ([`crate::belief::DEFAULT_BELIEF_PRIOR`], about one change
//! per cell per week, weighing one minute).

use serde::{Deserialize, Serialize};

use crate::error::MapperError;
use crate::poisson::CellProcess;

/// The Gamma prior on a cell's change rates (module doc). No default of its own: each
/// product has one.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RatePrior {
    /// α: pseudo-events (> 0).
    pub alpha: f64,
    /// β: pseudo-seconds of watched time (> 0).
    pub beta_s: f64,
}

impl RatePrior {
    /// Refuses a prior that is not two positive finite numbers; `name` is the parameter
    /// the error names (e.g. `news.prior`).
    pub fn check(&self, name: &'static str) -> Result<(), MapperError> {
        for (part, value) in [("alpha", self.alpha), ("beta_s", self.beta_s)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(MapperError::Param {
                    field: name,
                    reason: format!("{part} must be a positive number, got {value}"),
                });
            }
        }
        Ok(())
    }

    /// λ̂ = (n + α) / (D + β) for `events` in `watched_s` seconds, per second.
    pub fn rate(&self, events: u32, watched_s: f64) -> f64 {
        (f64::from(events) + self.alpha) / (watched_s.max(0.0) + self.beta_s)
    }

    /// The rate at which the cell changes at all, either way (the news value's rate):
    /// every change seen since the first sighting, watched or found after a gap
    /// ([`CellProcess::changes_seen`]), over the whole span since then
    /// ([`CellProcess::seen_span`]). α/β for a cell never seen.
    ///
    /// Not paper 004's Eq. 1, which counts only watched events over the watched time D:
    /// that is unbiased, but a fleet watches a cell only while a robot passes (seconds a
    /// visit), so a warehouse's pallets, which land while nobody looks, are almost never
    /// events and every cell keeps its prior rate. Counting a change found after a gap as
    /// one change over the gap's whole length undercounts a cell that changed several
    /// times in one gap (a lower bound of its rate for gaps long against 1/λ), but it
    /// learns from every visit, which is what the news needs: which cells change more.
    pub fn change_rate(&self, cell: &CellProcess) -> f64 {
        self.rate(cell.changes_seen(), cell.seen_span())
    }

    /// λ_b, free→blocked: the free→blocked events over the time watched free.
    pub fn block_rate(&self, cell: &CellProcess) -> f64 {
        self.rate(cell.n_block(), cell.observed_time_free())
    }

    /// λ_f, blocked→free: the blocked→free events over the time watched occupied.
    pub fn free_rate(&self, cell: &CellProcess) -> f64 {
        self.rate(cell.n_free(), cell.observed_time_occupied())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::poisson::Watch;

    #[test]
    fn the_prior_alone_and_with_events() {
        let prior = RatePrior {
            alpha: 2.0,
            beta_s: 100.0,
        };
        let never = CellProcess::UNOBSERVED;
        assert_eq!(prior.change_rate(&never), 0.02);
        assert_eq!(prior.block_rate(&never), 0.02);
        // Free 0–1, blocked from 2 (a change in 1–2), free again at 4 (in 3–4).
        let mut c = CellProcess::UNOBSERVED;
        for (t, occ) in [
            (0.0, false),
            (1.0, false),
            (2.0, true),
            (3.0, true),
            (4.0, false),
        ] {
            c.observe(t, occ, Watch::every(1.0));
        }
        // n = 2 in D = 4 s: (2 + 2) / (4 + 100).
        assert!((prior.change_rate(&c) - 4.0 / 104.0).abs() < 1e-15);
        // D_free = 1 + 0.5 + 0.5 = 2, D_occ = 0.5 + 1 + 0.5 = 2.
        assert!((prior.block_rate(&c) - 3.0 / 102.0).abs() < 1e-15);
        assert!((prior.free_rate(&c) - 3.0 / 102.0).abs() < 1e-15);
        // Seen blocked at 100 after a gap: a change the news counts over the whole span
        // (3 in 100 s), which paper 004's processes do not (D grows by one period).
        c.observe(100.0, true, Watch::every(1.0));
        assert!((prior.change_rate(&c) - 5.0 / 200.0).abs() < 1e-15);
        // Its one period of watched time splits between the states at its ends.
        assert!((prior.block_rate(&c) - 3.0 / 102.5).abs() < 1e-15);
    }

    #[test]
    fn a_prior_must_be_positive() {
        let good = RatePrior {
            alpha: 1.0,
            beta_s: 60.0,
        };
        assert!(good.check("news.prior").is_ok());
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let p = RatePrior { alpha: bad, ..good };
            let refused = p.check("news.prior");
            assert!(
                matches!(&refused, Err(MapperError::Param { field: "news.prior", reason }) if reason.starts_with("alpha")),
                "{refused:?}"
            );
        }
    }
}
