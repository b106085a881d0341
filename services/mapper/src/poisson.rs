//! The pair of Poisson processes one cell carries (paper 004 §3, Fig. 2): one counts the
//! cell's free→blocked events, the other its blocked→free events, and the two together
//! give the cell's change rate (Eq. 1), the probability that it changed since it was
//! last seen (Eq. 2) and its recency.
//!
//! **How the time a cell is watched accumulates** (the paper's t_not obs., which it
//! leaves to the reader). A cell is seen at discrete sensor updates. roam's rule: two
//! consecutive sightings at most `observation_period` apart (the sensor period, 1 s in
//! the grid world) mean the cell was watched the whole time in between; a longer gap
//! means it was watched for one period after the earlier sighting and not at all for
//! the rest, so the gap adds `gap − observation_period` to t_not obs. The watched time
//! is then D = t_last − t_not obs. − t_init = Σ min(gap, observation_period) over the
//! sightings after the first. Without this correction a cell seen once, forgotten for
//! an hour and seen again changed would look like it changes once an hour, whatever
//! its true rate (the "large bias" §3 warns about).
//!
//! **Which changes are events** (the paper counts "observed events" and is silent on
//! changes found after a gap). A change between two sightings at most one period apart
//! was watched: it is an event. A change found after a longer gap happened while the
//! cell was not watched; by default ([`Watch::events_across_gaps`] false) it updates
//! the state but is not counted, so the events and the watched time D cover the same
//! time and 1/T^c estimates the rate without bias. Counting it (true) adds up to one
//! event per gap for one period of watched time: a cell revisited now and then looks
//! like it changes at nearly every visit (on grid004 this roughly doubles the final
//! rate error; `roam reproduce mapper` reports both settings in the crate doc).
//!
//! Two sightings at the same instant that disagree (two robots' windows at one time)
//! set the cell's state to the later one but are not an event: no time passed for a
//! change to happen. So every event comes with a gap > 0, which adds to D, and D > 0
//! whenever there is an event: Eq. 1 never divides zero by a count.
//!
//! **The watched time in each state** (not in paper 004, which needs only D; roam's,
//! for the two-state Markov chain of [`crate::belief`]). A free→blocked event can only
//! happen while the cell is free, so that process's rate is its events over the time
//! the cell was watched *free*, D_free, and the blocked→free rate is over D_occ, as
//! iMac (Saarinen et al., IROS 2012) learns each transition rate from the observations
//! of its source state; over the whole D both processes count the same flux and would
//! say every changing cell is occupied half the time. A gap's watched time goes to the
//! state at both its ends, half to each when they differ (the change happened somewhere
//! in the gap, in the middle on average), so D_free + D_occ = D.

use serde::Serialize;

/// How sightings are turned into watched time and events (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Watch {
    /// The sensor period, seconds (> 0): sightings at most this far apart mean the cell
    /// was watched in between.
    pub period_s: f64,
    /// Whether a change found after a longer gap is an event.
    pub events_across_gaps: bool,
}

impl Watch {
    /// Watched every `period_s` seconds; changes across gaps are not events.
    pub fn every(period_s: f64) -> Watch {
        Watch {
            period_s,
            events_across_gaps: false,
        }
    }
}

/// A state change one process counts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Event {
    /// Free → blocked.
    Block,
    /// Blocked → free.
    Free,
}

/// What a cell was last seen as.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CellState {
    Free,
    Occupied,
}

/// One cell's two Poisson processes (paper 004 §3). Times are seconds on the caller's
/// clock; a cell never seen has every count at zero.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellProcess {
    /// t_init: the first sighting.
    t_init: f64,
    /// t_last: the latest sighting.
    t_last: f64,
    /// t_not obs.: the time between t_init and t_last the cell was not watched.
    t_not_obs: f64,
    /// D_occ: the watched time the cell was occupied (module doc).
    t_occupied: f64,
    /// Free→blocked events seen.
    n_block: u32,
    /// Blocked→free events seen.
    n_free: u32,
    /// Changes found after a gap (the state differs across a sighting gap longer than
    /// the period), which are not events of paper 004's processes: the news rate counts
    /// them ([`CellProcess::changes_seen`]).
    n_gap_changes: u32,
    /// The state at the latest sighting; `None` before the first.
    last: Option<CellState>,
}

