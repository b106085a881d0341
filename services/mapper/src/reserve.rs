//! The cells a robot's path will show it, with the time it should see each: what the
//! mapper reserves for a robot's mission ([`crate::news::NewsMap::reserve`]).
//!
//! roam's choice (no paper plans for a fleet): the robot drives the path from its start
//! at the start time, `s_per_m` seconds per metre (paper 000 Eq. 2's v_lin, which acts
//! as seconds per metre; turns are not counted), and sees every cell whose centre comes
//! within `radius_m` of it (its observation radius; walls that would hide a cell are not
//! known ahead, so a plan reserves a little more than the robot will see). A cell counts
//! as seen at the *last* time the path is within reach of it, as its last sighting will
//! be. A cell within half a cell's diagonal of the path is always reached, so a radius
//! of 0 reserves the cells the path crosses (and a few corner neighbours).
//!
//! Bounded work on any path: the path is clipped to the map (a waypoint a million metres
//! off costs nothing), repeated points are passed over, at most `max_cells` cells are
//! reserved (the path's first ones, in the order it reaches them) and at most
//! [`WORK_PER_CELL`] times as many cells as can be reserved (`max_cells`, or the map's
//! cells if fewer) are looked at, so a path that sweeps the same cells again and again
//! stops there: a straight path looks at about four cells for each it reserves.

use std::collections::HashMap;

use roam_proto::map::GridMeta;
use serde::{Deserialize, Serialize};

use crate::error::MapperError;

/// A cell (x, y) and the time it should be seen there, seconds.
pub type TimedCell = ((u32, u32), f64);

/// Seconds per metre by default: paper 000's Table I v_lin, 2.0.
pub const DEFAULT_S_PER_M: f64 = 2.0;

/// Cells looked at per cell reservable, at most (module doc).
pub const WORK_PER_CELL: usize = 32;

/// How a mission becomes a reservation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ReserveParams {
    /// Seconds per metre along the path (default [`DEFAULT_S_PER_M`]); 0 reserves every
    /// cell at the time the mission was heard.
    pub s_per_m: f64,
    /// Cells whose centre comes within this distance of the path are reserved, metres;
    /// absent: the scenario's observation radius.
    pub radius_m: Option<f64>,
}

impl Default for ReserveParams {
    fn default() -> Self {
        ReserveParams {
            s_per_m: DEFAULT_S_PER_M,
            radius_m: None,
        }
    }
}

impl ReserveParams {
    pub fn check(&self) -> Result<(), MapperError> {
        non_negative("reserve.s_per_m", self.s_per_m)?;
        if let Some(r) = self.radius_m {
            non_negative("reserve.radius_m", r)?;
        }
        Ok(())
    }
}

fn non_negative(field: &'static str, value: f64) -> Result<(), MapperError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(MapperError::Param {
            field,
            reason: format!("must be a finite number at least 0, got {value}"),
        })
    }
}

/// The cells of the `meta` grid that a robot driving `path` (world metres, from its
/// first point at `start_s`) sees, each with the last time it is within `radius_m` of
/// the robot (module doc), at most `max_cells` of them, by cell index. An empty path
/// reserves nothing.
pub fn cells_along(
    meta: &GridMeta,
    path: &[[f64; 2]],
    start_s: f64,
    s_per_m: f64,
    radius_m: f64,
    max_cells: usize,
) -> Result<Vec<TimedCell>, MapperError> {
    if !start_s.is_finite() {
        return Err(MapperError::BadTime(start_s));
    }
    non_negative("reserve.s_per_m", s_per_m)?;
    non_negative("reserve.radius_m", radius_m)?;
    if let Some(i) = path
        .iter()
        .position(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        return Err(MapperError::Param {
            field: "path",
            reason: format!("point {i} is not a finite position"),
        });
    }
    let map_cells =
        usize::try_from(u64::from(meta.width) * u64::from(meta.height)).unwrap_or(usize::MAX);
    let mut sweep = Sweep {
        meta,
        reach: radius_m.max(meta.resolution * std::f64::consts::FRAC_1_SQRT_2),
        max_cells,
        work_left: max_cells.min(map_cells).saturating_mul(WORK_PER_CELL),
        reserved: HashMap::new(),
    };
    let mut travelled = 0.0;
    // A point repeated adds nothing its neighbours' segments do not; a path of one
    // point (or of one point repeated) is that point.
    let mut points = path.to_vec();
    points.dedup();
    let segments: Vec<([f64; 2], [f64; 2])> = match points.as_slice() {
        [] => Vec::new(),
        [only] => vec![(*only, *only)],
        many => many.windows(2).map(|w| (w[0], w[1])).collect(),
    };
    for (a, b) in segments {
        let t_a = start_s + travelled * s_per_m;
        if !sweep.segment(a, b, t_a, s_per_m) {
            break;
        }
        travelled += distance(a, b);
    }
    let width = meta.width;
    let mut cells: Vec<TimedCell> = sweep
        .reserved
        .into_iter()
        .map(|(i, t)| ((i % width, i / width), t))
        .collect();
    cells.sort_by_key(|&((x, y), _)| (y, x));
    Ok(cells)
}

