//! What the window computes itself, without the planner: the fastest path from where the
//! robot is (the last-safe-moment rule, and the way on when no planner answers), the
//! point on its route where a replan should start, and the way back to its last fix.

use roam_planner::params::GaParams;
use roam_planner::search::fastest_path;

use super::routes::Route;
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
    let Some(nearest) = nearest(path, here) else {
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

/// The index of `path`'s point nearest to `here` (the first of equals).
pub(super) fn nearest(path: &[[f64; 2]], here: [f64; 2]) -> Option<usize> {
    (0..path.len()).min_by(|&a, &b| distance(path[a], here).total_cmp(&distance(path[b], here)))
}

/// What is left of `path` from `here`: `here`, then the path from its point nearest to
/// `here` on.
pub(super) fn route_left(path: &[[f64; 2]], here: [f64; 2]) -> Vec<[f64; 2]> {
    let from = nearest(path, here).unwrap_or(path.len());
    std::iter::once(here)
        .chain(path[from..].iter().copied())
        .collect()
}

/// The way back along `driven` (oldest first) from its end past its point `fix` (the
/// last with a fix) until at least `back_m` metres were covered: the robot's own track
/// in reverse, to where it last had a fix and a little beyond.
pub(super) fn back_along(driven: &[[f64; 2]], fix: usize, back_m: f64) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = Vec::new();
    let mut covered = 0.0;
    for (i, &p) in driven.iter().enumerate().rev() {
        if let Some(&last) = out.last() {
            covered += distance(last, p);
        }
        out.push(p);
        if i <= fix && covered >= back_m {
            break;
        }
    }
    out
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
    fn the_way_back_is_the_track_reversed_past_the_fix() {
        let driven = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]];
        assert_eq!(
            back_along(&driven, 2, 0.5),
            vec![[3.0, 0.0], [2.0, 0.0]],
            "to the fix, far enough already"
        );
        // The fix is where the track ends (the estimate froze there): back 1.5 m more.
        assert_eq!(
            back_along(&driven, 3, 1.5),
            vec![[3.0, 0.0], [2.0, 0.0], [1.0, 0.0]]
        );
        assert_eq!(
            back_along(&driven, 3, 10.0).len(),
            4,
            "at most the whole track"
        );
        assert!(back_along(&[], 0, 1.0).is_empty());
    }
}
