//! The change map (paper 004 §3): the obstacle grid the robot builds from its sensor
//! windows, a pair of Poisson processes per cell, and the layers and features the
//! exploration strategies and the learner read.
//!
//! **Map changes.** An update reports two kinds of change to the obstacle map, cell by
//! cell: *flips* (a known cell seen free where it was occupied, or the reverse) and
//! *discoveries* (an unknown cell seen for the first time). Both change "the obstacle
//! grid map" the paper's controller and reward look at (§2, §4); which of them the
//! explorer counts is its parameter (`ExplorerParams::count_discoveries`). Only flips
//! with time between them are Poisson events.
//!
//! **Values.** Window cells are ROS values: -1 not seen (skipped: the cell is not
//! touched), 0..=100 seen, occupied from [`OCCUPIED_FROM`] (50) up. The obstacle map
//! holds -1 (never seen), 0 (free) or 100 (occupied): each cell's last sighting.
//!
//! **Time.** Observations must come in time order (the same time again is fine: several
//! robots' windows of one instant merge by observing each in turn).

mod params;
mod scores;
mod update;
mod window;

use roam_proto::map::GridMeta;
use roam_world::grid::{occupancy, world_to_cell, Grid};

pub use crate::limits::MAX_MAP_CELLS;

use crate::error::MapperError;
use crate::features::{Features, TileCache};
use crate::poisson::CellProcess;

pub use params::MapParams;
pub use scores::{percent, scores};
pub use update::{MapStats, Update};
pub use window::{ObservationWindow, OCCUPIED_FROM};

/// The obstacle map, the Poisson processes and the feature caches of one map.
#[derive(Debug, Clone)]
pub struct ChangeMap {
    meta: GridMeta,
    params: MapParams,
    /// -1 never seen, 0 free, 100 occupied.
    obstacles: Vec<i8>,
    cells: Vec<CellProcess>,
    tiles: TileCache,
    t_first: Option<f64>,
    t_latest: Option<f64>,
    unseen: u64,
    events: u64,
    observations: u64,
}

impl ChangeMap {
    /// An empty map (every cell unknown) with the placement `meta`.
    pub fn new(meta: GridMeta, params: MapParams) -> Result<ChangeMap, MapperError> {
        params.check()?;
        let cells = u64::from(meta.width) * u64::from(meta.height);
        if cells == 0 {
            return Err(MapperError::EmptyMap);
        }
        if cells > MAX_MAP_CELLS {
            return Err(MapperError::too_large(cells));
        }
        if !(meta.resolution.is_finite() && meta.resolution > 0.0) {
            return Err(MapperError::BadResolution(meta.resolution));
        }
        Ok(ChangeMap {
            meta,
            params,
            obstacles: vec![occupancy::UNKNOWN; cells as usize],
            cells: vec![CellProcess::UNOBSERVED; cells as usize],
            tiles: TileCache::new(meta.width, meta.height),
            t_first: None,
            t_latest: None,
            unseen: cells,
            events: 0,
            observations: 0,
        })
    }

    pub fn meta(&self) -> &GridMeta {
        &self.meta
    }

    pub fn params(&self) -> &MapParams {
        &self.params
    }

    pub fn width(&self) -> u32 {
        self.meta.width
    }

    pub fn height(&self) -> u32 {
        self.meta.height
    }

    /// The index of cell (x, y), or `None` off the map.
    pub fn index(&self, x: u32, y: u32) -> Option<usize> {
        (x < self.meta.width && y < self.meta.height)
            .then(|| y as usize * self.meta.width as usize + x as usize)
    }

    /// The cell a world point (metres) falls in, or `None` off the map.
    pub fn cell_of(&self, at: [f64; 2]) -> Option<(u32, u32)> {
        world_to_cell(&self.meta, at[0], at[1]).map(|(x, y)| (x as u32, y as u32))
    }

