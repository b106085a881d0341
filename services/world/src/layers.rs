//! The derived layers: inflated occupancy and the heuristic information map.

use roam_proto::map::GridMeta;

use crate::distance::squared_distance;
use crate::grid::{occupancy, Grid};

/// Marks every cell within `radius_m` of an occupied cell as occupied (100), so a
/// planner that treats the robot as a point keeps its body clear of obstacles. Unknown
/// cells stay unknown unless an obstacle inflates over them; free cells stay free.
/// A cell counts as an obstacle when its value is at least `occupied_min` (Nav2's
/// lethal threshold; 65 by default, i.e. `occupied_thresh`).
pub fn inflate(occupancy_grid: &Grid<i8>, radius_m: f64, occupied_min: i8) -> Grid<i8> {
    let (w, h) = (occupancy_grid.width(), occupancy_grid.height());
    let is_obstacle = |i: usize| occupancy_grid.cells[i] >= occupied_min;
    let radius_cells = (radius_m / occupancy_grid.meta.resolution).max(0.0);
    let limit = (radius_cells * radius_cells) as f32;
    let d2 = squared_distance(w, h, is_obstacle);
    let cells = occupancy_grid
        .cells
        .iter()
        .zip(&d2)
        .map(|(&c, &d)| {
            if c >= occupied_min || d <= limit {
                occupancy::OCCUPIED
            } else if c == occupancy::UNKNOWN {
                occupancy::UNKNOWN
            } else {
                occupancy::FREE
            }
        })
        .collect();
    Grid {
        meta: occupancy_grid.meta,
        cells,
    }
}

/// The heuristic information map of paper 000 §II.B.3 (its Fig. 2): the mean
/// information score H of square blocks of the information map.
///
/// Ambiguity (paper 000 §II.B.3): the paper calls the compression c_h "the inverse of the
/// number of cells along one edge of the heuristic map" (c_h = 1/4 gives a 4 × 4
/// heuristic map, and its Fig. 2 and Table I agree) but also says a lower c_h gives
/// larger areas. roam follows the definition and the figure: the longer map edge is
/// cut into `round(1 / c_h)` blocks, blocks are square, and the blocks of the shorter
/// edge cover it with the same block size (the last block may be partial). Each block
/// holds the mean of the cells it covers inside the map.
pub fn heuristic(information: &Grid<u8>, compression: f64) -> Grid<f32> {
    let (w, h) = (information.width(), information.height());
    let block = block_size(w, h, compression);
    let (bw, bh) = (w.div_ceil(block), h.div_ceil(block));
    let mut sums = vec![0u64; bw * bh];
    let mut counts = vec![0u32; bw * bh];
    for y in 0..h {
        for x in 0..w {
            let b = (y / block) * bw + x / block;
            sums[b] += u64::from(information.cells[y * w + x]);
            counts[b] += 1;
        }
    }
    let cells = sums
        .iter()
        .zip(&counts)
        .map(|(&s, &n)| {
            if n == 0 {
                0.0
            } else {
                (s as f64 / f64::from(n)) as f32
            }
        })
        .collect();
    Grid {
        meta: GridMeta {
            width: bw as u32,
            height: bh as u32,
            resolution: information.meta.resolution * block as f64,
            origin: information.meta.origin,
        },
        cells,
    }
}

/// The edge of one heuristic block in cells, for a `w × h` map at compression `c_h`.
pub fn block_size(w: usize, h: usize, compression: f64) -> usize {
    let blocks_per_edge = (1.0 / compression).round().max(1.0) as usize;
    w.max(h).div_ceil(blocks_per_edge).max(1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_proto::map::Origin;

    fn meta(width: u32, height: u32) -> GridMeta {
        GridMeta {
            width,
            height,
            resolution: 0.1,
            origin: Origin::default(),
        }
    }

    #[test]
    fn inflation_covers_the_radius_and_no_more() {
        let mut grid = Grid::filled(meta(21, 21), occupancy::FREE);
        grid.cells[10 * 21 + 10] = occupancy::OCCUPIED;
        grid.cells[0] = occupancy::UNKNOWN;
        let inflated = inflate(&grid, 0.3, 65);
        // 3 cells away straight is inside, (3,1) is sqrt(10) > 3 cells and outside.
        assert_eq!(inflated.get(13, 10), Some(occupancy::OCCUPIED));
        assert_eq!(inflated.get(10, 7), Some(occupancy::OCCUPIED));
        assert_eq!(inflated.get(13, 11), Some(occupancy::FREE));
        assert_eq!(inflated.get(14, 10), Some(occupancy::FREE));
        assert_eq!(inflated.get(0, 0), Some(occupancy::UNKNOWN));
        let occupied = inflated
            .cells
            .iter()
            .filter(|&&c| c == occupancy::OCCUPIED)
            .count();
        // Lattice points within radius 3: 29.
        assert_eq!(occupied, 29);
    }

    #[test]
    fn heuristic_averages_square_blocks() {
        // 8 × 4 map at c_h = 1/4: blocks of 2 × 2 cells, a 4 × 2 heuristic map.
        let mut info = Grid::filled(meta(8, 4), 0u8);
        for x in 0..2 {
            for y in 0..2 {
                info.cells[y * 8 + x] = 100;
            }
        }
        info.cells[2] = 40;
        let h = heuristic(&info, 0.25);
        assert_eq!((h.meta.width, h.meta.height), (4, 2));
        assert!((h.meta.resolution - 0.2).abs() < 1e-12);
        assert_eq!(h.cells[0], 100.0);
        assert_eq!(h.cells[1], 10.0);
        assert_eq!(h.cells[4], 0.0);
    }

    #[test]
    fn partial_edge_blocks_average_only_their_cells() {
        let info = Grid::filled(meta(5, 5), 50u8);
        let h = heuristic(&info, 0.5); // blocks of 3: 2 × 2 heuristic cells
        assert_eq!((h.meta.width, h.meta.height), (2, 2));
        assert!(h.cells.iter().all(|&v| v == 50.0));
    }
}
