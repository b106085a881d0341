//! The news value: per cell, the probability that it changed since any robot last saw
//! it, shared across a fleet.
//!
//! Not in paper 004, whose P_c(E > 0) (Eq. 2) is the same quantity for one robot with
//! the rate 1/T^c; roam's for a fleet (`shared/DESIGN.md`, "The fleet and the news"):
//!
//! ```text
//! P_news = 1 − exp(−λ̂ · Δt),   λ̂ = (n + α) / (D + β),   Δt = t_now − t_seen
//! ```
//!
//! with n the cell's events of both its Poisson processes (free→blocked and
//! blocked→free, as [`crate::poisson`] counts them), D its watched time and (α, β) the
//! Gamma prior of [`crate::prior`]: the cell changes at all at rate λ̂, whichever way. One
//! rate for both directions pools both processes' few events (the map now,
//! [`crate::belief`], splits them by state). A cell never seen is news for certain:
//! P_news = 1.
//!
//! **t_seen is shared.** The change map already merges every robot's observations, so
//! t_last is when *any* robot last saw the cell. And a robot's plan counts before it is
//! driven: [`NewsMap::reserve`] takes the cells on a robot's current plan with the times
//! it should see them, and for every *other* robot the cell counts as seen then:
//! t_seen = max(t_last, t_reserved). A reservation in the future makes P_news 0 now, so
//! a plan for robot A sees the cells on B's plan as fresh as at B's ETA there and looks
//! elsewhere; A's own reservation is not counted against A (its replans keep their
//! news). A cell never seen but reserved counts as seen at the reservation's time, with
//! the prior's rate α/β. Each robot holds at most one reservation (a new one replaces
//! it), for at most [`MAX_RESERVING_ROBOTS`] robots and [`MAX_RESERVED_CELLS`] cells
//! each: at most 8 MB a robot, 256 MB for a full fleet of full reservations.

use std::collections::BTreeMap;

use roam_proto::map::GridMeta;
use roam_world::grid::Grid;
use serde::{Deserialize, Serialize};

use crate::change_map::{scores, ChangeMap};
use crate::error::MapperError;
pub use crate::limits::{MAX_MAP_CELLS, MAX_RESERVED_CELLS, MAX_RESERVING_ROBOTS};
use crate::poisson::CellProcess;
use crate::prior::RatePrior;
use crate::reserve::{ReserveParams, TimedCell};

/// The news value's prior by default: α = 1 pseudo-event over β = 3,600 s, a change per
/// cell per hour. It errs toward looking: a robot that has not watched a cell for an hour
/// cannot say it is static, so every cell is news in proportion to how long nobody looked
/// (after 10 minutes 15%, after an hour 63%), and each change a visit finds
/// ([`RatePrior::change_rate`]) raises the cell's rate against the hours it was watched.
/// One hour and not a day (the default until the warehouse was measured): under a day's
/// prior a 1-hour shift's news stays below 4% everywhere, which the planner's 0–100
/// scores round to 0–4 (every cell seen in the last 20 minutes worth nothing, the rest
/// in four steps), and a week of shifts (7 hours of span) cannot outweigh it. A site that
/// changes less often wants a larger β; a short world of fast changes (paper 004's grid
/// world) a β of seconds, or the prior outweighs its events.
pub const DEFAULT_NEWS_PRIOR: RatePrior = RatePrior {
    alpha: 1.0,
    beta_s: 3_600.0,
};

/// The news value's parameters (the mapper's `news:` config).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NewsParams {
    /// The Gamma prior on the change rate (default [`DEFAULT_NEWS_PRIOR`]).
    pub prior: RatePrior,
    /// How the mapper turns a robot's mission into its reservation.
    pub reserve: ReserveParams,
}

impl Default for NewsParams {
    fn default() -> Self {
        NewsParams {
            prior: DEFAULT_NEWS_PRIOR,
            reserve: ReserveParams::default(),
        }
    }
}

impl NewsParams {
    pub fn check(&self) -> Result<(), MapperError> {
        self.prior.check("news.prior")?;
        self.reserve.check()
    }
}