    /// Records one sensor window seen at time `t` (seconds). Only the window's seen
    /// cells are touched. The window must lie inside the map, carry `width · height`
    /// values in -1..=100, and `t` must not be before the latest observation; a refused
    /// window changes nothing.
    pub fn observe(
        &mut self,
        window: &ObservationWindow<'_>,
        t: f64,
    ) -> Result<Update, MapperError> {
        self.check_window(window, t)?;
        self.t_first.get_or_insert(t);
        self.t_latest = Some(t);
        self.observations += 1;
        self.tiles
            .mark(window.x0, window.y0, window.width, window.height);
        let watch = self.params.watch();
        let mut update = Update {
            t,
            ..Update::default()
        };
        let (w, ww) = (self.meta.width as usize, window.width as usize);
        for (row, values) in window.cells.chunks(ww.max(1)).enumerate() {
            let y = window.y0 + row as u32;
            let base = y as usize * w + window.x0 as usize;
            for (dx, &v) in values.iter().enumerate() {
                if v < 0 {
                    continue;
                }
                update.observed += 1;
                let i = base + dx;
                let x = window.x0 + dx as u32;
                let occupied = v >= OCCUPIED_FROM;
                let (Some(cell), Some(mapped)) = (self.cells.get_mut(i), self.obstacles.get_mut(i))
                else {
                    continue;
                };
                let had_events = cell.has_events();
                if cell.observe(t, occupied, watch).is_some() {
                    update.events += 1;
                    self.events += 1;
                    if !had_events {
                        self.tiles.activate(x, y);
                    }
                }
                let value = if occupied {
                    occupancy::OCCUPIED
                } else {
                    occupancy::FREE
                };
                if *mapped == occupancy::UNKNOWN {
                    update.discovered.push((x, y));
                    self.unseen -= 1;
                } else if *mapped != value {
                    update.flipped.push((x, y));
                }
                *mapped = value;
            }
        }
        Ok(update)
    }

    fn check_window(&self, window: &ObservationWindow<'_>, t: f64) -> Result<(), MapperError> {
        if !t.is_finite() {
            return Err(MapperError::BadTime(t));
        }
        if let Some(latest) = self.t_latest {
            if t < latest {
                return Err(MapperError::TimeWentBack { t, latest });
            }
        }
        let inside = u64::from(window.x0) + u64::from(window.width) <= u64::from(self.meta.width)
            && u64::from(window.y0) + u64::from(window.height) <= u64::from(self.meta.height);
        if !inside {
            return Err(MapperError::WindowOutside {
                x0: window.x0,
                y0: window.y0,
                width: window.width,
                height: window.height,
                map_width: self.meta.width,
                map_height: self.meta.height,
            });
        }
        let expected = u64::from(window.width) * u64::from(window.height);
        if window.cells.len() as u64 != expected {
            return Err(MapperError::WindowSize {
                width: window.width,
                height: window.height,
                got: window.cells.len(),
            });
        }
        if let Some((index, &value)) = window
            .cells
            .iter()
            .enumerate()
            .find(|(_, &v)| !(v == -1 || (0..=100).contains(&v)))
        {
            return Err(MapperError::BadValue { value, index });
        }
        Ok(())
    }

    /// The obstacle map, row-major: -1 never seen, 0 free, 100 occupied.
    pub fn obstacles(&self) -> &[i8] {
        &self.obstacles
    }

    /// The obstacle map as a grid.
    pub fn obstacle_grid(&self) -> Grid<i8> {
        Grid {
            meta: self.meta,
            cells: self.obstacles.clone(),
        }
    }

    /// Cell (x, y)'s processes, or `None` off the map.
    pub fn process(&self, x: u32, y: u32) -> Option<&CellProcess> {
        self.index(x, y).and_then(|i| self.cells.get(i))
    }

    /// Every cell's processes, row-major.
    pub fn processes(&self) -> &[CellProcess] {
        &self.cells
    }

    /// The first observation's time, seconds.
    pub fn t_first(&self) -> Option<f64> {
        self.t_first
    }

    /// The latest observation's time, seconds.
    pub fn t_latest(&self) -> Option<f64> {
        self.t_latest
    }

    pub fn stats(&self) -> MapStats {
        MapStats {
            seen_cells: self.cells.len() as u64 - self.unseen,
            active_cells: self.tiles.active_cells() as u64,
            events: self.events,
            observations: self.observations,
        }
    }

    /// The time the layers and features are evaluated at: `t_now`, but never before the
    /// latest observation (a cell cannot have been seen in the future).
    pub(crate) fn now(&self, t_now: f64) -> f64 {
        match self.t_latest {
            // NaN compares as not later: the latest time is used.
            Some(latest) if t_now.is_nan() || t_now < latest => latest,
            _ => t_now,
        }
    }

