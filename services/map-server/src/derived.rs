//! What a derived layer was computed from, and how a derived layer follows a few cell
//! edits of its source without being computed again over the whole map.
//!
//! A derived layer carries a [`Derivation`]: the version of its source it was computed
//! from and the recipe (robot radius, lethal threshold; or compression). It is persisted
//! with the layer, so a restore can tell a derived layer that is in step with its source
//! from one that is not (a crash between the two saves, a fallback to an older copy of
//! the source, another radius in the config) and compute it again.

use std::collections::BTreeMap;

use roam_proto::cells::Cells;
use roam_proto::map::{
    GridMeta, HEURISTIC_LAYER, INFLATED_LAYER, INFORMATION_LAYER, OCCUPANCY_LAYER,
};
use serde::{Deserialize, Serialize};

use crate::edits::CellEdits;
use roam_world::grid::Grid;
use roam_world::layers;

/// The source of a derived layer: `inflated` is derived from `occupancy`, `heuristic`
/// from `information`; `None` for a layer that is not derived.
pub fn derived_source(name: &str) -> Option<&'static str> {
    match name {
        INFLATED_LAYER => Some(OCCUPANCY_LAYER),
        HEURISTIC_LAYER => Some(INFORMATION_LAYER),
        _ => None,
    }
}

/// How a derived layer is computed from its source.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Recipe {
    /// `inflated` from `occupancy` ([`layers::inflate`]).
    Inflate {
        robot_radius_m: f64,
        lethal_threshold: i8,
    },
    /// `heuristic` from `information` ([`layers::heuristic`]).
    Heuristic { compression: f64 },
}

/// The source version and recipe a derived layer was computed with.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Derivation {
    pub source_version: u64,
    pub recipe: Recipe,
}

/// Above this share of the map (1/4), a window is not worth it: inflate everything.
const WINDOW_SHARE: u64 = 4;

/// The cells of `inflated` that change when `edits` are written to `occupancy`, found
/// by inflating only a window around them: the edits' bounding box grown by twice the
/// radius (every obstacle that can reach a cell whose value may change), of which the
/// box grown by once the radius (every cell an edited cell can reach) is compared with
/// `inflated`. Exact: a cell farther than the radius from every edit keeps its value,
/// and a cell within it sees every obstacle within the radius inside the window.
/// `None` when the window would cover more than a quarter of the map, where inflating
/// the whole map is as cheap.
pub fn inflated_changes(
    meta: &GridMeta,
    occupancy: &[i8],
    inflated: &[i8],
    edits: &CellEdits,
    robot_radius_m: f64,
    lethal_threshold: i8,
) -> Option<CellEdits> {
    let Cells::I8(values) = &edits.values else {
        return None;
    };
    let meta = *meta;
    let Some((x0, y0, x1, y1)) = edits.bounds() else {
        return Some(CellEdits::empty(roam_proto::cells::Dtype::I8));
    };
    let radius_cells = (robot_radius_m / meta.resolution).max(0.0);
    if !radius_cells.is_finite() {
        return None;
    }
    // Saturating: a radius of any size (from a scenario, say) only widens the window.
    let reach = (radius_cells.ceil() as u64).saturating_add(1);
    let grow = |lo: u32, hi: u32, by: u64, size: u32| {
        (
            u64::from(lo).saturating_sub(by),
            u64::from(hi)
                .saturating_add(by)
                .min(u64::from(size).saturating_sub(1)),
        )
    };
    let (wx0, wx1) = grow(x0, x1, reach.saturating_mul(2), meta.width);
    let (wy0, wy1) = grow(y0, y1, reach.saturating_mul(2), meta.height);
    let (ww, wh) = (wx1 - wx0 + 1, wy1 - wy0 + 1);
    if ww * wh > meta.cell_count() / WINDOW_SHARE {
        return None;
    }
    let (wx0, wy0, ww, wh) = (wx0 as usize, wy0 as usize, ww as usize, wh as usize);
    let width = meta.width as usize;
    let mut window = Vec::with_capacity(ww * wh);
    for y in wy0..wy0 + wh {
        window.extend_from_slice(occupancy.get(y * width + wx0..y * width + wx0 + ww)?);
    }
    for (&(x, y), &value) in edits.positions.iter().zip(values) {
        window[(y as usize - wy0) * ww + (x as usize - wx0)] = value;
    }
    let window = Grid {
        meta: GridMeta {
            width: ww as u32,
            height: wh as u32,
            ..meta
        },
        cells: window,
    };
    let inflated_window = layers::inflate(&window, robot_radius_m, lethal_threshold);
    let (ix0, ix1) = grow(x0, x1, reach, meta.width);
    let (iy0, iy1) = grow(y0, y1, reach, meta.height);
    let mut changes = CellEdits::empty(roam_proto::cells::Dtype::I8);
    let mut new_values = Vec::new();
    for y in iy0 as usize..=iy1 as usize {
        for x in ix0 as usize..=ix1 as usize {
            let new = inflated_window.cells[(y - wy0) * ww + (x - wx0)];
            if inflated.get(y * width + x) != Some(&new) {
                changes.positions.push((x as u32, y as u32));
                new_values.push(new);
            }
        }
    }
    changes.values = Cells::I8(new_values);
    Some(changes)
}

