//! The local observation sees what a laser would: walls hide what is behind them, and
//! the wall cells that stop the rays are seen.

mod common;

use roam_sim::los::{FREE, OCCUPIED, UNSEEN};
use roam_sim::Sim;

#[test]
fn a_wall_hides_the_cells_behind_it() {
    // 1 m cells; a wall along x = 10 from y = 6 to y = 14; the robot at (7.5, 10.5),
    // 2.5 m west of it; radius 6 m.
    let text = "
name: los
map:
  grid:
    size_m: [21.0, 21.0]
    resolution: 1.0
    obstacles: [ { rect: [10.0, 6.0, 10.9, 14.9] } ]
sensing: { observation_radius_m: 6.0 }
robots: [ { name: r, at: [7.5, 10.5] } ]
";
    let mut sim = Sim::new(&common::inline(text), 0).expect("sim");
    let report = sim.step(&[]).expect("step");
    let obs = report.robots[0]
        .readings
        .observation
        .clone()
        .expect("an observation");
    // The robot's own cell and the free cells between it and the wall: seen, free.
    for x in 7..=9 {
        assert_eq!(obs.get(x, 10), Some(FREE), "({x}, 10)");
    }
    // The wall facing the robot: seen, occupied.
    for y in 8..=12 {
        assert_eq!(obs.get(10, y), Some(OCCUPIED), "wall (10, {y})");
    }
    // Behind the wall: not seen.
    for y in 8..=12 {
        assert_eq!(obs.get(11, y), Some(UNSEEN), "(11, {y}) behind the wall");
        assert_eq!(obs.get(12, y), Some(UNSEEN), "(12, {y}) behind the wall");
    }
    // Past the radius: outside the window, or not seen.
    assert!(matches!(obs.get(14, 10), None | Some(UNSEEN)));
    // In the open, westwards, everything within the radius is seen.
    assert_eq!(obs.get(2, 10), Some(FREE));
    assert_eq!(obs.get(7, 4), Some(FREE));
    // Every seen cell agrees with the ground truth.
    let occupancy = sim.occupancy();
    for (x, y, v) in obs.seen() {
        let truth = occupancy.get(x as usize, y as usize).expect("on the map");
        assert_eq!(v == OCCUPIED, truth == 100, "({x}, {y})");
    }
}

#[test]
fn a_diagonal_wall_is_opaque_and_blocks_are_seen() {
    // A diagonal wall of cells touching only at their corners, from (5, 1) to (1, 5);
    // the robot at (1.5, 1.5) inside the corner it makes.
    let text = "
name: diagonal
map:
  grid:
    size_m: [12.0, 12.0]
    resolution: 1.0
    obstacles:
      - rect: [5.2, 1.2, 5.8, 1.8]
      - rect: [4.2, 2.2, 4.8, 2.8]
      - rect: [3.2, 3.2, 3.8, 3.8]
      - rect: [2.2, 4.2, 2.8, 4.8]
      - rect: [1.2, 5.2, 1.8, 5.8]
      - rect: [0.0, 6.2, 0.8, 6.8]
      - rect: [6.2, 0.0, 6.8, 0.8]
sensing: { observation_radius_m: 9.0 }
robots: [ { name: r, at: [1.5, 1.5] } ]
blocks: [ { name: b, size_cells: [1, 1], period_steps: 5, path: [[1.5, 3.5]] } ]
";
    let mut sim = Sim::new(&common::inline(text), 0).expect("sim");
    let obs = sim.step(&[]).expect("step").robots[0]
        .readings
        .observation
        .clone()
        .expect("observation");
    assert_eq!(obs.get(1, 3), Some(OCCUPIED), "the block is seen");
    assert_eq!(obs.get(1, 4), Some(UNSEEN), "behind the block");
    assert_eq!(obs.get(3, 3), Some(OCCUPIED), "the wall facing the robot");
    assert_eq!(obs.get(2, 2), Some(FREE));
    // Beyond the diagonal wall nothing is seen (no leaks between corner-touching cells).
    for (x, y) in [(4, 4), (5, 5), (6, 3), (3, 6), (6, 6), (7, 2), (2, 7)] {
        assert_eq!(obs.get(x, y), Some(UNSEEN), "({x}, {y})");
    }
}