/// P_news of one cell (module doc): 1 − exp(−λ̂ · (t_now − t_seen)), 1 when `seen_s` is
/// `None` (never seen), 0 when the cell counts as seen at or after `now_s`.
pub fn news_probability(
    cell: &CellProcess,
    prior: &RatePrior,
    seen_s: Option<f64>,
    now_s: f64,
) -> f64 {
    let Some(seen) = seen_s else {
        return 1.0;
    };
    let elapsed = (now_s - seen).max(0.0);
    -(-prior.change_rate(cell) * elapsed).exp_m1()
}

/// The fleet's reservations and the news value's prior, for one change map's grid. The
/// change map itself is passed to each query, so one [`ChangeMap`] keeps taking
/// observations beside it.
#[derive(Debug, Clone)]
pub struct NewsMap {
    meta: GridMeta,
    prior: RatePrior,
    /// Per robot: (cell index, time), one entry per cell, by index.
    reservations: BTreeMap<String, Vec<(u32, f64)>>,
}

impl NewsMap {
    /// A news map with no reservation for a grid of `meta`'s size.
    pub fn new(meta: GridMeta, prior: RatePrior) -> Result<NewsMap, MapperError> {
        prior.check("news.prior")?;
        let cells = u64::from(meta.width) * u64::from(meta.height);
        if cells == 0 {
            return Err(MapperError::EmptyMap);
        }
        if cells > MAX_MAP_CELLS {
            return Err(MapperError::too_large(cells));
        }
        Ok(NewsMap {
            meta,
            prior,
            reservations: BTreeMap::new(),
        })
    }

    /// A news map for `map`'s grid.
    pub fn for_map(map: &ChangeMap, prior: RatePrior) -> Result<NewsMap, MapperError> {
        NewsMap::new(*map.meta(), prior)
    }

    pub fn prior(&self) -> &RatePrior {
        &self.prior
    }

    /// Replaces `robot`'s reservation with `cells`: each cell (x, y) of its current plan
    /// with the time (seconds, the change map's clock) it should be seen there. A cell
    /// given twice keeps its latest time; no cells releases the robot. Returns the cells
    /// reserved. Refused, changing nothing: a cell off the map, a time that is not
    /// finite, more than [`MAX_RESERVED_CELLS`] cells, or a new robot when
    /// [`MAX_RESERVING_ROBOTS`] hold one.
    pub fn reserve<I>(&mut self, robot: &str, cells: I) -> Result<usize, MapperError>
    where
        I: IntoIterator<Item = TimedCell>,
    {
        let mut reserved: BTreeMap<u32, f64> = BTreeMap::new();
        for ((x, y), t) in cells {
            if x >= self.meta.width || y >= self.meta.height {
                return Err(MapperError::CellOffMap {
                    x: i64::from(x),
                    y: i64::from(y),
                    width: self.meta.width,
                    height: self.meta.height,
                });
            }
            if !t.is_finite() {
                return Err(MapperError::BadTime(t));
            }
            let index = y * self.meta.width + x;
            let at = reserved.entry(index).or_insert(t);
            *at = at.max(t);
            if reserved.len() > MAX_RESERVED_CELLS {
                return Err(MapperError::reservation_too_large());
            }
        }
        if reserved.is_empty() {
            self.release(robot);
            return Ok(0);
        }
        if !self.reservations.contains_key(robot) && self.reservations.len() >= MAX_RESERVING_ROBOTS
        {
            return Err(MapperError::too_many_robots(robot));
        }
        let count = reserved.len();
        self.reservations
            .insert(robot.to_owned(), reserved.into_iter().collect());
        Ok(count)
    }

    /// Drops `robot`'s reservation; whether it had one.
    pub fn release(&mut self, robot: &str) -> bool {
        self.reservations.remove(robot).is_some()
    }

    /// The robots holding a reservation, by name.
    pub fn reserving_robots(&self) -> impl Iterator<Item = &str> {
        self.reservations.keys().map(String::as_str)
    }

    /// The cells `robot` has reserved (0 without a reservation).
    pub fn reserved_cells(&self, robot: &str) -> usize {
        self.reservations.get(robot).map_or(0, Vec::len)
    }