    /// The recency of a cell never seen: as if it had been seen one sensor period before
    /// the map's first observation, t_now − t_first + observation_period, so it is
    /// strictly the stalest cell and recency-based exploration goes there first (the
    /// paper does not say). 0 before any observation.
    pub fn unseen_recency(&self, t_now: f64) -> f64 {
        match self.t_first {
            None => 0.0,
            Some(t_first) => {
                (self.now(t_now) - t_first).max(0.0) + self.params.observation_period_s
            }
        }
    }

    /// The change rate 1/T^c of every cell (Eq. 1), events per second; 0 where no
    /// event was seen.
    pub fn rate_layer(&self) -> Grid<f64> {
        self.layer(|c| c.rate())
    }

    /// The `change_information` layer at `t_now`: round(100 · P_c(E > 0)) of every cell
    /// (Eq. 2), as paper 000's information scores (0–100), what the planner couples in.
    pub fn change_scores(&self, t_now: f64) -> Vec<u8> {
        scores(&self.probability_layer(t_now).cells)
    }

    /// P_c(E > 0) at `t_now` of every cell (Eq. 2).
    pub fn probability_layer(&self, t_now: f64) -> Grid<f64> {
        let t = self.now(t_now);
        self.layer(|c| c.change_probability(t))
    }

    /// r^c = t_now − t_last of every cell, seconds; [`ChangeMap::unseen_recency`] for
    /// cells never seen.
    pub fn recency_layer(&self, t_now: f64) -> Grid<f64> {
        let t = self.now(t_now);
        let unseen = self.unseen_recency(t);
        self.layer(|c| c.recency(t).unwrap_or(unseen))
    }

    fn layer(&self, f: impl Fn(&CellProcess) -> f64) -> Grid<f64> {
        Grid {
            meta: self.meta,
            cells: self.cells.iter().map(f).collect(),
        }
    }

    /// The learner's features at `t_now` (§4): p = Σ_c P_c(E > 0) and r = max_c r^c
    /// over the whole map, from the per-tile caches (see [`crate::features`]): cheap,
    /// and equal to [`ChangeMap::features_exact`] to ~10⁻¹² relative. Takes `&mut self`
    /// only to refresh those caches.
    pub fn features(&mut self, t_now: f64) -> Features {
        let t = self.now(t_now);
        let (p, min_t_last) = self.tiles.refresh(&self.cells, t);
        Features {
            p,
            r: self.max_recency(t, min_t_last),
        }
    }

    /// The features by the definition, summing every cell: the reference the cached
    /// [`ChangeMap::features`] is tested against.
    pub fn features_exact(&self, t_now: f64) -> Features {
        let t = self.now(t_now);
        let p = self.cells.iter().map(|c| c.change_probability(t)).sum();
        let min_t_last = self
            .cells
            .iter()
            .filter_map(|c| c.t_last())
            .fold(f64::INFINITY, f64::min);
        Features {
            p,
            r: self.max_recency(t, min_t_last),
        }
    }

