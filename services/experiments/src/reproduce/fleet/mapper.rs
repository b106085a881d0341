//! The fleet's mapper in process: the mapper's own code ([`ChangeMap`], [`NewsMap`],
//! [`belief_layer`]) fed every robot's observation every step, on the planner's grid
//! (module doc of [`super::world`]): each 5 cm observation window is laid onto the
//! 0.2 m cells it covers (a cell seen when any of its map cells is seen, occupied when
//! any seen one is).

use roam_mapper::belief::{belief_layer, BeliefParams};
use roam_mapper::change_map::{ChangeMap, MapParams, ObservationWindow};
use roam_mapper::news::NewsMap;
use roam_mapper::prior::RatePrior;
use roam_mapper::reserve::cells_along;
use roam_proto::cells::Cells;
use roam_proto::sim::LocalObservation;

use super::world::FleetWorld;
use super::FleetError;

/// The cells one reservation holds at most (a plan's reach).
const MAX_RESERVED: usize = 1 << 16;

/// A window of the coarse grid, as the change map takes it.
#[derive(Debug, Default)]
struct CoarseWindow {
    x0: u32,
    y0: u32,
    width: u32,
    height: u32,
    cells: Vec<i8>,
}

/// The fleet's map and, for a variant that does not share, each robot's own.
#[derive(Debug)]
pub struct FleetMapper {
    /// Every robot's observations: what the mapper service keeps.
    pub shared: ChangeMap,
    /// Each robot's own observations (the variant without sharing).
    own: Option<Vec<ChangeMap>>,
    pub news: NewsMap,
    window: CoarseWindow,
}

fn mapper_error(e: impl std::fmt::Display) -> FleetError {
    FleetError::Mapper(e.to_string())
}

impl FleetMapper {
    /// An empty map on the world's coarse grid; `own_maps`: one more per robot.
    pub fn new(
        world: &FleetWorld,
        robots: usize,
        own_maps: bool,
        prior: RatePrior,
    ) -> Result<FleetMapper, FleetError> {
        let params = MapParams {
            observation_period_s: world.step_s,
            ..MapParams::default()
        };
        let map = || ChangeMap::new(world.coarse, params).map_err(mapper_error);
        let shared = map()?;
        let own = if own_maps {
            Some((0..robots).map(|_| map()).collect::<Result<Vec<_>, _>>()?)
        } else {
            None
        };
        Ok(FleetMapper {
            news: NewsMap::for_map(&shared, prior).map_err(mapper_error)?,
            shared,
            own,
            window: CoarseWindow::default(),
        })
    }

    /// Robot `robot`'s observation at `t`.
    pub fn observe(
        &mut self,
        world: &FleetWorld,
        robot: usize,
        o: &LocalObservation,
        t: f64,
    ) -> Result<(), FleetError> {
        let Cells::I8(cells) = &o.cells else {
            return Ok(());
        };
        coarsen_window(
            world.factor,
            o.x0,
            o.y0,
            o.meta.width,
            o.meta.height,
            cells,
            &mut self.window,
        );
        let w = &self.window;
        let window = ObservationWindow {
            x0: w.x0,
            y0: w.y0,
            width: w.width,
            height: w.height,
            cells: &w.cells,
        };
        self.shared.observe(&window, t).map_err(mapper_error)?;
        if let Some(own) = self.own.as_mut().and_then(|o| o.get_mut(robot)) {
            own.observe(&window, t).map_err(mapper_error)?;
        }
        Ok(())
    }

    /// `robot`'s plan, driven from `start_s` at `s_per_m`, seeing `radius_m` around it:
    /// its cells count as seen then for every other robot.
    pub fn reserve(
        &mut self,
        world: &FleetWorld,
        robot: &str,
        path: &[[f64; 2]],
        start_s: f64,
        s_per_m: f64,
        radius_m: f64,
    ) -> Result<(), FleetError> {
        let cells = cells_along(
            &world.coarse,
            path,
            start_s,
            s_per_m,
            radius_m,
            MAX_RESERVED,
        )
        .map_err(mapper_error)?;
        self.news.reserve(robot, cells).map_err(mapper_error)?;
        Ok(())
    }