    /// P_news of cell (x, y) at `now_s` for `for_robot` (every reservation counted but
    /// its own; `None`: every reservation), or `None` off the map.
    pub fn probability(
        &self,
        map: &ChangeMap,
        (x, y): (u32, u32),
        now_s: f64,
        for_robot: Option<&str>,
    ) -> Result<Option<f64>, MapperError> {
        self.check_map(map)?;
        let Some((index, cell)) = map
            .index(x, y)
            .and_then(|i| Some((i, map.processes().get(i)?)))
        else {
            return Ok(None);
        };
        let t = map.now(now_s);
        let reserved = self
            .counted(for_robot)
            .filter_map(|cells| {
                let at = cells
                    .binary_search_by_key(&(index as u32), |&(i, _)| i)
                    .ok()?;
                cells.get(at).map(|&(_, t)| t)
            })
            .fold(None, |seen: Option<f64>, t| {
                Some(seen.map_or(t, |s| s.max(t)))
            });
        Ok(Some(news_probability(
            cell,
            &self.prior,
            latest(cell.t_last(), reserved),
            t,
        )))
    }

    /// P_news of every cell at `now_s` for `for_robot` (see [`NewsMap::probability`]), on
    /// the change map's grid. `now_s` before the map's latest observation is taken as it.
    pub fn probabilities(
        &self,
        map: &ChangeMap,
        now_s: f64,
        for_robot: Option<&str>,
    ) -> Result<Grid<f64>, MapperError> {
        self.check_map(map)?;
        let t = map.now(now_s);
        let processes = map.processes();
        let mut p: Vec<f64> = processes
            .iter()
            .map(|c| news_probability(c, &self.prior, c.t_last(), t))
            .collect();
        // P_news falls as t_seen rises, so the latest of several sightings is the least
        // news of them: each reservation can only lower a cell's value.
        for cells in self.counted(for_robot) {
            for &(index, reserved) in cells {
                let i = index as usize;
                if let (Some(cell), Some(value)) = (processes.get(i), p.get_mut(i)) {
                    let seen = latest(cell.t_last(), Some(reserved));
                    *value = value.min(news_probability(cell, &self.prior, seen, t));
                }
            }
        }
        Ok(Grid {
            meta: *map.meta(),
            cells: p,
        })
    }

    /// The news scores round(100 · P_news) of every cell at `now_s` for `for_robot`, on
    /// the change map's grid: paper 000's information scale (0–100), what the planner
    /// plans on.
    pub fn news_scores(
        &self,
        map: &ChangeMap,
        now_s: f64,
        for_robot: Option<&str>,
    ) -> Result<Grid<u8>, MapperError> {
        let p = self.probabilities(map, now_s, for_robot)?;
        Ok(Grid {
            meta: p.meta,
            cells: scores(&p.cells),
        })
    }

    /// The reservations counted for `for_robot`: everyone's but its own.
    fn counted<'a>(&'a self, for_robot: Option<&'a str>) -> impl Iterator<Item = &'a [(u32, f64)]> {
        self.reservations
            .iter()
            .filter(move |(robot, _)| Some(robot.as_str()) != for_robot)
            .map(|(_, cells)| cells.as_slice())
    }

    fn check_map(&self, map: &ChangeMap) -> Result<(), MapperError> {
        if map.width() == self.meta.width && map.height() == self.meta.height {
            Ok(())
        } else {
            Err(MapperError::GridMismatch {
                width: self.meta.width,
                height: self.meta.height,
                got_width: map.width(),
                got_height: map.height(),
            })
        }
    }
}

