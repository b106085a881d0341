//! What the window computes itself, without the planner: the fastest path from where the
//! robot is (the last-safe-moment rule, and the way on when no planner answers), the
//! point on its route where a replan should start, and the way back to its last fix.

use roam_planner::params::GaParams;
use roam_planner::search::fastest_path;

use super::Route;
use crate::calibration::TimeModel;
use crate::information::InformationScale;
use crate::path::distance;

/// The fastest path from `from` to `to` on the scale's map under `model` (paper 000
/// Eq. 2 with turns, the planner's own search): the route and its ETA. `None` when
/// either end is not a free cell or the task cannot be reached.
pub(super) fn fastest_route(
    scale: &InformationScale<'_>,
    model: TimeModel,
    from: [f64; 2],
    to: [f64; 2],
) -> Option<Route> {
    let world = scale.world;
    let start = world.cell_at(from[0], from[1])?;
    let goal = world.cell_at(to[0], to[1])?;
    let params = GaParams {
        v_lin: model.v_lin,
        v_ang: model.v_ang,
        ..scale.params.clone()
    };
    let cells = fastest_path(world, &params, start, goal)?;
    let t_eta_s = roam_planner::eta::path_eta(world, &params, &cells);
    Some(Route {
        points: world.centers(&cells),
        t_eta_s,
        curious: false,
    })
}

/// The point `lead_m` further along `path` than the path's point nearest to `here`
/// (its last point when the path is shorter): where the robot will be when a plan asked
/// now comes, if it drives on.
pub(super) fn point_ahead(path: &[[f64; 2]], here: [f64; 2], lead_m: f64) -> [f64; 2] {
    let Some(nearest) = (0..path.len())
        .min_by(|&a, &b| distance(path[a], here).total_cmp(&distance(path[b], here)))
    else {
        return here;
    };
    let mut left = lead_m.max(0.0);
    let mut at = path[nearest];
    for next in &path[nearest + 1..] {
        let step = distance(at, *next);
        if step >= left {
            let t = if step > 0.0 { left / step } else { 0.0 };
            return [at[0] + t * (next[0] - at[0]), at[1] + t * (next[1] - at[1])];
        }
        left -= step;
        at = *next;
    }
    at
}

/// The way back along `driven` (oldest first) from its end to its point `to_index`: the
/// points in reverse, the robot's own track to where it last had a fix.
pub(super) fn back_along(driven: &[[f64; 2]], to_index: usize) -> Vec<[f64; 2]> {
    driven[to_index.min(driven.len())..]
        .iter()
        .rev()
        .copied()
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_point_ahead_walks_the_path_from_the_nearest_point() {
        let path = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0]];
        assert_eq!(point_ahead(&path, [0.1, 0.2], 1.0), [1.0, 0.0]);
        assert_eq!(point_ahead(&path, [1.9, 0.1], 1.5), [2.0, 1.5]);
        assert_eq!(point_ahead(&path, [0.0, 0.0], 10.0), [2.0, 2.0]);
        assert_eq!(point_ahead(&[], [3.0, 3.0], 1.0), [3.0, 3.0]);
    }

    #[test]
    fn the_way_back_is_the_track_reversed_to_the_fix() {
        let driven = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]];
        assert_eq!(
            back_along(&driven, 1),
            vec![[3.0, 0.0], [2.0, 0.0], [1.0, 0.0]]
        );
        assert!(back_along(&driven, 9).is_empty());
    }
}