/// The cells of `heuristic` that change when `edits` are written to `information`:
/// each block holding an edit is averaged again (bit for bit what
/// [`layers::heuristic`] gives).
pub fn heuristic_changes(
    meta: &GridMeta,
    information: &[u8],
    heuristic: &[f32],
    edits: &CellEdits,
    compression: f64,
) -> Option<CellEdits> {
    let Cells::U8(values) = &edits.values else {
        return None;
    };
    let (w, h) = (meta.width as usize, meta.height as usize);
    if information.len() != w * h {
        return None;
    }
    let block = layers::block_size(w, h, compression);
    let bw = w.div_ceil(block);
    // The last value written to each cell, grouped by block.
    let mut last: BTreeMap<(usize, usize, u32, u32), u8> = BTreeMap::new();
    for (&(x, y), &v) in edits.positions.iter().zip(values) {
        last.insert((y as usize / block, x as usize / block, x, y), v);
    }
    let mut changes = CellEdits::empty(roam_proto::cells::Dtype::F32);
    let mut new_values = Vec::new();
    let mut cursor = last.iter().peekable();
    while let Some((&(by, bx, _, _), _)) = cursor.peek() {
        let xs = bx * block..((bx + 1) * block).min(w);
        let ys = by * block..((by + 1) * block).min(h);
        let mut sum: u64 = 0;
        for y in ys.clone() {
            sum += information[y * w + xs.start..y * w + xs.end]
                .iter()
                .map(|&c| u64::from(c))
                .sum::<u64>();
        }
        while let Some((&(_, _, x, y), &v)) = cursor.next_if(|(k, _)| k.0 == by && k.1 == bx) {
            let old = information[y as usize * w + x as usize];
            sum = sum - u64::from(old) + u64::from(v);
        }
        // As `layers::heuristic` computes it, so the two agree bit for bit.
        let n = (xs.len() * ys.len()) as u32;
        let mean = if n == 0 {
            0.0
        } else {
            (sum as f64 / f64::from(n)) as f32
        };
        if heuristic.get(by * bw + bx) != Some(&mean) {
            changes.positions.push((bx as u32, by as u32));
            new_values.push(mean);
        }
    }
    changes.values = Cells::F32(new_values);
    Some(changes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use roam_proto::map::Origin;
    use roam_world::grid::occupancy;

    fn meta(w: u32, h: u32) -> GridMeta {
        GridMeta {
            width: w,
            height: h,
            resolution: 0.1,
            origin: Origin::default(),
        }
    }

    fn edits_of(writes: &[(u32, u32, i8)]) -> CellEdits {
        CellEdits {
            positions: writes.iter().map(|&(x, y, _)| (x, y)).collect(),
            values: Cells::I8(writes.iter().map(|&(_, _, v)| v).collect()),
        }
    }

    proptest! {
        /// The window gives exactly what inflating the whole edited map gives.
        #[test]
        fn windowed_inflation_equals_a_full_one(
            seed_cells in proptest::collection::vec(
                prop_oneof![20 => Just(0i8), 1 => Just(100i8), 2 => Just(-1i8), 1 => Just(70i8)],
                60 * 50,
            ),
            writes in proptest::collection::vec((0u32..60, 0u32..50, prop_oneof![Just(0i8), Just(100i8), Just(-1i8)]), 1..4),
            radius in 0.0f64..0.45,
        ) {
            let grid = Grid { meta: meta(60, 50), cells: seed_cells };
            let before = layers::inflate(&grid, radius, 65);
            let edits = edits_of(&writes);
            // No window (the edit reaches too far: the caller inflates the whole map): not
            // this property's case; rejected so that every counted case compares.
            let Some(changes) = inflated_changes(&grid.meta, &grid.cells, &before.cells, &edits, radius, 65) else {
                return Err(TestCaseError::reject("no window for this edit"));
            };
            let mut after_grid = grid.clone();
            let mut cells = Cells::I8(after_grid.cells.clone());
            edits.apply(&after_grid.meta, &mut cells);
            let Cells::I8(c) = cells else { unreachable!() };
            after_grid.cells = c;
            let full = layers::inflate(&after_grid, radius, 65);
            let mut incremental = Cells::I8(before.cells.clone());
            changes.apply(&grid.meta, &mut incremental);
            prop_assert_eq!(incremental, Cells::I8(full.cells));
        }
    }

    #[test]
    fn a_large_window_asks_for_a_full_inflation() {
        let grid = Grid::filled(meta(20, 20), occupancy::FREE);
        let before = layers::inflate(&grid, 0.2, 65);
        let edits = edits_of(&[(0, 0, 100), (19, 19, 100)]);
        assert!(
            inflated_changes(&grid.meta, &grid.cells, &before.cells, &edits, 0.2, 65).is_none()
        );
        // A radius of any size, even one no window can hold, asks for it too.
        let one = edits_of(&[(5, 5, 100)]);
        for radius in [1e9, 1e300, f64::MAX] {
            let changes =
                inflated_changes(&grid.meta, &grid.cells, &before.cells, &one, radius, 65);
            assert!(changes.is_none(), "radius {radius}");
        }
    }

    #[test]
    fn one_obstacle_changes_only_the_disc_around_it() {
        let grid = Grid::filled(meta(200, 200), occupancy::FREE);
        let before = layers::inflate(&grid, 0.2, 65);
        let changes = inflated_changes(
            &grid.meta,
            &grid.cells,
            &before.cells,
            &edits_of(&[(100, 100, 100)]),
            0.2,
            65,
        )
        .expect("a small window");
        // Radius 2 cells: the 13 lattice points within 2 of the obstacle.
        assert_eq!(changes.len(), 13);
    }

    #[test]
    fn heuristic_blocks_follow_their_edits_exactly() {
        let mut info = Grid::filled(meta(9, 7), 0u8);
        for (i, c) in info.cells.iter_mut().enumerate() {
            *c = (i * 37 % 101) as u8;
        }
        let before = layers::heuristic(&info, 0.25);
        let edits = CellEdits {
            positions: vec![(0, 0), (8, 6), (0, 0), (4, 3)],
            values: Cells::U8(vec![100, 3, 55, 0]),
        };
        let changes = heuristic_changes(&info.meta, &info.cells, &before.cells, &edits, 0.25)
            .expect("changes");
        let mut after = Cells::U8(info.cells.clone());
        edits.apply(&info.meta, &mut after);
        let Cells::U8(after) = after else {
            unreachable!()
        };
        let full = layers::heuristic(
            &Grid {
                meta: info.meta,
                cells: after,
            },
            0.25,
        );
        let mut incremental = Cells::F32(before.cells.clone());
        changes.apply(&before.meta, &mut incremental);
        assert_eq!(incremental, Cells::F32(full.cells));
    }
}
