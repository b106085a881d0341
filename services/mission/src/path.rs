//! Turning a planned path into the controller's waypoints, and watching the robot
//! against it.

use roam_proto::controller::MAX_WAYPOINTS;

/// The controller's waypoints for a planned path, at most [`MAX_WAYPOINTS`] (the
/// mission message's limit): [`waypoints_within`] with that limit.
pub fn mission_waypoints(points: &[[f64; 2]], max_spacing_m: f64) -> Vec<[f64; 2]> {
    waypoints_within(points, max_spacing_m, MAX_WAYPOINTS)
}

/// The waypoints of a planned path (cell centres, 8-connected) for a controller that
/// drives it as planned (`follow: path`, pure pursuit on the polyline of the robot's
/// position and the waypoints), at most `max_points` of them.
///
/// **Only what is straight is thinned.** A point is left out only when the path goes on
/// through it in the same direction (the step into it and the step out of it are
/// parallel and the same way), so every point where the path turns is kept and the
/// polyline of the waypoints *is* the planned path: no detour the planner made, however
/// small, is cut, and waypoints are never farther apart than the path bends. A straight
/// run keeps a point at least every `max_spacing_m` (so a controller that follows
/// waypoints one by one sees the path too). The first point, the cell the robot plans
/// from, is left out (the controller's path starts where the robot is) unless it is the
/// only one; the last is always kept.
///
/// **A path with more turns than `max_points`** (a long path on a large map; the
/// built-in world's have a few hundred) cannot be sent whole: it is then resampled
/// into `max_points` points evenly spaced along its length, the last one its end.
/// Between those the controller drives straight, so a detour shorter than the spacing
/// (the path's length / `max_points`) is cut there, and only there.
pub fn waypoints_within(
    points: &[[f64; 2]],
    max_spacing_m: f64,
    max_points: usize,
) -> Vec<[f64; 2]> {
    let (Some(&first), Some(&last)) = (points.first(), points.last()) else {
        return Vec::new();
    };
    if points.len() == 1 {
        return vec![first];
    }
    let mut out = Vec::new();
    let mut kept = first;
    for (i, &p) in points.iter().enumerate().skip(1) {
        let end = i + 1 == points.len();
        let turn = !end && !straight_on(points[i - 1], p, points[i + 1]);
        // A point beyond the spacing from the last kept one: keep the one before it.
        if distance(kept, p) > max_spacing_m && i >= 2 && points[i - 1] != kept {
            kept = points[i - 1];
            out.push(kept);
        }
        if end || turn {
            kept = p;
            out.push(p);
        }
    }
    let max_points = max_points.max(1);
    if out.len() > max_points {
        let polyline: Vec<[f64; 2]> = std::iter::once(first).chain(out).collect();
        return resample(&polyline, max_points, last);
    }
    out
}

