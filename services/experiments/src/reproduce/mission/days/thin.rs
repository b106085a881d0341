//! Today's waypoints: how the executive made a plan into a mission before it sent every
//! turn (`path::mission_waypoints`, commit d1bf322), kept here as the baseline `today`
//! drives. The controller then drives straight from waypoint to waypoint (`follow:
//! waypoints`), which cuts the GA path's small detours.

use roam_planner::world::World;

use roam_mission::path::distance;

/// Thins a planned path (cell centres, 8-connected) into waypoints: from each kept
/// point, the farthest later point that is at most `max_spacing_m` away and in a
/// straight line of free space (`clear(a, b)`), always keeping the last. A corner is
/// kept because its diagonal is not clear.
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

/// Whether the straight segment a → b stays on traversable cells of the planning grid
/// (sampled every half cell).
pub fn clear(world: &World, a: [f64; 2], b: [f64; 2]) -> bool {
    let step = world.meta.resolution / 2.0;
    let n = (distance(a, b) / step).ceil().max(1.0) as usize;
    (0..=n).all(|i| {
        let t = i as f64 / n as f64;
        world
            .cell_at(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]))
            .is_some_and(|c| world.is_traversable(c))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn straight_runs_thin_to_the_spacing_and_a_blocked_corner_is_kept() {
        // An L: 10 cells east, then 10 north, 0.2 m apart.
        let mut points: Vec<[f64; 2]> = (0..=10).map(|i| [0.2 * f64::from(i), 0.0]).collect();
        points.extend((1..=10).map(|i| [2.0, 0.2 * f64::from(i)]));
        // The inside of the corner is a wall: nothing cuts across it.
        let inside = |p: [f64; 2]| p[0] < 1.99 && p[1] > 0.01;
        let cuts_corner =
            |a: [f64; 2], b: [f64; 2]| a[1] < 0.01 && a[0] < 1.99 && b[0] > 1.99 && b[1] > 0.01;
        let open = |a: [f64; 2], b: [f64; 2]| !(inside(a) || inside(b) || cuts_corner(a, b));
        let w = thin(&points, 1.0, open);
        assert_eq!(w.last(), points.last());
        assert!(w.contains(&[2.0, 0.0]), "the corner is kept: {w:?}");
        for pair in std::iter::once(points[0])
            .chain(w.iter().copied())
            .collect::<Vec<_>>()
            .windows(2)
        {
            assert!(distance(pair[0], pair[1]) <= 1.0 + 1e-9, "{pair:?}");
        }
        assert!(w.len() <= 6, "thinned: {w:?}");
        assert_eq!(thin(&[[1.0, 1.0]], 1.0, open), vec![[1.0, 1.0]]);
        assert!(thin(&[], 1.0, open).is_empty());
    }
}
