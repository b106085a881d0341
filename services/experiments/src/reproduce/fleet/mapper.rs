//! The fleet's mapper in process: the mapper's own code ([`ChangeMap`], [`NewsMap`],
//! [`belief_layer`]) fed every robot's observation every step, on the planner's grid
//! (module doc of [`super::world`]). The live mapper keeps its map at the map's 5 cm,
//! where a cell nobody saw keeps its state; so does this one, in a [`FineBelief`] of the
//! 5 cm cells seen occupied last. A 0.2 m cell an observation touched is seen occupied
//! when any of its 5 cm cells is seen occupied now, seen free when none is and none of
//! its others is still believed occupied from an earlier sighting, and not seen
//! otherwise (it keeps its state, and its belief fades with its rates, as a 5 cm cell
//! nobody looks at). Why not lay each window onto the coarse cells alone (occupied when
//! any seen map cell is, free otherwise): a robot looking along a pallet's face sees few
//! of the face's cells (the grid's line of sight runs centre to centre), so its view
//! would write the face's coarse cells free over the view of the robot standing at the
//! pallet, and the fleet would plan through the pallet.

use roam_mapper::belief::{belief_layer, BeliefParams};
use roam_mapper::change_map::{ChangeMap, MapParams, ObservationWindow};
use roam_mapper::news::NewsMap;
use roam_mapper::prior::RatePrior;
use roam_mapper::reserve::cells_along;
use roam_proto::cells::Cells;
use roam_proto::sim::LocalObservation;

use super::error::FleetError;
use super::world::FleetWorld;

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

/// Which map cells (5 cm) were seen occupied when last seen (none before any sighting).
#[derive(Debug, Clone)]
struct FineBelief {
    width: u32,
    height: u32,
    occupied: Vec<bool>,
}

impl FineBelief {
    fn new(width: u32, height: u32) -> FineBelief {
        FineBelief {
            width,
            height,
            occupied: vec![false; width as usize * height as usize],
        }
    }