impl Default for CellProcess {
    fn default() -> Self {
        CellProcess::UNOBSERVED
    }
}

impl CellProcess {
    /// A cell never seen.
    pub const UNOBSERVED: CellProcess = CellProcess {
        t_init: 0.0,
        t_last: 0.0,
        t_not_obs: 0.0,
        t_occupied: 0.0,
        n_block: 0,
        n_free: 0,
        n_gap_changes: 0,
        last: None,
    };

    /// Records a sighting at time `t` (seconds) of the cell as `occupied` or free (see
    /// the module doc for how the gap since the last sighting counts). Returns the
    /// event it makes, if the state changed since the last sighting and the change
    /// counts. A sighting earlier than the last one (out of order) is taken as if it
    /// were at the last one's time.
    pub fn observe(&mut self, t: f64, occupied: bool, watch: Watch) -> Option<Event> {
        let state = if occupied {
            CellState::Occupied
        } else {
            CellState::Free
        };
        let Some(previous) = self.last else {
            self.t_init = t;
            self.t_last = t;
            self.last = Some(state);
            return None;
        };
        let gap = (t - self.t_last).max(0.0);
        let watched = gap <= watch.period_s;
        if !watched {
            self.t_not_obs += gap - watch.period_s;
        }
        let watched_time = gap.min(watch.period_s);
        let occupied_ends = u8::from(previous == CellState::Occupied) + u8::from(occupied);
        self.t_occupied += watched_time * f64::from(occupied_ends) / 2.0;
        self.t_last = self.t_last.max(t);
        self.last = Some(state);
        if previous == state || gap <= 0.0 {
            return None;
        }
        if !(watched || watch.events_across_gaps) {
            self.n_gap_changes = self.n_gap_changes.saturating_add(1);
            return None;
        }
        Some(match state {
            CellState::Occupied => {
                self.n_block = self.n_block.saturating_add(1);
                Event::Block
            }
            CellState::Free => {
                self.n_free = self.n_free.saturating_add(1);
                Event::Free
            }
        })
    }

    /// Whether the cell was ever seen.
    pub fn observed(&self) -> bool {
        self.last.is_some()
    }

    /// The state at the latest sighting.
    pub fn last_state(&self) -> Option<CellState> {
        self.last
    }

    /// t_init, the first sighting (`None` if never seen).
    pub fn t_init(&self) -> Option<f64> {
        self.last.map(|_| self.t_init)
    }

    /// t_last, the latest sighting (`None` if never seen).
    pub fn t_last(&self) -> Option<f64> {
        self.last.map(|_| self.t_last)
    }

    /// t_not obs., seconds.
    pub fn t_not_observed(&self) -> f64 {
        self.t_not_obs
    }

    pub fn n_block(&self) -> u32 {
        self.n_block
    }

    pub fn n_free(&self) -> u32 {
        self.n_free
    }

    /// Every change the cell was seen to make since its first sighting, watched (the
    /// events) or found after a gap (at least one change happened in it), over which
    /// [`CellProcess::seen_span`] is the exposure: the news value's count
    /// ([`crate::prior::RatePrior::change_rate`]).
    pub fn changes_seen(&self) -> u32 {
        self.n_block
            .saturating_add(self.n_free)
            .saturating_add(self.n_gap_changes)
    }

    /// t_last − t_init: the time over which [`CellProcess::changes_seen`] were counted,
    /// seconds (0 before the second sighting).
    pub fn seen_span(&self) -> f64 {
        (self.t_last - self.t_init).max(0.0)
    }