/// The cells reserved so far and what is left to spend.
struct Sweep<'a> {
    meta: &'a GridMeta,
    /// How near the path a cell's centre must come, metres.
    reach: f64,
    max_cells: usize,
    work_left: usize,
    reserved: HashMap<u32, f64>,
}

impl Sweep<'_> {
    /// Reserves the cells along segment a → b, driven from time `t_a`. Returns false
    /// when the cell or work limit is reached.
    fn segment(&mut self, a: [f64; 2], b: [f64; 2], t_a: f64, s_per_m: f64) -> bool {
        let len = distance(a, b);
        let dir = if len > 0.0 {
            [(b[0] - a[0]) / len, (b[1] - a[1]) / len]
        } else {
            [0.0, 0.0]
        };
        let Some((u0, u1)) = self.clip(a, dir, len) else {
            return true;
        };
        // Pieces short enough that their boxes stay near the path.
        let piece = 2.0 * self.reach.max(self.meta.resolution);
        let mut u = u0;
        loop {
            let v = (u + piece).min(u1);
            if !self.piece(a, dir, u, v, t_a, s_per_m) {
                return false;
            }
            if v >= u1 {
                return true;
            }
            u = v;
        }
    }

    /// The part [u0, u1] of a + u·dir, u in [0, len], within reach of the map, if any.
    fn clip(&self, a: [f64; 2], dir: [f64; 2], len: f64) -> Option<(f64, f64)> {
        let m = self.meta;
        let lo = [m.origin.x - self.reach, m.origin.y - self.reach];
        let hi = [
            m.origin.x + f64::from(m.width) * m.resolution + self.reach,
            m.origin.y + f64::from(m.height) * m.resolution + self.reach,
        ];
        let (mut u0, mut u1) = (0.0f64, len);
        for axis in 0..2 {
            if dir[axis] == 0.0 {
                if a[axis] < lo[axis] || a[axis] > hi[axis] {
                    return None;
                }
            } else {
                let (s, e) = (
                    (lo[axis] - a[axis]) / dir[axis],
                    (hi[axis] - a[axis]) / dir[axis],
                );
                u0 = u0.max(s.min(e));
                u1 = u1.min(s.max(e));
            }
        }
        (u0 <= u1).then_some((u0, u1))
    }

    /// Reserves the cells within reach of a + u·dir for u in [u, v].
    fn piece(
        &mut self,
        a: [f64; 2],
        dir: [f64; 2],
        u: f64,
        v: f64,
        t_a: f64,
        s_per_m: f64,
    ) -> bool {
        let m = self.meta;
        let (p, q) = (
            [a[0] + u * dir[0], a[1] + u * dir[1]],
            [a[0] + v * dir[0], a[1] + v * dir[1]],
        );
        let cell_range = |lo: f64, hi: f64, origin: f64, n: u32| {
            let first = ((lo - self.reach - origin) / m.resolution).floor().max(0.0);
            let last = ((hi + self.reach - origin) / m.resolution).floor();
            let last = last.min(f64::from(n) - 1.0);
            (first <= last).then_some((first as u32, last as u32))
        };
        let (Some((x0, x1)), Some((y0, y1))) = (
            cell_range(p[0].min(q[0]), p[0].max(q[0]), m.origin.x, m.width),
            cell_range(p[1].min(q[1]), p[1].max(q[1]), m.origin.y, m.height),
        ) else {
            return true;
        };
        let reach2 = self.reach * self.reach;
        for y in y0..=y1 {
            for x in x0..=x1 {
                if self.work_left == 0 {
                    return false;
                }
                self.work_left -= 1;
                let c = [
                    m.origin.x + (f64::from(x) + 0.5) * m.resolution,
                    m.origin.y + (f64::from(y) + 0.5) * m.resolution,
                ];
                let (dx, dy) = (c[0] - a[0], c[1] - a[1]);
                // Along the segment and across it, from a.
                let along = dx * dir[0] + dy * dir[1];
                let across2 = (dx * dx + dy * dy - along * along).max(0.0);
                if across2 > reach2 {
                    continue;
                }
                let half = (reach2 - across2).sqrt();
                if along + half < u || along - half > v {
                    continue;
                }
                let leaves = (along + half).min(v);
                let t = t_a + leaves * s_per_m;
                let index = y * m.width + x;
                if let Some(at) = self.reserved.get_mut(&index) {
                    *at = at.max(t);
                } else if self.reserved.len() < self.max_cells {
                    self.reserved.insert(index, t);
                } else {
                    return false;
                }
            }
        }
        true
    }
}