    fn at(&self, x: u32, y: u32) -> bool {
        x < self.width && y < self.height && self.occupied[(y * self.width + x) as usize]
    }
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
    /// The fleet's 5 cm belief, and each robot's own beside `own`.
    fine: FineBelief,
    own_fine: Vec<FineBelief>,
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
        let map = world.inflated.meta;
        let fine = FineBelief::new(map.width, map.height);
        Ok(FleetMapper {
            news: NewsMap::for_map(&shared, prior).map_err(mapper_error)?,
            shared,
            own_fine: if own_maps {
                vec![fine.clone(); robots]
            } else {
                Vec::new()
            },
            fine,
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
        let fine = FineWindow {
            x0: o.x0,
            y0: o.y0,
            width: o.meta.width,
            height: o.meta.height,
            cells,
        };
        coarsen_window(world.factor, &fine, &mut self.fine, &mut self.window);
        self.shared
            .observe(&self.window.view(), t)
            .map_err(mapper_error)?;
        if let (Some(own), Some(own_fine)) = (
            self.own.as_mut().and_then(|o| o.get_mut(robot)),
            self.own_fine.get_mut(robot),
        ) {
            coarsen_window(world.factor, &fine, own_fine, &mut self.window);
            own.observe(&self.window.view(), t).map_err(mapper_error)?;
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

impl CoarseWindow {
    fn view(&self) -> ObservationWindow<'_> {
        ObservationWindow {
            x0: self.x0,
            y0: self.y0,
            width: self.width,
            height: self.height,
            cells: &self.cells,
        }
    }
}

/// One robot's observation at the map's resolution (ROS values, -1 unseen).
struct FineWindow<'a> {
    x0: u32,
    y0: u32,
    width: u32,
    height: u32,
    cells: &'a [i8],
}

/// The fine window laid onto `belief` (the map cells it saw take what they were seen
/// as), then onto the coarse cells of `factor` map cells a side (module doc): 100 when
/// any of a coarse cell's map cells is seen occupied now; 0 when some are seen, all
/// free, and none of the others is believed occupied; -1 otherwise.
fn coarsen_window(factor: u32, fine: &FineWindow, belief: &mut FineBelief, out: &mut CoarseWindow) {
    let f = factor.max(1);
    let (x0, y0, width, height) = (fine.x0, fine.y0, fine.width.max(1), fine.height.max(1));
    let (cx0, cy0) = (x0 / f, y0 / f);
    let (cx1, cy1) = ((x0 + width - 1) / f, (y0 + height - 1) / f);
    out.x0 = cx0;
    out.y0 = cy0;
    out.width = cx1 - cx0 + 1;
    out.height = cy1 - cy0 + 1;
    out.cells.clear();
    out.cells.resize((out.width * out.height) as usize, -1);
    let cw = out.width as usize;
    for (row, values) in fine.cells.chunks(width as usize).enumerate() {
        let y = y0 + row as u32;
        for (dx, &v) in values.iter().enumerate() {
            let x = x0 + dx as u32;
            if v < 0 || x >= belief.width || y >= belief.height {
                continue;
            }
            belief.occupied[(y * belief.width + x) as usize] = v >= 50;
            let slot = &mut out.cells[((y / f - cy0) as usize) * cw + (x / f - cx0) as usize];
            *slot = if v >= 50 { 100 } else { (*slot).max(0) };
        }
    }
    for (slot, cell) in out.cells.iter_mut().enumerate() {
        if *cell != 0 {
            continue;
        }
        // Seen free in part: an unseen map cell still believed occupied keeps it.
        let (cx, cy) = (cx0 + (slot % cw) as u32, cy0 + (slot / cw) as u32);
        let held = (cy * f..(cy + 1) * f).any(|y| (cx * f..(cx + 1) * f).any(|x| belief.at(x, y)));
        if held {
            *cell = -1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn free_map(width: u32, height: u32) -> FineBelief {
        FineBelief {
            width,
            height,
            occupied: vec![false; (width * height) as usize],
        }
    }

    fn window(x0: u32, y0: u32, width: u32, height: u32, cells: &[i8]) -> FineWindow<'_> {
        FineWindow {
            x0,
            y0,
            width,
            height,
            cells,
        }
    }

    #[test]
    fn a_fine_window_lands_on_the_coarse_cells_it_covers() {
        // A 6 x 2 window at map cell (2, 3), 4 map cells a coarse cell: coarse cells
        // (0..=1, 0..=1).
        let cells = [
            -1, 0, 0, -1, -1, -1, //
            -1, -1, 100, -1, -1, 0,
        ];
        let mut belief = free_map(16, 16);
        let mut out = CoarseWindow::default();
        coarsen_window(4, &window(2, 3, 6, 2, &cells), &mut belief, &mut out);
        assert_eq!((out.x0, out.y0, out.width, out.height), (0, 0, 2, 2));
        // Row y 3 is coarse row 0, row y 4 coarse row 1; x 2..=3 coarse 0, 4..=7 coarse 1:
        // seen free at x 3 and 4 of row 3, occupied at x 4 of row 4, none seen in
        // coarse (0, 1).
        assert_eq!(out.cells, vec![0, 0, -1, 100]);
        assert!(belief.at(4, 4));
        // Seen free again: the belief follows.
        let cells = [-1, -1, 0, -1, -1, -1, -1, -1, -1, -1, -1, -1];
        coarsen_window(4, &window(2, 4, 6, 2, &cells), &mut belief, &mut out);
        assert!(!belief.at(4, 4));
        assert_eq!((out.y0, out.height), (1, 1));
        assert_eq!(out.cells, vec![-1, 0]);
    }

    #[test]
    fn a_coarse_cell_keeps_what_was_seen_in_it_where_it_is_not_seen_again() {
        // A robot at a pallet's face sees one of its map cells, (0, 1), occupied;
        // another robot along the face sees only the free row 0 of the same coarse cell:
        // the pallet's cell keeps its state, so the coarse cell is still occupied.
        let mut belief = free_map(8, 4);
        let mut out = CoarseWindow::default();
        let mut at_the_face = vec![-1i8; 32];
        at_the_face[..4].copy_from_slice(&[0, 0, 0, 0]);
        at_the_face[8] = 100;
        coarsen_window(4, &window(0, 0, 8, 4, &at_the_face), &mut belief, &mut out);
        assert_eq!(out.cells, vec![100, -1]);
        let mut along = vec![-1i8; 32];
        along[..8].copy_from_slice(&[0; 8]);
        coarsen_window(4, &window(0, 0, 8, 4, &along), &mut belief, &mut out);
        assert_eq!(out.cells, vec![-1, 0], "not seen again: it keeps its state");
        // Seen gone: free.
        let cleared = vec![0i8; 32];
        coarsen_window(4, &window(0, 0, 8, 4, &cleared), &mut belief, &mut out);
        assert_eq!(out.cells, vec![0, 0]);
    }
}