    /// Whether any event was seen (the cell has a rate above zero).
    pub fn has_events(&self) -> bool {
        self.n_block > 0 || self.n_free > 0
    }

    /// The time the cell was watched, D = t_last − t_not obs. − t_init, seconds.
    pub fn observed_time(&self) -> f64 {
        (self.t_last - self.t_not_obs - self.t_init).max(0.0)
    }

    /// D_occ: the watched time the cell was occupied, seconds (module doc).
    pub fn observed_time_occupied(&self) -> f64 {
        self.t_occupied.clamp(0.0, self.observed_time())
    }

    /// D_free = D − D_occ: the watched time the cell was free, seconds (module doc).
    pub fn observed_time_free(&self) -> f64 {
        (self.observed_time() - self.observed_time_occupied()).max(0.0)
    }

    /// E(T_block) of Eq. 1, seconds; infinite when no free→blocked event was seen.
    pub fn mean_block_interval(&self) -> f64 {
        interval(self.observed_time(), self.n_block)
    }

    /// E(T_free) of Eq. 1, seconds; infinite when no blocked→free event was seen.
    pub fn mean_free_interval(&self) -> f64 {
        interval(self.observed_time(), self.n_free)
    }

    /// T^c = min(E(T_block), E(T_free)) (Eq. 1), seconds; infinite when the cell has no
    /// events.
    pub fn interval(&self) -> f64 {
        self.mean_block_interval().min(self.mean_free_interval())
    }

    /// The change rate 1/T^c, events per second of one process; 0 without events.
    pub fn rate(&self) -> f64 {
        let n = self.n_block.max(self.n_free);
        if n == 0 {
            return 0.0;
        }
        let d = self.observed_time();
        if d > 0.0 {
            f64::from(n) / d
        } else {
            0.0
        }
    }

    /// P_c(E > 0) = 1 − exp(−(t_now − t_last)/T^c) (Eq. 2): the probability that the
    /// cell changed at least once since it was last seen. 0 for a cell without events
    /// (rate 0) and for a cell never seen (nothing is known of its rate).
    pub fn change_probability(&self, t_now: f64) -> f64 {
        let rate = self.rate();
        if rate == 0.0 {
            return 0.0;
        }
        let elapsed = (t_now - self.t_last).max(0.0);
        -(-rate * elapsed).exp_m1()
    }

    /// r^c = t_now − t_last (§3), seconds; `None` for a cell never seen (the change map
    /// gives those a value of its own, see `ChangeMap::recency_layer`).
    pub fn recency(&self, t_now: f64) -> Option<f64> {
        self.last.map(|_| (t_now - self.t_last).max(0.0))
    }
}

