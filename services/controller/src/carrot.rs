//! Following a mission's path as a path: pure pursuit on the polyline of its points.
//!
//! Paper 002's attractive force f_a (§3, Eq. 3) pulls toward "a mission waypoint". When
//! the waypoints are a planned path (a curious GA path, paper 000, every cell of it),
//! what matters is the path between them: a robot that drives straight from one
//! waypoint toward the next cuts every detour the plan made, and the detours are where
//! the information is. So, with `follow: path`, the point f_a pulls toward is a
//! *carrot*: the point a lookahead distance L ahead, along the polyline, of the robot's
//! projection onto it. The repulsive force f_Tr and the information-seeking force f_is
//! act as before, and the adaptive weight z_isa(ω) (Eq. 2) is taken against this f_a.
//!
//! **The projection is monotone and searched forward only.** [`PathTracker::pursue`]
//! looks for the robot's nearest point on the polyline starting at the last projection
//! and never behind it, walking segment by segment while the next one is no farther
//! than the best so far (so it stops at the first local minimum of the distance), and
//! never more than a window of arc length ahead. A path that comes back near itself (a
//! U turn, a loop that crosses itself) is therefore followed in order: the later pass
//! is beyond a stretch that is farther from the robot, so the walk never reaches it
//! before the robot has driven the stretch in between.
//!
//! **At the end** the carrot is clamped at the last point; the mission is complete when
//! the carrot is there and the robot is within g_thres of it.

/// A polyline followed in order, and how far along it the robot is.
#[derive(Debug, Clone, PartialEq)]
pub struct PathTracker {
    points: Vec<[f64; 2]>,
    /// `arc[i]`: the length of the polyline from `points[0]` to `points[i]`, metres.
    arc: Vec<f64>,
    /// The segment `points[segment] → points[segment + 1]` the last projection lies on
    /// (0 for a one-point path).
    segment: usize,
    /// The arc length of the last projection, metres.
    progress_m: f64,
}

/// What [`PathTracker::pursue`] found for one position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pursuit {
    /// The robot's projection onto the path: its nearest point in the forward window.
    pub projection: [f64; 2],
    /// The projection's arc length from the path's first point, metres; never less than
    /// the previous one's.
    pub progress_m: f64,
    /// The carrot: the point `lookahead_m` along the path beyond the projection, or the
    /// path's last point when that is nearer.
    pub carrot: [f64; 2],
    /// The carrot is the path's last point (the lookahead reaches its end).
    pub at_end: bool,
    /// The index of the first path point ahead of the projection (the end of its
    /// segment; the last point's index once the projection is on the last segment).
    pub next_point: usize,
    /// From the robot to its projection, then along the rest of the path, metres.
    pub distance_left_m: f64,
}

/// A path that cannot be followed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PathError {
    #[error("a path to follow needs at least one point")]
    Empty,
    #[error("path point {index} ({point:?}) is not a finite point")]
    NotFinite { index: usize, point: [f64; 2] },
}

/// The nearest point to a position on one piece of a segment.
#[derive(Debug, Clone, Copy)]
struct Nearest {
    distance: f64,
    arc: f64,
}

