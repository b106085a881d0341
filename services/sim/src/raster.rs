//! The cells a straight segment crosses (Amanatides & Woo's grid traversal), for motion
//! (a robot's move, in metres) and for line of sight (between two cell centres).
//!
//! Both walks are *supercover* walks: every cell whose inside the segment passes
//! through, and where the segment goes exactly through a grid corner, both cells beside
//! the corner as well as the diagonal one. So a robot never slips between two occupied
//! cells that touch only at a corner, and it never sees through such a gap either
//! (Bresenham's 8-connected lines would leak through diagonal walls).

/// Cells are `(x, y)` in grid coordinates, possibly outside the grid.
pub type CellXy = (i64, i64);

/// The first cell on the segment from `from` to `to` (both in cell units: world metres
/// minus the origin, over the resolution) that `blocked` refuses, with the fraction
/// `t ∈ [0, 1]` of the segment at which the segment enters it. The start cell itself is
/// not tested. `None` when the segment stays in cells that are not blocked.
pub fn first_blocked(
    from: [f64; 2],
    to: [f64; 2],
    mut blocked: impl FnMut(CellXy) -> bool,
) -> Option<(f64, CellXy)> {
    let (dx, dy) = (to[0] - from[0], to[1] - from[1]);
    let mut cell: CellXy = (from[0].floor() as i64, from[1].floor() as i64);
    let axis = |p: f64, d: f64| -> (i64, f64, f64) {
        if d > 0.0 {
            (1, (p.floor() + 1.0 - p) / d, 1.0 / d)
        } else if d < 0.0 {
            (-1, (p - p.floor()) / -d, 1.0 / -d)
        } else {
            (0, f64::INFINITY, f64::INFINITY)
        }
    };
    let (sx, mut tx, step_tx) = axis(from[0], dx);
    let (sy, mut ty, step_ty) = axis(from[1], dy);
    // A crossing at exactly t = 1 counts only in the positive direction: a point on a
    // cell's lower edge belongs to that cell (floor), its upper edge to the next one.
    let crosses = |t: f64, s: i64| t < 1.0 || (t == 1.0 && s > 0);
    loop {
        let x_next = crosses(tx, sx);
        let y_next = crosses(ty, sy);
        if !x_next && !y_next {
            return None;
        }
        if x_next && (!y_next || tx < ty) {
            cell.0 += sx;
            if blocked(cell) {
                return Some((tx, cell));
            }
            tx += step_tx;
        } else if y_next && (!x_next || ty < tx) {
            cell.1 += sy;
            if blocked(cell) {
                return Some((ty, cell));
            }
            ty += step_ty;
        } else {
            // Exactly through a corner: the two cells beside it, then the diagonal.
            let t = tx;
            for side in [(cell.0 + sx, cell.1), (cell.0, cell.1 + sy)] {
                if blocked(side) {
                    return Some((t, side));
                }
            }
            cell = (cell.0 + sx, cell.1 + sy);
            if blocked(cell) {
                return Some((t, cell));
            }
            tx += step_tx;
            ty += step_ty;
        }
    }
}

/// The cells strictly between cell (0, 0) and cell `(dx, dy)` that the segment between
/// their centres crosses, nearest first, in exact integer arithmetic (no tie is ever
/// decided by rounding).
pub fn cells_between(dx: i64, dy: i64) -> Vec<CellXy> {
    let (sx, sy) = (dx.signum(), dy.signum());
    let (ax, ay) = (dx.abs(), dy.abs());
    let mut cells = Vec::with_capacity((ax + ay) as usize);
    // The segment crosses x boundary i (i = 0..ax) at t = (i + ½)/ax and y boundary j at
    // t = (j + ½)/ay; compare (2i + 1)·ay with (2j + 1)·ax.
    let (mut i, mut j) = (0, 0);
    let mut cell: CellXy = (0, 0);
    while i < ax || j < ay {
        let order = if i == ax {
            std::cmp::Ordering::Greater
        } else if j == ay {
            std::cmp::Ordering::Less
        } else {
            ((2 * i + 1) * ay).cmp(&((2 * j + 1) * ax))
        };
        match order {
            std::cmp::Ordering::Less => {
                cell.0 += sx;
                i += 1;
                cells.push(cell);
            }
            std::cmp::Ordering::Greater => {
                cell.1 += sy;
                j += 1;
                cells.push(cell);
            }
            std::cmp::Ordering::Equal => {
                cells.push((cell.0 + sx, cell.1));
                cells.push((cell.0, cell.1 + sy));
                cell = (cell.0 + sx, cell.1 + sy);
                i += 1;
                j += 1;
                cells.push(cell);
            }
        }
    }
    cells.pop(); // the target itself
    cells
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn straight_and_diagonal_lines() {
        assert_eq!(cells_between(3, 0), vec![(1, 0), (2, 0)]);
        assert_eq!(cells_between(0, -2), vec![(0, -1)]);
        assert_eq!(cells_between(1, 0), Vec::<CellXy>::new());
        // Through the corners: both side cells each time.
        assert_eq!(
            cells_between(2, 2),
            vec![(1, 0), (0, 1), (1, 1), (2, 1), (1, 2)]
        );
        assert_eq!(cells_between(1, 1), vec![(1, 0), (0, 1)]);
        // Slope 1/2: x boundaries at t = 1/8, 3/8, 5/8, 7/8, y boundaries at 1/4, 3/4.
        assert_eq!(
            cells_between(4, 2),
            vec![(1, 0), (1, 1), (2, 1), (3, 1), (3, 2)]
        );
        assert_eq!(
            cells_between(-4, -2),
            vec![(-1, 0), (-1, -1), (-2, -1), (-3, -1), (-3, -2)]
        );
    }

    #[test]
    fn a_move_stops_at_the_first_blocked_cell() {
        let wall = |c: CellXy| c.0 >= 5;
        let (t, cell) = first_blocked([0.5, 0.5], [10.5, 0.5], wall).expect("hits");
        assert_eq!(cell, (5, 0));
        assert!((t - 0.45).abs() < 1e-12);
        assert_eq!(first_blocked([0.5, 0.5], [4.9, 3.0], wall), None);
        // Ending exactly on the wall's edge enters it; leaving a cell leftwards onto its
        // own lower edge does not enter the neighbour.
        assert!(first_blocked([0.5, 0.5], [5.0, 0.5], wall).is_some());
        assert_eq!(first_blocked([6.5, 0.5], [6.0, 0.5], |c| c.0 <= 5), None);
    }

    #[test]
    fn a_move_through_a_corner_checks_both_sides() {
        let one_side = |c: CellXy| c == (1, 0);
        let hit = first_blocked([0.5, 0.5], [1.5, 1.5], one_side).expect("corner");
        assert_eq!(hit.1, (1, 0));
        assert_eq!(first_blocked([0.5, 0.5], [1.5, 1.5], |_| false), None);
    }
}