fn distance(a: [f64; 2], b: [f64; 2]) -> f64 {
    (b[0] - a[0]).hypot(b[1] - a[1])
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_proto::map::Origin;

    /// 10 × 3 cells of 1 m from the origin.
    fn meta() -> GridMeta {
        GridMeta {
            width: 10,
            height: 3,
            resolution: 1.0,
            origin: Origin::default(),
        }
    }

    const HALF_DIAGONAL: f64 = std::f64::consts::FRAC_1_SQRT_2;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }

    #[test]
    fn a_straight_path_reserves_its_row_at_the_time_it_leaves_each_cell() {
        // Along the middle row at 2 s/m from t = 100: cell x is left behind when the
        // robot is half a diagonal past its centre (or at the path's end).
        let path = [[0.5, 1.5], [9.5, 1.5]];
        let cells = cells_along(&meta(), &path, 100.0, 2.0, 0.0, 1000).expect("cells");
        assert_eq!(cells.len(), 10);
        for ((x, y), t) in cells {
            assert_eq!(y, 1);
            let leaves = (f64::from(x) + HALF_DIAGONAL).min(9.0);
            assert!(close(t, 100.0 + 2.0 * leaves), "cell {x}: {t}");
        }
        // A radius of 1 m takes the rows beside it too, left as the robot passes them.
        let wide = cells_along(&meta(), &path, 100.0, 2.0, 1.0, 1000).expect("cells");
        assert_eq!(wide.len(), 30);
        let beside = wide
            .iter()
            .find(|((x, y), _)| (*x, *y) == (4, 0))
            .expect("(4, 0)");
        assert!(close(beside.1, 108.0));
        // At the mission's time: s_per_m 0.
        let now = cells_along(&meta(), &path, 100.0, 0.0, 0.0, 1000).expect("cells");
        assert!(now.iter().all(|&(_, t)| t == 100.0));
    }

    #[test]
    fn a_path_that_turns_counts_its_length_and_keeps_the_last_pass() {
        // Right along row 0, up, and back left along row 2, 1 s/m: cell (1, 0) is left
        // at 1 + 0.71 s; (1, 2) on the way back, 4 + 2 + (4 − 1) + 0.71 s after the start.
        let path = [[0.5, 0.5], [4.5, 0.5], [4.5, 2.5], [0.5, 2.5]];
        let cells = cells_along(&meta(), &path, 0.0, 1.0, 0.0, 1000).expect("cells");
        let at = |c: (u32, u32)| cells.iter().find(|(x, _)| *x == c).map(|&(_, t)| t);
        assert!(close(at((1, 0)).expect("(1, 0)"), 1.0 + HALF_DIAGONAL));
        assert!(close(at((1, 2)).expect("(1, 2)"), 9.0 + HALF_DIAGONAL));
        // Cell (4, 1) is on the way up: left 1 + 0.71 m after the first corner, 4 m on.
        assert!(close(
            at((4, 1)).expect("(4, 1)"),
            4.0 + 1.0 + HALF_DIAGONAL
        ));
        assert_eq!(at((9, 0)), None);
    }

    #[test]
    fn the_work_is_bounded_on_any_path() {
        let path = [[0.5, 1.5], [9.5, 1.5]];
        // The first three cells the path reaches.
        let first = cells_along(&meta(), &path, 0.0, 1.0, 0.0, 3).expect("cells");
        assert_eq!(
            first.iter().map(|&(c, _)| c).collect::<Vec<_>>(),
            [(0, 1), (1, 1), (2, 1)]
        );
        // A waypoint a billion metres away is clipped to the map.
        let far = [[0.5, 1.5], [1e9, 1.5]];
        let cells = cells_along(&meta(), &far, 0.0, 1.0, 0.0, 1000).expect("cells");
        assert_eq!(cells.len(), 10);
        // Sweeping the same row a thousand times stops at the work limit: the row's ten
        // cells, from the first few passes.
        let zigzag: Vec<[f64; 2]> = (0..1000)
            .map(|i| if i % 2 == 0 { [0.5, 1.5] } else { [9.5, 1.5] })
            .collect();
        let swept = cells_along(&meta(), &zigzag, 0.0, 1.0, 0.0, 1000).expect("cells");
        assert_eq!(swept.len(), 10);
        assert!(swept.iter().all(|&(_, t)| t < 9.0 * 100.0), "{swept:?}");
        // Ten thousand copies of one point are that point.
        let repeated =
            cells_along(&meta(), &[[2.5, 1.5]; 10_000], 7.0, 1.0, 0.0, 10).expect("point");
        assert_eq!(repeated, vec![((2, 1), 7.0)]);
        assert!(cells_along(&meta(), &[], 0.0, 1.0, 0.0, 10)
            .expect("empty")
            .is_empty());
        // One point: the cells around it, at the start time.
        let still = cells_along(&meta(), &[[2.5, 1.5]], 7.0, 1.0, 0.0, 10).expect("point");
        assert_eq!(still, vec![((2, 1), 7.0)]);
        assert!(matches!(
            cells_along(&meta(), &[[0.0, f64::NAN]], 0.0, 1.0, 0.0, 10),
            Err(MapperError::Param { field: "path", .. })
        ));
        assert!(matches!(
            cells_along(&meta(), &path, 0.0, -1.0, 0.0, 10),
            Err(MapperError::Param {
                field: "reserve.s_per_m",
                ..
            })
        ));
    }
}
