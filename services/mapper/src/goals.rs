//! Goal sampling from a coarsened weight map (paper 004 §3): "this distribution is
//! discretized more coarsely by grouping square patches … together and averaging their
//! values, in order to smooth out noise".
//!
//! - The map is cut into square patches of `patch_cells` cells from the origin (the
//!   last row and column of patches may be smaller). The paper does not give the size;
//!   roam's default is 3 cells: on the 25 × 25 grid world that gives 9 × 9 patches, each
//!   the size of a block's 2 × 2 footprint plus its neighbours, so a block's cells and
//!   the free cells around them share a patch and the robot is sent *next to* the
//!   change rather than onto the block.
//! - A patch weighs the mean of its cells' weights (all its cells, walls included: the
//!   mean is the smoothing), or 0 when it has no cell a goal may be on. Negative,
//!   non-finite or NaN weights count as 0.
//! - A patch is drawn ∝ its weight, then a cell in it uniformly among the cells that are
//!   not known occupied (free or unknown: an unknown cell is a fine thing to go and see).
//! - When every patch weighs 0 (no change seen yet for the change-based strategy), the
//!   goal is uniform over the known-free cells, or over the cells not known occupied if
//!   none is known free: that is the "random zig-zag until a first change is detected"
//!   of §5.
//!
//! Every draw comes from the caller's seeded stream.

use rand::{Rng, RngCore};
use roam_world::grid::occupancy;

/// The default patch side, cells.
pub const DEFAULT_PATCH_CELLS: u32 = 3;

/// Whether a goal may be put on a cell with this obstacle value.
fn goal_allowed(value: i8) -> bool {
    value != occupancy::OCCUPIED
}

/// Draws a goal cell from `weights` (one per cell, row-major, as `obstacles`) on a
/// `width × height` map coarsened into patches of `patch_cells` (at least 1). `None`
/// only when every cell is known occupied.
pub fn sample_goal(
    weights: &[f64],
    obstacles: &[i8],
    width: u32,
    height: u32,
    patch_cells: u32,
    rng: &mut impl RngCore,
) -> Option<(u32, u32)> {
    let n = (width as usize * height as usize)
        .min(weights.len())
        .min(obstacles.len());
    if n == 0 || width == 0 {
        return None;
    }
    let s = patch_cells.max(1);
    let (px, py) = (width.div_ceil(s), height.div_ceil(s));
    let patch_cells_of = |p: usize| {
        let (x0, y0) = ((p as u32 % px) * s, (p as u32 / px) * s);
        let (x1, y1) = ((x0 + s).min(width), (y0 + s).min(height));
        (y0..y1).flat_map(move |y| (x0..x1).map(move |x| (x, y)))
    };
    let index = |(x, y): (u32, u32)| y as usize * width as usize + x as usize;
    let patches = px as usize * py as usize;
    let mut cumulative = Vec::with_capacity(patches);
    let mut total = 0.0;
    for p in 0..patches {
        let (mut sum, mut count, mut allowed) = (0.0, 0usize, false);
        for c in patch_cells_of(p) {
            let i = index(c);
            if i >= n {
                continue;
            }
            let w = weights[i];
            sum += if w.is_finite() && w > 0.0 { w } else { 0.0 };
            count += 1;
            allowed |= goal_allowed(obstacles[i]);
        }
        if allowed && count > 0 {
            total += sum / count as f64;
        }
        cumulative.push(total);
    }
    if total > 0.0 && total.is_finite() {
        let u = rng.random::<f64>() * total;
        let p = cumulative.partition_point(|&c| c <= u).min(patches - 1);
        let cells: Vec<_> = patch_cells_of(p)
            .filter(|&c| index(c) < n && goal_allowed(obstacles[index(c)]))
            .collect();
        if !cells.is_empty() {
            return Some(cells[rng.random_range(0..cells.len())]);
        }
    }
    let cell_of = |i: usize| ((i % width as usize) as u32, (i / width as usize) as u32);
    let free: Vec<usize> = (0..n)
        .filter(|&i| obstacles[i] == occupancy::FREE)
        .collect();
    let pool = if free.is_empty() {
        (0..n).filter(|&i| goal_allowed(obstacles[i])).collect()
    } else {
        free
    };
    if pool.is_empty() {
        return None;
    }
    Some(cell_of(pool[rng.random_range(0..pool.len())]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seed::stream;

    #[test]
    fn patches_are_drawn_by_their_mean_weight() {
        // 6 x 3 map, patches of 3: left patch (x 0..3) and right patch (x 3..6).
        // Left: one cell of weight 9 → mean 1. Right: every cell 2 → mean 2.
        let (w, h) = (6u32, 3u32);
        let mut weights = vec![0.0; 18];
        weights[0] = 9.0;
        for y in 0..3 {
            for x in 3..6 {
                weights[y * 6 + x] = 2.0;
            }
        }
        let obstacles = vec![0i8; 18];
        let mut rng = stream(1, "goals");
        let n = 30_000;
        let right = (0..n)
            .filter_map(|_| sample_goal(&weights, &obstacles, w, h, 3, &mut rng))
            .filter(|&(x, _)| x >= 3)
            .count();
        let share = right as f64 / n as f64;
        assert!((share - 2.0 / 3.0).abs() < 0.015, "{share}");
    }

    #[test]
    fn goals_avoid_known_obstacles_and_fall_back_to_free_cells() {
        // 3 x 1, one patch; the weighted cell is a wall: the goal is one of the others.
        let weights = [0.0, 0.0, 5.0];
        let obstacles = [0i8, -1, 100];
        let mut rng = stream(2, "goals");
        for _ in 0..200 {
            let g = sample_goal(&weights, &obstacles, 3, 1, 3, &mut rng).expect("goal");
            assert!(g == (0, 0) || g == (1, 0), "{g:?}");
        }
        // All weights zero: uniform over the known-free cells only.
        for _ in 0..200 {
            assert_eq!(
                sample_goal(&[0.0; 3], &obstacles, 3, 1, 3, &mut rng),
                Some((0, 0))
            );
        }
        // No free cell known: any cell not known occupied.
        assert_eq!(
            sample_goal(&[0.0; 3], &[-1, 100, 100], 3, 1, 2, &mut rng),
            Some((0, 0))
        );
        assert_eq!(sample_goal(&[1.0; 2], &[100, 100], 2, 1, 1, &mut rng), None);
        // A patch made only of walls never wins, whatever its weight.
        let g = sample_goal(&[0.0, f64::NAN, 1e9], &[0, 0, 100], 3, 1, 1, &mut rng);
        assert!(matches!(g, Some((0, 0)) | Some((1, 0))), "{g:?}");
    }
}