/// D / n, infinite for n = 0.
fn interval(d: f64, n: u32) -> f64 {
    if n == 0 {
        f64::INFINITY
    } else {
        d / f64::from(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PERIOD: Watch = Watch {
        period_s: 1.0,
        events_across_gaps: false,
    };
    const ACROSS: Watch = Watch {
        period_s: 1.0,
        events_across_gaps: true,
    };

    /// Sightings (t, occupied) in order.
    fn seen_with(watch: Watch, sightings: &[(f64, bool)]) -> CellProcess {
        let mut c = CellProcess::UNOBSERVED;
        for &(t, occ) in sightings {
            c.observe(t, occ, watch);
        }
        c
    }

    fn seen(sightings: &[(f64, bool)]) -> CellProcess {
        seen_with(PERIOD, sightings)
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    #[test]
    fn a_change_found_after_a_gap_is_no_event_but_counts_for_the_news() {
        // Free at 0 and 1 (watched), occupied at 100 (after a gap), free at 101
        // (watched: an event), free again at 500.
        let c = seen(&[
            (0.0, false),
            (1.0, false),
            (100.0, true),
            (101.0, false),
            (500.0, false),
        ]);
        assert_eq!((c.n_block(), c.n_free()), (0, 1));
        assert_eq!(c.changes_seen(), 2);
        assert!(close(c.seen_span(), 500.0));
        // Counted as events across gaps, it is not counted twice.
        let across = seen_with(ACROSS, &[(0.0, false), (100.0, true)]);
        assert_eq!((across.n_block(), across.changes_seen()), (1, 1));
        assert_eq!(CellProcess::UNOBSERVED.changes_seen(), 0);
        assert!(close(CellProcess::UNOBSERVED.seen_span(), 0.0));
    }

    #[test]
    fn a_cell_never_seen_knows_nothing() {
        let c = CellProcess::UNOBSERVED;
        assert!(!c.observed());
        assert_eq!(c.rate(), 0.0);
        assert_eq!(c.interval(), f64::INFINITY);
        assert_eq!(c.change_probability(100.0), 0.0);
        assert_eq!(c.recency(100.0), None);
        assert_eq!(c.t_last(), None);
    }

    #[test]
    fn a_cell_without_events_has_rate_zero() {
        // Seen free every second from t = 3 to t = 10: watched 7 s, no events.
        let c = seen(&(3..=10).map(|t| (f64::from(t), false)).collect::<Vec<_>>());
        assert!(close(c.observed_time(), 7.0));
        assert_eq!(c.rate(), 0.0);
        assert_eq!(c.interval(), f64::INFINITY);
        assert_eq!(c.change_probability(50.0), 0.0);
        assert_eq!(c.recency(50.0), Some(40.0));
        assert_eq!(c.t_init(), Some(3.0));
    }

    #[test]
    fn eq_1_and_eq_2_by_hand() {
        // t = 0..=10 every second; free, blocked at 2, free at 5, blocked at 9.
        let states = [0, 0, 1, 1, 1, 0, 0, 0, 0, 1, 1];
        let c = seen(
            &states
                .iter()
                .enumerate()
                .map(|(t, &s)| (t as f64, s == 1))
                .collect::<Vec<_>>(),
        );
        assert_eq!((c.n_block(), c.n_free()), (2, 1));
        // D = 10 − 0 − 0 = 10 s. E(T_block) = 10/2 = 5 s, E(T_free) = 10/1 = 10 s.
        assert!(close(c.mean_block_interval(), 5.0));
        assert!(close(c.mean_free_interval(), 10.0));
        assert!(close(c.interval(), 5.0));
        assert!(close(c.rate(), 0.2));
        // Eq. 2 at t_now = 13: 1 − e^(−3/5) = 0.451188363905973...
        assert!(close(c.change_probability(13.0), 0.451_188_363_905_973_6));
        assert_eq!(c.change_probability(10.0), 0.0);
        assert_eq!(c.recency(13.0), Some(3.0));
    }

    #[test]
    fn watched_time_is_split_by_state() {
        // The cell of `eq_1_and_eq_2_by_hand`: free 0–1, a change in 1–2, blocked 2–4, a
        // change in 4–5, free 5–8, a change in 8–9, blocked 9–10. Each change's second
        // goes half to each state.
        let states = [0, 0, 1, 1, 1, 0, 0, 0, 0, 1, 1];
        let c = seen(
            &states
                .iter()
                .enumerate()
                .map(|(t, &s)| (t as f64, s == 1))
                .collect::<Vec<_>>(),
        );
        assert!(close(c.observed_time_occupied(), 4.5));
        assert!(close(c.observed_time_free(), 5.5));
        // A gap: only its first period is watched, and it goes to the states at its ends.
        let gap = seen(&[(0.0, true), (1.0, true), (41.0, false)]);
        assert!(close(gap.observed_time(), 2.0));
        assert!(close(gap.observed_time_occupied(), 1.5));
        assert!(close(gap.observed_time_free(), 0.5));
        assert_eq!(CellProcess::UNOBSERVED.observed_time_occupied(), 0.0);
    }

    #[test]
    fn time_not_observed_is_taken_out() {
        // Free at 0 and 1, blocked at 2, free at 3: D = 3 s, one event each way, T = 3 s.
        let dense = seen(&[(0.0, false), (1.0, false), (2.0, true), (3.0, false)]);
        assert!(close(dense.observed_time(), 3.0));
        assert!(close(dense.interval(), 3.0));
        // The same events, but the robot is away from t = 1 to t = 41 (the cell is
        // blocked at 41 and 42, free at 43): the 40 s gap counts 1 s watched (one
        // period) and 39 s not watched.
        let sightings = [
            (0.0, false),
            (1.0, false),
            (41.0, true),
            (42.0, true),
            (43.0, false),
        ];
        let gap = seen(&sightings);
        assert!(close(gap.t_not_observed(), 39.0));
        // D = 43 − 39 − 0 = 4 s (0–1, 1–2 of the gap, 41–43).
        assert!(close(gap.observed_time(), 4.0));
        // The change found at 41 happened unwatched: not an event. Only 42 → 43 counts.
        assert_eq!((gap.n_block(), gap.n_free()), (0, 1));
        assert!(close(gap.interval(), 4.0));
        // Counting changes across gaps: both, T = 4/1 = 4 s still (one of each).
        let across = seen_with(ACROSS, &sightings);
        assert_eq!((across.n_block(), across.n_free()), (1, 1));
        assert!(close(across.observed_time(), 4.0));
        assert!(close(across.interval(), 4.0));
        // Uncorrected, Eq. 1 would give 43 s: ten times too slow.
        assert!(close(
            gap.t_last().unwrap_or(0.0) - gap.t_init().unwrap_or(0.0),
            43.0
        ));
    }

    #[test]
    fn changes_across_gaps_are_events_only_when_asked() {
        // Free at 0, blocked at 10 (a gap of 10 s), free at 11.
        let sightings = [(0.0, false), (10.0, true), (11.0, false)];
        let c = seen(&sightings);
        assert_eq!((c.n_block(), c.n_free()), (0, 1));
        // D = 11 − 9 = 2 s; one free event: T = 2 s, rate 0.5.
        assert!(close(c.rate(), 0.5));
        let a = seen_with(ACROSS, &sightings);
        assert_eq!((a.n_block(), a.n_free()), (1, 1));
        assert!(close(a.rate(), 0.5));
        // Two gaps and two changes across them: only the counting variant has events.
        let twice = [(0.0, false), (10.0, true), (20.0, false)];
        assert_eq!(seen(&twice).rate(), 0.0);
        // D = 2 s (one period per gap), one event each way: rate 1/2.
        assert!(close(seen_with(ACROSS, &twice).rate(), 0.5));
    }

    #[test]
    fn a_gap_of_exactly_one_period_is_watched_time() {
        let c = seen(&[(0.0, false), (1.0, true), (2.5, false)]);
        // Gaps 1 (watched) and 1.5 (1 watched, 0.5 not).
        assert!(close(c.t_not_observed(), 0.5));
        assert!(close(c.observed_time(), 2.0));
        assert!(close(c.rate(), 0.5));
    }

    #[test]
    fn disagreeing_sightings_at_one_instant_are_not_events() {
        let mut c = CellProcess::UNOBSERVED;
        assert_eq!(c.observe(5.0, false, PERIOD), None);
        assert_eq!(c.observe(5.0, true, PERIOD), None);
        assert_eq!(c.last_state(), Some(CellState::Occupied));
        assert_eq!(c.rate(), 0.0);
        // Time passes: a real event.
        assert_eq!(c.observe(6.0, false, PERIOD), Some(Event::Free));
        assert!(close(c.rate(), 1.0));
        // Out of order: treated as at t_last, so no event and no time.
        assert_eq!(c.observe(4.0, true, PERIOD), None);
        assert_eq!(c.t_last(), Some(6.0));
        assert!(close(c.observed_time(), 1.0));
    }
}