fn distance(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

impl PathTracker {
    /// A tracker at the start of the polyline through `points`, in order.
    pub fn new(points: Vec<[f64; 2]>) -> Result<PathTracker, PathError> {
        if points.is_empty() {
            return Err(PathError::Empty);
        }
        if let Some((index, &point)) = points
            .iter()
            .enumerate()
            .find(|(_, p)| !(p[0].is_finite() && p[1].is_finite()))
        {
            return Err(PathError::NotFinite { index, point });
        }
        let mut arc = Vec::with_capacity(points.len());
        let mut total = 0.0;
        arc.push(0.0);
        for pair in points.windows(2) {
            total += distance(pair[0], pair[1]);
            arc.push(total);
        }
        Ok(PathTracker {
            points,
            arc,
            segment: 0,
            progress_m: 0.0,
        })
    }

    /// The polyline's points, in the order they are followed.
    pub fn points(&self) -> &[[f64; 2]] {
        &self.points
    }

    /// The polyline's length, metres.
    pub fn length_m(&self) -> f64 {
        self.arc.last().copied().unwrap_or(0.0)
    }

    /// The last projection's arc length, metres.
    pub fn progress_m(&self) -> f64 {
        self.progress_m
    }

    /// The point at arc length `s` (clamped to the path), searching from `from_segment`
    /// on, and the segment it lies on.
    fn point_at(&self, s: f64, from_segment: usize) -> ([f64; 2], usize) {
        let last = self.points.len() - 1;
        let mut k = from_segment.min(last.saturating_sub(1));
        while k + 1 < last && self.arc[k + 1] < s {
            k += 1;
        }
        if last == 0 {
            return (self.points[0], 0);
        }
        let (a, b) = (self.points[k], self.points[k + 1]);
        let len = self.arc[k + 1] - self.arc[k];
        if len <= 0.0 {
            return (b, k);
        }
        let t = ((s - self.arc[k]) / len).clamp(0.0, 1.0);
        ([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])], k)
    }

    /// The nearest point to `p` on segment `k` between arc lengths `from` and `to`.
    fn nearest_on(&self, k: usize, p: [f64; 2], from: f64, to: f64) -> Nearest {
        let (a, b) = (self.points[k], self.points[k + 1]);
        let len = self.arc[k + 1] - self.arc[k];
        let lo = (from - self.arc[k]).clamp(0.0, len);
        let hi = (to - self.arc[k]).clamp(lo, len);
        let t = if len > 0.0 {
            let along = ((p[0] - a[0]) * (b[0] - a[0]) + (p[1] - a[1]) * (b[1] - a[1])) / len;
            // A NaN position keeps the piece's start (f64::clamp would pass the NaN on).
            if along.is_nan() {
                lo
            } else {
                along.clamp(lo, hi)
            }
        } else {
            0.0
        };
        let point = if len > 0.0 {
            let f = t / len;
            [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])]
        } else {
            a
        };
        Nearest {
            distance: distance(p, point),
            arc: self.arc[k] + t,
        }
    }

    /// Projects `p` onto the path (module doc: forward from the last projection, to the
    /// first local minimum of the distance, at most `window_m` of arc ahead), moves the
    /// projection there, and puts the carrot `lookahead_m` beyond it, clamped at the
    /// end. Both lengths are metres and should be positive (the controller's parameters
    /// are checked); a `p` that is not finite leaves the projection where it was.
    pub fn pursue(&mut self, p: [f64; 2], lookahead_m: f64, window_m: f64) -> Pursuit {
        let last = self.points.len() - 1;
        if last == 0 {
            let only = self.points[0];
            return Pursuit {
                projection: only,
                progress_m: 0.0,
                carrot: only,
                at_end: true,
                next_point: 0,
                distance_left_m: distance(p, only),
            };
        }
        let limit = self.progress_m + window_m.max(0.0);
        let mut segment = self.segment;
        let mut best = self.nearest_on(segment, p, self.progress_m, limit);
        let mut k = segment + 1;
        while k < last && self.arc[k] <= limit {
            let next = self.nearest_on(k, p, self.arc[k], limit);
            if next.distance <= best.distance {
                best = next;
                segment = k;
                k += 1;
            } else {
                break;
            }
        }
        // Never behind the last projection (a NaN distance never wins the walk above).
        if best.arc >= self.progress_m {
            self.segment = segment;
            self.progress_m = best.arc;
        }
        let (projection, _) = self.point_at(self.progress_m, self.segment);
        let total = self.length_m();
        let ahead = self.progress_m + lookahead_m.max(0.0);
        let (carrot, _) = self.point_at(ahead, self.segment);
        Pursuit {
            projection,
            progress_m: self.progress_m,
            carrot,
            at_end: ahead >= total,
            next_point: (self.segment + 1).min(last),
            distance_left_m: distance(p, projection) + (total - self.progress_m),
        }
    }

    /// What is left to drive from `p` without moving the projection: from `p` to the
    /// last projection, then along the rest of the path, metres.
    pub fn distance_left_m(&self, p: [f64; 2]) -> f64 {
        let (projection, _) = self.point_at(self.progress_m, self.segment);
        distance(p, projection) + (self.length_m() - self.progress_m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const L: f64 = 0.4;
    const W: f64 = 0.8;
    /// A window longer than any path here: what is checked is the walk's own rule.
    const WIDE: f64 = 100.0;

    fn close(a: [f64; 2], b: [f64; 2]) {
        assert!(distance(a, b) < 1e-9, "{a:?} != {b:?}");
    }

    /// Drives a point robot along `tracker`'s carrots in steps of `step` (no forces but
    /// f_a), and returns the positions and the projections' progress.
    fn drive(tracker: &mut PathTracker, from: [f64; 2], step: f64) -> Vec<([f64; 2], f64)> {
        let mut p = from;
        let mut out = Vec::new();
        for _ in 0..10_000 {
            let a = tracker.pursue(p, L, W);
            out.push((p, a.progress_m));
            let end = *tracker.points().last().expect("a point");
            if a.at_end && distance(p, end) <= 0.1 {
                return out;
            }
            let (dx, dy) = (a.carrot[0] - p[0], a.carrot[1] - p[1]);
            let n = dx.hypot(dy).max(1e-12);
            p = [p[0] + step * dx / n, p[1] + step * dy / n];
        }
        panic!("never reached the end");
    }

    fn off_path(p: [f64; 2], path: &[[f64; 2]]) -> f64 {
        let t = PathTracker::new(vec![path[0]]).expect("one point");
        let mut best = distance(p, t.points()[0]);
        for pair in path.windows(2) {
            let s = PathTracker::new(pair.to_vec()).expect("segment");
            best = best.min(s.nearest_on(0, p, 0.0, f64::INFINITY).distance);
        }
        best
    }

    #[test]
    fn bad_paths_are_refused() {
        assert_eq!(PathTracker::new(Vec::new()), Err(PathError::Empty));
        let bad = PathTracker::new(vec![[0.0, 0.0], [1.0, 1.0], [f64::INFINITY, 1.0]]);
        assert_eq!(
            bad,
            Err(PathError::NotFinite {
                index: 2,
                point: [f64::INFINITY, 1.0]
            })
        );
        assert_eq!(
            bad.map(|_| ()).map_err(|e| e.to_string()),
            Err("path point 2 ([inf, 1.0]) is not a finite point".to_owned())
        );
    }

    #[test]
    fn the_carrot_is_the_lookahead_beyond_the_projection() {
        let mut t = PathTracker::new(vec![[0.0, 0.0], [2.0, 0.0], [2.0, 2.0]]).expect("path");
        assert!((t.length_m() - 4.0).abs() < 1e-12);
        // 0.3 m off the first leg at x = 1: projected to (1, 0), the carrot 0.4 m on.
        let a = t.pursue([1.0, 0.3], L, WIDE);
        close(a.projection, [1.0, 0.0]);
        close(a.carrot, [1.4, 0.0]);
        assert!((a.progress_m - 1.0).abs() < 1e-12);
        assert!((a.distance_left_m - (0.3 + 3.0)).abs() < 1e-12);
        assert_eq!((a.next_point, a.at_end), (1, false));
        // Near the corner the carrot goes round it.
        let a = t.pursue([1.8, 0.0], L, WIDE);
        close(a.carrot, [2.0, 0.2]);
        assert_eq!(a.next_point, 1);
        assert!((t.distance_left_m([1.8, 0.1]) - (0.1 + 2.2)).abs() < 1e-12);
    }

    #[test]
    fn the_projection_never_moves_back_and_the_window_bounds_it() {
        let points: Vec<[f64; 2]> = (0..=50).map(|i| [0.2 * f64::from(i), 0.0]).collect();
        let mut t = PathTracker::new(points).expect("path");
        let a = t.pursue([3.0, 0.0], L, W);
        // Only 0.8 m of the window is searched: the projection stops at 0.8 m, short of
        // the robot, and catches up over the next updates.
        assert!((a.progress_m - 0.8).abs() < 1e-9, "{}", a.progress_m);
        assert!((t.pursue([3.0, 0.0], L, W).progress_m - 1.6).abs() < 1e-9);
        assert!((t.pursue([3.0, 0.0], L, W).progress_m - 2.4).abs() < 1e-9);
        assert!((t.pursue([3.0, 0.0], L, W).progress_m - 3.0).abs() < 1e-9);
        // Pushed back (or a jump of the estimate): the projection stays, the carrot too.
        let back = t.pursue([1.0, 0.5], L, W);
        assert!((back.progress_m - 3.0).abs() < 1e-9);
        close(back.carrot, [3.4, 0.0]);
        // A position that is not finite changes nothing.
        let nan = t.pursue([f64::NAN, 0.0], L, W);
        assert!((nan.progress_m - 3.0).abs() < 1e-9);
        // Monotone along a noisy drive.
        let mut t = PathTracker::new(vec![[0.0, 0.0], [10.0, 0.0]]).expect("path");
        let mut before = 0.0;
        for k in 0..100 {
            let wobble = if k % 2 == 0 { 0.15 } else { -0.25 };
            let s = t
                .pursue([0.1 * f64::from(k) + wobble, wobble], L, W)
                .progress_m;
            assert!(s >= before, "step {k}: {s} < {before}");
            before = s;
        }
    }

    #[test]
    fn the_lookahead_is_clamped_at_the_end() {
        let mut t = PathTracker::new(vec![[0.0, 0.0], [1.0, 0.0]]).expect("path");
        let a = t.pursue([0.5, 0.0], L, W);
        close(a.carrot, [0.9, 0.0]);
        assert!(!a.at_end);
        let a = t.pursue([0.7, 0.1], L, W);
        close(a.carrot, [1.0, 0.0]);
        assert!(a.at_end);
        // Beyond the end the projection is the end and the carrot stays there.
        let a = t.pursue([1.5, 0.0], L, W);
        close(a.projection, [1.0, 0.0]);
        close(a.carrot, [1.0, 0.0]);
        assert!((a.distance_left_m - 0.5).abs() < 1e-12);
        assert_eq!(a.next_point, 1);
        // A one-point path: the carrot is the point.
        let mut one = PathTracker::new(vec![[2.0, 2.0]]).expect("point");
        let a = one.pursue([0.0, 2.0], L, W);
        close(a.carrot, [2.0, 2.0]);
        assert!(a.at_end && (a.distance_left_m - 2.0).abs() < 1e-12);
    }

    #[test]
    fn a_u_shaped_path_is_followed_in_order() {
        // East 4 m, north 0.6 m, back west 4 m: the return leg passes 0.6 m from the
        // outward one, nearer than the robot ever is to the bend early on.
        let path = vec![[0.0, 0.0], [4.0, 0.0], [4.0, 0.6], [0.0, 0.6]];
        let mut t = PathTracker::new(path.clone()).expect("path");
        // Halfway out and pushed 0.35 m toward the return leg (0.25 m from it): still
        // the outward leg, even with a window that reaches the return leg.
        let a = t.pursue([2.0, 0.35], L, WIDE);
        assert!((a.progress_m - 2.0).abs() < 1e-9, "{}", a.progress_m);
        close(a.carrot, [2.4, 0.0]);
        let mut t = PathTracker::new(path.clone()).expect("path");
        let driven = drive(&mut t, [0.0, 0.0], 0.2);
        // It went round the bend: the farthest east it got is near x = 4.
        let east = driven.iter().map(|(p, _)| p[0]).fold(f64::MIN, f64::max);
        assert!(east > 3.7, "turned back at x = {east}");
        for (p, _) in &driven {
            assert!(off_path(*p, &path) < 0.2, "{p:?} is off the U");
        }
        assert!(driven.windows(2).all(|w| w[1].1 >= w[0].1));
    }

    #[test]
    fn a_self_crossing_path_is_followed_in_order() {
        // A figure of eight's loop: out east, round a loop that crosses the outward leg
        // at (2, 0), and on east. A follower that took the nearest point anywhere would
        // jump from the crossing straight to the exit leg and skip the loop.
        let path = vec![
            [0.0, 0.0],
            [3.0, 0.0],
            [3.0, 1.0],
            [2.0, 1.0],
            [2.0, -1.0],
            [5.0, -1.0],
        ];
        let mut t = PathTracker::new(path.clone()).expect("path");
        // At the crossing on the way out: the projection is on the first leg.
        let a = t.pursue([0.4, 0.0], L, W);
        assert!(a.progress_m < 0.5);
        for x in [0.8, 1.2, 1.6, 2.0] {
            t.pursue([x, 0.0], L, W);
        }
        // On the crossing itself, even with a window that reaches the loop's pass
        // through it (at 6 m): the outward pass (at 2 m).
        let a = t.pursue([2.0, 0.0], L, WIDE);
        assert!((a.progress_m - 2.0).abs() < 1e-9, "{}", a.progress_m);
        close(a.carrot, [2.4, 0.0]);
        // Driven from the start, the robot goes round the loop: it gets to x ≈ 3, y ≈ 1.
        let mut t = PathTracker::new(path.clone()).expect("path");
        let driven = drive(&mut t, [0.0, 0.0], 0.2);
        assert!(
            driven.iter().any(|(p, _)| p[0] > 2.7 && p[1] > 0.7),
            "the loop was skipped"
        );
        // And through the crossing a second time, on the way down.
        assert!(driven
            .iter()
            .any(|(p, s)| distance(*p, [2.0, 0.0]) < 0.2 && *s > 5.0));
        for (p, _) in &driven {
            assert!(off_path(*p, &path) < 0.2, "{p:?} is off the path");
        }
        let end = driven.last().expect("driven").0;
        assert!(distance(end, [5.0, -1.0]) <= 0.1);
    }
}