/// Whether the path goes straight on through `b`: a → b and b → c are parallel and the
/// same way (within rounding; a repeated point counts as straight on).
fn straight_on(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> bool {
    let (u, v) = ([b[0] - a[0], b[1] - a[1]], [c[0] - b[0], c[1] - b[1]]);
    let (nu, nv) = (u[0].hypot(u[1]), v[0].hypot(v[1]));
    if nu == 0.0 || nv == 0.0 {
        return true;
    }
    let cross = u[0] * v[1] - u[1] * v[0];
    let dot = u[0] * v[0] + u[1] * v[1];
    cross.abs() <= 1e-9 * nu * nv && dot > 0.0
}

/// `n` points evenly spaced along the polyline `points` (its length / n apart, the
/// first one that far from its start), the last one `end`.
fn resample(points: &[[f64; 2]], n: usize, end: [f64; 2]) -> Vec<[f64; 2]> {
    let total: f64 = points.windows(2).map(|s| distance(s[0], s[1])).sum();
    let mut out = Vec::with_capacity(n);
    let mut segment = 0;
    let mut start = 0.0; // arc length at points[segment]
    for k in 1..n {
        let s = total * k as f64 / n as f64;
        while segment + 2 < points.len()
            && start + distance(points[segment], points[segment + 1]) < s
        {
            start += distance(points[segment], points[segment + 1]);
            segment += 1;
        }
        let (a, b) = (points[segment], points[(segment + 1).min(points.len() - 1)]);
        let len = distance(a, b);
        let t = if len > 0.0 {
            ((s - start) / len).clamp(0.0, 1.0)
        } else {
            0.0
        };
        out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
    }
    out.push(end);
    out
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

    /// An 8-connected cell path from `from` (0.2 m cells) by unit steps.
    fn cells(from: [f64; 2], steps: &[(i32, i32)]) -> Vec<[f64; 2]> {
        let mut p = from;
        let mut out = vec![p];
        for &(dx, dy) in steps {
            p = [p[0] + 0.2 * f64::from(dx), p[1] + 0.2 * f64::from(dy)];
            out.push(p);
        }
        out
    }

    fn repeat(step: (i32, i32), n: usize) -> Vec<(i32, i32)> {
        vec![step; n]
    }

    /// The largest distance from a point of `path` to the polyline `first` + `kept`.
    fn cut(path: &[[f64; 2]], kept: &[[f64; 2]]) -> f64 {
        let polyline: Vec<[f64; 2]> = std::iter::once(path[0])
            .chain(kept.iter().copied())
            .collect();
        path.iter()
            .map(|&p| off_path_m(p, &polyline))
            .fold(0.0, f64::max)
    }

    #[test]
    fn a_straight_path_keeps_a_point_every_spacing_and_the_end() {
        let points = cells([0.0, 0.0], &repeat((1, 0), 10));
        let kept = waypoints_within(&points, 1.0, 100);
        assert_eq!(kept.len(), 2);
        assert!((kept[0][0] - 1.0).abs() < 1e-9);
        assert!((kept[1][0] - 2.0).abs() < 1e-9);
        assert_eq!(waypoints_within(&points[..1], 1.0, 100), vec![[0.0, 0.0]]);
        assert!(waypoints_within(&[], 1.0, 100).is_empty());
    }

    #[test]
    fn a_zig_zag_keeps_every_corner_and_cuts_no_detour() {
        // East, a diagonal tooth north-east and back south-east, east, a square detour
        // north and back, east: in open space, where a line-of-sight thinning would go
        // straight from end to end.
        let mut steps = repeat((1, 0), 3);
        steps.extend(repeat((1, 1), 3));
        steps.extend(repeat((1, -1), 3));
        steps.extend(repeat((1, 0), 2));
        steps.extend(repeat((0, 1), 4));
        steps.extend(repeat((1, 0), 2));
        steps.extend(repeat((0, -1), 4));
        steps.extend(repeat((1, 0), 3));
        let points = cells([0.0, 0.0], &steps);
        let kept = waypoints_within(&points, 1.0, 100);
        // Every corner is a waypoint, in order.
        let corners: Vec<usize> = (1..points.len() - 1)
            .filter(|&i| !straight_on(points[i - 1], points[i], points[i + 1]))
            .collect();
        assert_eq!(corners.len(), 7);
        let mut at = 0;
        for &c in &corners {
            let found = kept[at..]
                .iter()
                .position(|&k| distance(k, points[c]) < 1e-9)
                .unwrap_or_else(|| panic!("corner {c} {:?} was cut", points[c]));
            at += found + 1;
        }
        // The waypoints' polyline is the planned path: no point of it is off.
        assert!(cut(&points, &kept) < 1e-9, "{}", cut(&points, &kept));
        // Only straight runs were thinned, and none is longer than the 1 m spacing: the
        // waypoints are the corners and the end.
        assert_eq!(kept.len(), corners.len() + 1);
        assert_eq!(kept.last(), points.last());
    }

    #[test]
    fn a_staircase_keeps_every_stair() {
        // East, north-east, east, north-east...: every point is a turn.
        let steps: Vec<(i32, i32)> = (0..20)
            .map(|i| if i % 2 == 0 { (1, 0) } else { (1, 1) })
            .collect();
        let points = cells([1.0, 1.0], &steps);
        let kept = waypoints_within(&points, 1.0, 100);
        assert_eq!(kept, points[1..].to_vec());
    }

    #[test]
    fn a_path_with_more_turns_than_the_limit_is_resampled_evenly() {
        // 40 stairs (41 waypoints) into at most 10: evenly spaced along the length.
        let steps: Vec<(i32, i32)> = (0..40)
            .map(|i| if i % 2 == 0 { (1, 0) } else { (0, 1) })
            .collect();
        let points = cells([0.0, 0.0], &steps);
        assert_eq!(waypoints_within(&points, 1.0, 100).len(), 40);
        let kept = waypoints_within(&points, 1.0, 10);
        assert_eq!(kept.len(), 10);
        assert_eq!(kept.last(), points.last());
        // 8 m of path in 10 pieces of 0.8 m: each waypoint is on the path, at 0.8 k m.
        for (k, w) in kept.iter().enumerate() {
            assert!(off_path_m(*w, &points) < 1e-9, "{w:?} is off the path");
            let along = 0.8 * (k + 1) as f64;
            let n = (along / 0.2).floor() as usize;
            let rest = along - 0.2 * n as f64;
            let expect = if n + 1 < points.len() {
                let (a, b) = (points[n], points[n + 1]);
                [
                    a[0] + (b[0] - a[0]) * rest / 0.2,
                    a[1] + (b[1] - a[1]) * rest / 0.2,
                ]
            } else {
                points[points.len() - 1]
            };
            assert!(distance(*w, expect) < 1e-9, "{k}: {w:?} != {expect:?}");
        }
        assert_eq!(mission_waypoints(&points, 1.0).len(), 40);
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
