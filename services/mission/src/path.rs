//! Turning a planned path into the controller's waypoints, and watching the robot
//! against it.

/// Thins a planned path (cell centres, 8-connected) into waypoints for the controller:
/// from each kept point, the farthest later point that is at most `max_spacing_m` away
/// and in a straight line of free space (`clear(a, b)`), always keeping the last. The
/// controller then drives straight between waypoints, where the planner's path had
/// a point every cell; corners are kept because a corner's diagonal is not clear.
pub fn thin(
    points: &[[f64; 2]],
    max_spacing_m: f64,
    clear: impl Fn([f64; 2], [f64; 2]) -> bool,
) -> Vec<[f64; 2]> {
    let mut out = Vec::new();
    let Some(&first) = points.first() else {
        return out;
    };
    let mut from = 0;
    let mut anchor = first;
    while from + 1 < points.len() {
        let mut next = from + 1;
        for (j, &p) in points.iter().enumerate().skip(from + 2) {
            if distance(anchor, p) > max_spacing_m || !clear(anchor, p) {
                break;
            }
            next = j;
        }
        anchor = points[next];
        out.push(anchor);
        from = next;
    }
    if out.is_empty() {
        out.push(first);
    }
    out
}

/// Whether the straight segment a→b stays on traversable cells of the planning grid
/// (sampled every half cell).
pub fn clear(world: &roam_planner::world::World, a: [f64; 2], b: [f64; 2]) -> bool {
    let step = world.meta.resolution / 2.0;
    let n = (distance(a, b) / step).ceil().max(1.0) as usize;
    (0..=n).all(|i| {
        let t = i as f64 / n as f64;
        world
            .cell_at(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]))
            .is_some_and(|c| world.is_traversable(c))
    })
}

pub fn distance(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// The distance from `p` to the polyline `path` (to its single point if it has one).
pub fn off_path_m(p: [f64; 2], path: &[[f64; 2]]) -> f64 {
    match path {
        [] => f64::INFINITY,
        [only] => distance(p, *only),
        _ => path
            .windows(2)
            .map(|s| to_segment(p, s[0], s[1]))
            .fold(f64::INFINITY, f64::min),
    }
}

fn to_segment(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    if len2 == 0.0 {
        return distance(p, a);
    }
    let t = (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0);
    distance(p, [a[0] + t * dx, a[1] + t * dy])
}

/// Whether the robot, `distance_left_m` from its task at `speed_m_per_s`, would arrive
/// after `task_start_s` if it left at `now_s`: the executive then replans the shortest
/// way.
pub fn eta_slips(now_s: f64, distance_left_m: f64, speed_m_per_s: f64, task_start_s: f64) -> bool {
    now_s + distance_left_m / speed_m_per_s > task_start_s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_straight_path_thins_to_spaced_points_and_keeps_the_end() {
        let points: Vec<[f64; 2]> = (0..=10).map(|i| [f64::from(i) * 0.2, 0.0]).collect();
        let thinned = thin(&points, 1.0, |_, _| true);
        assert_eq!(thinned.len(), 2);
        assert!((thinned[0][0] - 1.0).abs() < 1e-9);
        assert_eq!(thinned[1], [2.0, 0.0]);
    }

    #[test]
    fn a_corner_is_kept_when_its_diagonal_is_blocked() {
        // An L: east 1 m, then north 1 m; nothing may cut the corner.
        let mut points: Vec<[f64; 2]> = (0..=5).map(|i| [f64::from(i) * 0.2, 0.0]).collect();
        points.extend((1..=5).map(|i| [1.0, f64::from(i) * 0.2]));
        let straight = |a: [f64; 2], b: [f64; 2]| a[0] == b[0] || a[1] == b[1];
        let thinned = thin(&points, 5.0, straight);
        assert_eq!(thinned, vec![[1.0, 0.0], [1.0, 1.0]]);
    }

    #[test]
    fn off_path_distance_and_eta_slip_by_hand() {
        let path = [[0.0, 0.0], [4.0, 0.0], [4.0, 4.0]];
        assert!((off_path_m([2.0, 1.5], &path) - 1.5).abs() < 1e-12);
        assert!((off_path_m([5.0, 2.0], &path) - 1.0).abs() < 1e-12);
        assert!((off_path_m([-3.0, 4.0], &path) - 5.0).abs() < 1e-12);
        // 10 m at 0.5 m/s is 20 s: from 50 s that is 70 s.
        assert!(!eta_slips(50.0, 10.0, 0.5, 70.0));
        assert!(eta_slips(50.1, 10.0, 0.5, 70.0));
    }
}