    /// The news scores robot `robot` plans on at `now_s`: the fleet's (others' plans
    /// counted when `reservations`), or its own map's when the maps are not shared.
    pub fn news_scores(
        &self,
        robot: usize,
        name: &str,
        now_s: f64,
        reservations: bool,
    ) -> Result<Vec<u8>, FleetError> {
        let map = self
            .own
            .as_ref()
            .and_then(|o| o.get(robot))
            .unwrap_or(&self.shared);
        let for_robot = if reservations { Some(name) } else { None };
        let scores = if reservations || self.own.is_some() {
            self.news.news_scores(map, now_s, for_robot)
        } else {
            // No reservation counted: a news map that holds none.
            NewsMap::for_map(map, *self.news.prior()).and_then(|n| n.news_scores(map, now_s, None))
        };
        scores.map(|g| g.cells).map_err(mapper_error)
    }

    /// The fleet's belief P(occupied now) per coarse cell.
    pub fn belief(&self, world: &FleetWorld, now_s: f64) -> Result<Vec<f64>, FleetError> {
        belief_layer(
            &self.shared,
            now_s,
            &BeliefParams::default(),
            Some(&world.static_coarse),
        )
        .map(|g| g.cells)
        .map_err(mapper_error)
    }
}

/// The fine window (x0, y0, width, height, cells) laid onto coarse cells of `factor`
/// map cells a side.
fn coarsen_window(
    factor: u32,
    x0: u32,
    y0: u32,
    width: u32,
    height: u32,
    cells: &[i8],
    out: &mut CoarseWindow,
) {
    let f = factor.max(1);
    let (cx0, cy0) = (x0 / f, y0 / f);
    let (cx1, cy1) = ((x0 + width.max(1) - 1) / f, (y0 + height.max(1) - 1) / f);
    out.x0 = cx0;
    out.y0 = cy0;
    out.width = cx1 - cx0 + 1;
    out.height = cy1 - cy0 + 1;
    out.cells.clear();
    out.cells.resize((out.width * out.height) as usize, -1);
    let cw = out.width as usize;
    for (row, values) in cells.chunks(width.max(1) as usize).enumerate() {
        let cy = ((y0 + row as u32) / f - cy0) as usize;
        for (dx, &v) in values.iter().enumerate() {
            if v < 0 {
                continue;
            }
            let cx = ((x0 + dx as u32) / f - cx0) as usize;
            let slot = &mut out.cells[cy * cw + cx];
            if v >= 50 {
                *slot = 100;
            } else if *slot < 0 {
                *slot = 0;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fine_window_lands_on_the_coarse_cells_it_covers() {
        // A 6 x 2 window at map cell (2, 3), 4 map cells a coarse cell: coarse cells
        // (0..=1, 0..=1).
        let cells = [
            -1, 0, 0, -1, -1, -1, //
            -1, -1, 100, -1, -1, 0,
        ];
        let mut out = CoarseWindow::default();
        coarsen_window(4, 2, 3, 6, 2, &cells, &mut out);
        assert_eq!((out.x0, out.y0, out.width, out.height), (0, 0, 2, 2));
        // Row y 3 is coarse row 0, row y 4 coarse row 1; x 2..=3 coarse 0, 4..=7 coarse 1:
        // seen free at x 3 and 4, occupied at x 4 of row 4.
        assert_eq!(out.cells, vec![0, 0, -1, 100]);
        let cells = [100, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1];
        coarsen_window(4, 2, 3, 6, 2, &cells, &mut out);
        assert_eq!(out.cells, vec![100, -1, -1, -1]);
    }
}