    fn max_recency(&self, t: f64, min_t_last: f64) -> f64 {
        if self.unseen > 0 && !self.params.r_over_seen_cells {
            self.unseen_recency(t)
        } else if min_t_last.is_finite() {
            (t - min_t_last).max(0.0)
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_proto::map::Origin;

    fn meta(width: u32, height: u32) -> GridMeta {
        GridMeta {
            width,
            height,
            resolution: 1.0,
            origin: Origin::default(),
        }
    }

    #[test]
    fn a_wire_observation_is_its_window_and_other_cells_are_none() {
        let mut o = roam_proto::sim::LocalObservation {
            robot: "r1".into(),
            step: 3,
            time_s: 1.2,
            at: [2.5, 1.5],
            x0: 1,
            y0: 0,
            meta: meta(2, 3),
            cells: roam_proto::cells::Cells::I8(vec![0, 100, -1, 0, 0, 100]),
        };
        assert_eq!(
            ObservationWindow::from_wire(&o),
            Some(window(1, 0, 2, 3, &[0, 100, -1, 0, 0, 100]))
        );
        o.cells = roam_proto::cells::Cells::U8(vec![0; 6]);
        assert_eq!(ObservationWindow::from_wire(&o), None);
    }

    fn window(x0: u32, y0: u32, width: u32, height: u32, cells: &[i8]) -> ObservationWindow<'_> {
        ObservationWindow {
            x0,
            y0,
            width,
            height,
            cells,
        }
    }

    #[test]
    fn refuses_bad_input_and_changes_nothing() {
        assert!(matches!(
            ChangeMap::new(meta(3000, 3000), MapParams::default()),
            Err(MapperError::MapTooLarge { .. })
        ));
        assert_eq!(
            ChangeMap::new(meta(0, 5), MapParams::default()).err(),
            Some(MapperError::EmptyMap)
        );
        let mut map = ChangeMap::new(meta(4, 4), MapParams::default()).expect("map");
        let cells = [0i8; 4];
        assert!(matches!(
            map.observe(&window(3, 0, 2, 2, &cells), 0.0),
            Err(MapperError::WindowOutside { .. })
        ));
        assert!(matches!(
            map.observe(&window(0, 0, 2, 3, &cells), 0.0),
            Err(MapperError::WindowSize { .. })
        ));
        assert!(matches!(
            map.observe(&window(0, 0, 2, 2, &[0, 101, 0, 0]), 0.0),
            Err(MapperError::BadValue { index: 1, .. })
        ));
        assert!(matches!(
            map.observe(&window(0, 0, 2, 2, &cells), f64::NAN),
            Err(MapperError::BadTime(_))
        ));
        assert_eq!(map.stats(), MapStats::default());
        map.observe(&window(0, 0, 2, 2, &cells), 5.0).expect("ok");
        assert!(matches!(
            map.observe(&window(0, 0, 2, 2, &cells), 4.0),
            Err(MapperError::TimeWentBack { .. })
        ));
        // The same time again is fine (another robot's window).
        map.observe(&window(0, 0, 2, 2, &cells), 5.0)
            .expect("same t");
    }

    #[test]
    fn only_seen_cells_are_touched_and_changes_are_counted() {
        let mut map = ChangeMap::new(meta(4, 3), MapParams::default()).expect("map");
        // A 3 x 2 window at (1, 1): row y = 1 then y = 2.
        let u = map
            .observe(&window(1, 1, 3, 2, &[0, -1, 100, 0, 0, -1]), 1.0)
            .expect("observe");
        assert_eq!(u.observed, 4);
        assert_eq!(u.discovered, vec![(1, 1), (3, 1), (1, 2), (2, 2)]);
        assert!(u.flipped.is_empty());
        assert_eq!(u.events, 0);
        assert_eq!(map.obstacles()[4 + 2], -1, "unseen window cell untouched");
        assert_eq!(map.obstacles()[4 + 3], 100);
        assert_eq!(map.obstacles()[0], -1, "outside the window untouched");
        // One second later (3, 1) is free and (2, 2) occupied; (1, 1) unseen.
        let u = map
            .observe(&window(1, 1, 3, 2, &[-1, -1, 0, 0, 100, -1]), 2.0)
            .expect("observe");
        assert_eq!(u.flipped, vec![(3, 1), (2, 2)]);
        assert!(u.discovered.is_empty());
        assert_eq!(u.events, 2);
        assert_eq!(u.map_changes(true), 2);
        assert_eq!(u.centroid(false), Some((3, 2))); // (2.5, 1.5) rounds away from zero
        assert_eq!(map.stats().active_cells, 2);
        assert_eq!(map.stats().seen_cells, 4);
        // Rates: each flipped cell watched 1 s with one event: 1/s. P at t = 3: 1 − 1/e.
        let rate = map.rate_layer();
        assert_eq!(rate.get(3, 1), Some(1.0));
        assert_eq!(rate.get(1, 1), Some(0.0));
        let p = map.probability_layer(3.0);
        let expected = 1.0 - (-1.0f64).exp();
        assert!((p.get(2, 2).unwrap_or(0.0) - expected).abs() < 1e-15);
        // Recency: (1, 1) last seen at 1, unseen cells count from t_first − 1 s.
        let r = map.recency_layer(3.0);
        assert_eq!(r.get(1, 1), Some(2.0));
        assert_eq!(r.get(3, 1), Some(1.0));
        assert_eq!(r.get(0, 0), Some(3.0));
        let f = map.features(3.0);
        assert!((f.p - 2.0 * expected).abs() < 1e-12);
        assert_eq!(f.r, 3.0);
        assert_eq!(f, map.features_exact(3.0));
    }

    /// Two robots' windows of the same instant merge into the one map; where they
    /// overlap and disagree, the later one sets the cell but no time passed, so there is
    /// no event. A second later, a change either robot sees is an event of the map.
    #[test]
    fn two_robots_windows_merge_into_one_map() {
        let mut map = ChangeMap::new(meta(4, 1), MapParams::default()).expect("map");
        // Robot a sees cells 0..=2, robot b cells 2..=3, both at t = 1.
        map.observe(&window(0, 0, 3, 1, &[0, 0, 0]), 1.0)
            .expect("a");
        let u = map.observe(&window(2, 0, 2, 1, &[100, 0]), 1.0).expect("b");
        assert_eq!(u.events, 0, "a disagreement at one instant is not an event");
        assert_eq!(map.obstacles(), &[0, 0, 100, 0]);
        assert_eq!(map.stats().seen_cells, 4);
        // At t = 2 robot b sees cell 3 blocked: one free→blocked event, rate 1/s.
        let u = map
            .observe(&window(2, 0, 2, 1, &[100, 100]), 2.0)
            .expect("b again");
        assert_eq!((u.events, u.flipped.clone()), (1, vec![(3, 0)]));
        assert_eq!(map.rate_layer().get(3, 0), Some(1.0));
        assert_eq!(map.rate_layer().get(0, 0), Some(0.0));
    }

    #[test]
    fn once_everything_is_seen_r_is_the_stalest_cell() {
        let mut map = ChangeMap::new(meta(2, 1), MapParams::default()).expect("map");
        map.observe(&window(0, 0, 2, 1, &[0, 0]), 0.0).expect("a");
        map.observe(&window(0, 0, 1, 1, &[0]), 4.0).expect("b");
        let f = map.features(10.0);
        assert_eq!(f.r, 10.0);
        assert_eq!(f.p, 0.0);
        // Asked about a time before the latest observation: the latest is used.
        assert_eq!(map.features(1.0).r, 4.0);
    }

    /// Random windows, flips at very different rates, gaps, and queries at times near
    /// and far: the tile caches must always give the plain sum.
    #[test]
    fn cached_features_equal_the_plain_sum() {
        use rand::Rng;
        for seed in 0..2u64 {
            let mut rng = crate::seed::stream(seed, "test");
            // 150 x 70: three tiles across and two up, the last ones partial.
            let (w, h) = (150u32, 70u32);
            let mut map = ChangeMap::new(meta(w, h), MapParams::default()).expect("map");
            let mut world: Vec<bool> = (0..w * h).map(|_| rng.random_bool(0.2)).collect();
            // Per-cell flip probability per second: most cells static, some slow, a few
            // fast.
            let flip: Vec<f64> = (0..w * h)
                .map(|_| match rng.random_range(0..10) {
                    0 => 0.5,
                    1..=3 => 0.01,
                    _ => 0.0,
                })
                .collect();
            let mut t = 0.0;
            let mut cells = Vec::new();
            for k in 0..300 {
                // Mostly one second per update, sometimes a long pause.
                t += if k % 50 == 49 { 300.0 } else { 1.0 };
                for (i, cell) in world.iter_mut().enumerate() {
                    if rng.random_bool(flip[i]) {
                        *cell = !*cell;
                    }
                }
                let (ww, wh) = (rng.random_range(1..=80), rng.random_range(1..=60));
                let (x0, y0) = (rng.random_range(0..=w - ww), rng.random_range(0..=h - wh));
                cells.clear();
                for y in y0..y0 + wh {
                    for x in x0..x0 + ww {
                        let v = if rng.random_bool(0.1) {
                            -1
                        } else if world[(y * w + x) as usize] {
                            100
                        } else {
                            0
                        };
                        cells.push(v);
                    }
                }
                let window = ObservationWindow {
                    x0,
                    y0,
                    width: ww,
                    height: wh,
                    cells: &cells,
                };
                map.observe(&window, t).expect("observe");
                if k % 4 == 0 {
                    for query in [t, t + 0.3, t + 7.0, t + 400.0] {
                        let (cached, exact) = (map.features(query), map.features_exact(query));
                        let tolerance = 1e-10 * exact.p.max(1.0);
                        assert!(
                            (cached.p - exact.p).abs() <= tolerance,
                            "seed {seed} update {k} at {query}: {cached:?} vs {exact:?}"
                        );
                        assert_eq!(cached.r, exact.r);
                    }
                }
            }
            assert!(map.stats().active_cells > 500, "{:?}", map.stats());
        }
    }
}