/// The later of two optional times.
fn latest(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.max(b)),
        (a, b) => a.or(b),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::change_map::{MapParams, ObservationWindow};
    use roam_proto::map::Origin;

    fn meta(width: u32, height: u32) -> GridMeta {
        GridMeta {
            width,
            height,
            resolution: 1.0,
            origin: Origin::default(),
        }
    }

    /// α = 1 over β = 10 s: rates large enough to read.
    const PRIOR: RatePrior = RatePrior {
        alpha: 1.0,
        beta_s: 10.0,
    };

    /// A one-row map whose cells were each seen free once, at t = 0.
    fn seen_once(width: u32) -> ChangeMap {
        let mut map = ChangeMap::new(meta(width, 1), MapParams::default()).expect("map");
        let cells = vec![0i8; width as usize];
        let window = ObservationWindow {
            x0: 0,
            y0: 0,
            width,
            height: 1,
            cells: &cells,
        };
        map.observe(&window, 0.0).expect("observe");
        map
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    #[test]
    fn rates_and_last_seen_times_give_the_closed_form() {
        // Three cells: 0 never seen; 1 watched free every second from 0 to 10 (n = 0,
        // D = 10 s); 2 watched as well, blocked from 4 to 7 (n = 2, D = 10 s).
        let mut map = ChangeMap::new(meta(3, 1), MapParams::default()).expect("map");
        for t in 0..=10 {
            let occupied = (4..=7).contains(&t);
            let cells = [0, if occupied { 100 } else { 0 }];
            let window = ObservationWindow {
                x0: 1,
                y0: 0,
                width: 2,
                height: 1,
                cells: &cells,
            };
            map.observe(&window, f64::from(t)).expect("observe");
        }
        let news = NewsMap::for_map(&map, PRIOR).expect("news");
        let p = news.probabilities(&map, 30.0, None).expect("p").cells;
        // λ̂ = (0 + 1)/(10 + 10) = 0.05 and (2 + 1)/(10 + 10) = 0.15 per second, Δt = 20 s.
        assert_eq!(p[0], 1.0);
        assert!(close(p[1], 1.0 - (-1.0f64).exp()), "{}", p[1]);
        assert!(close(p[2], 1.0 - (-3.0f64).exp()), "{}", p[2]);
        let scores = news.news_scores(&map, 30.0, None).expect("scores");
        assert_eq!(scores.cells, vec![100, 63, 95]);
        assert_eq!(scores.meta, *map.meta());
        // Just seen: no news yet; asked before the latest observation: as at it.
        assert_eq!(
            news.probabilities(&map, 10.0, None).expect("p").cells[1],
            0.0
        );
        assert_eq!(
            news.probabilities(&map, 3.0, None).expect("p").cells[1],
            0.0
        );
        assert_eq!(
            news.probability(&map, (2, 0), 30.0, None).expect("p"),
            Some(p[2])
        );
        assert_eq!(news.probability(&map, (3, 0), 30.0, None).expect("p"), None);
    }

    #[test]
    fn a_cell_without_events_becomes_news_with_time() {
        let map = seen_once(1);
        let news = NewsMap::for_map(&map, DEFAULT_NEWS_PRIOR).expect("news");
        let at = |t: f64| news.probabilities(&map, t, None).expect("p").cells[0];
        // The prior's rate, one change an hour: after 10 minutes 15%, after an hour
        // 1 − 1/e.
        assert!(close(at(600.0), 1.0 - (-1.0f64 / 6.0).exp()));
        assert!(close(at(3600.0), 1.0 - (-1.0f64).exp()));
        assert!(at(3600.0) < at(7200.0));
    }

    #[test]
    fn after_a_reserves_its_plan_b_finds_no_news_there_and_a_still_does() {
        // Four cells seen at t = 0, λ̂ = 1/10 s: at t = 20 each is 1 − e^−2 = 86% news,
        // the same for both robots.
        let map = seen_once(4);
        let mut news = NewsMap::for_map(&map, PRIOR).expect("news");
        let scores = |news: &NewsMap, robot: Option<&str>| {
            news.news_scores(&map, 20.0, robot).expect("scores").cells
        };
        assert_eq!(scores(&news, Some("a")), vec![86; 4]);
        assert_eq!(scores(&news, Some("b")), vec![86; 4]);

        // A's plan passes cells 2 and 3 at t = 25 and 26: no news there for B (or for
        // the fleet as a whole); A's own plan keeps its news for A.
        assert_eq!(news.reserve("a", [((2, 0), 25.0), ((3, 0), 26.0)]), Ok(2));
        assert_eq!(scores(&news, Some("b")), vec![86, 86, 0, 0]);
        assert_eq!(scores(&news, None), vec![86, 86, 0, 0]);
        assert_eq!(scores(&news, Some("a")), vec![86; 4]);

        // B's plan passed cell 0 at t = 15: for A it counts as seen 5 s ago, 1 − e^−0.5.
        news.reserve("b", [((0, 0), 15.0)]).expect("b");
        assert_eq!(scores(&news, Some("a")), vec![39, 86, 86, 86]);
        assert_eq!(scores(&news, Some("b")), vec![86, 86, 0, 0]);

        // A new plan replaces A's reservation; an empty one releases it.
        news.reserve("a", [((1, 0), 30.0)]).expect("a again");
        assert_eq!(scores(&news, Some("b")), vec![86, 0, 86, 86]);
        assert_eq!(news.reserve("a", []), Ok(0));
        assert_eq!(news.reserving_robots().collect::<Vec<_>>(), ["b"]);
        assert_eq!(scores(&news, Some("b")), vec![86; 4]);
    }

    #[test]
    fn a_reserved_cell_never_seen_is_seen_at_its_reservation_with_the_prior_rate() {
        let map = ChangeMap::new(meta(2, 1), MapParams::default()).expect("map");
        let mut news = NewsMap::for_map(&map, PRIOR).expect("news");
        news.reserve("a", [((1, 0), 5.0), ((1, 0), 2.0)])
            .expect("a");
        assert_eq!(
            news.reserved_cells("a"),
            1,
            "one entry per cell, the latest time"
        );
        let p = news.probabilities(&map, 15.0, Some("b")).expect("p").cells;
        assert_eq!(p[0], 1.0);
        // α/β = 0.1 per second over 10 s.
        assert!(close(p[1], 1.0 - (-1.0f64).exp()));
    }

    #[test]
    fn reservations_are_bounded_and_checked() {
        let map = seen_once(4);
        let mut news = NewsMap::for_map(&map, PRIOR).expect("news");
        for r in 0..MAX_RESERVING_ROBOTS {
            news.reserve(&format!("r{r}"), [((0, 0), 1.0)])
                .expect("room");
        }
        assert!(matches!(
            news.reserve("one-more", [((0, 0), 1.0)]),
            Err(MapperError::TooManyRobots {
                max: MAX_RESERVING_ROBOTS,
                ..
            })
        ));
        // A robot that holds one may replace it.
        assert_eq!(news.reserve("r0", [((1, 0), 2.0)]), Ok(1));
        assert!(matches!(
            news.reserve("r1", [((4, 0), 1.0)]),
            Err(MapperError::CellOffMap { x: 4, .. })
        ));
        assert!(matches!(
            news.reserve("r1", [((1, 0), 1.0), ((2, 0), f64::NAN)]),
            Err(MapperError::BadTime(t)) if t.is_nan()
        ));
        // Refused: nothing changed.
        assert_eq!(news.reserved_cells("r1"), 1);
        assert_eq!(
            news.probability(&map, (0, 0), 1.0, None).expect("p"),
            Some(0.0)
        );
        assert!(news.release("r1"));
        assert!(!news.release("r1"));
    }

    #[test]
    fn a_reservation_holds_at_most_max_reserved_cells() {
        let map = ChangeMap::new(meta(1024, 513), MapParams::default()).expect("map");
        let mut news = NewsMap::for_map(&map, PRIOR).expect("news");
        let cells = |n: usize| (0..n).map(|i| (((i % 1024) as u32, (i / 1024) as u32), 1.0));
        assert_eq!(
            news.reserve("a", cells(MAX_RESERVED_CELLS)),
            Ok(MAX_RESERVED_CELLS)
        );
        assert_eq!(
            news.reserve("b", cells(MAX_RESERVED_CELLS + 1)),
            Err(MapperError::ReservationTooLarge {
                max: MAX_RESERVED_CELLS
            })
        );
        let other = ChangeMap::new(meta(4, 1), MapParams::default()).expect("map");
        assert!(matches!(
            news.probabilities(&other, 1.0, None),
            Err(MapperError::GridMismatch { .. })
        ));
    }
}
