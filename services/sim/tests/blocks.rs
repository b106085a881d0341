//! Paper 004's two moving blocks in the shipped grid world: the top one changes position
//! every 7 steps over 6 positions, the bottom one every 2 steps on a cycle along the
//! bottom wall.

mod common;

use std::collections::BTreeSet;

use roam_sim::Sim;

/// The cells each block covers in the sim's occupancy at the current step.
fn covered(sim: &Sim, block: usize) -> BTreeSet<(i64, i64)> {
    let b = &sim.world().blocks()[block];
    let cells: BTreeSet<_> = b.footprint.cells(b.centre_at(sim.steps())).collect();
    let occupancy = sim.occupancy();
    for &(x, y) in &cells {
        assert_eq!(
            occupancy.get(x as usize, y as usize),
            Some(100),
            "({x}, {y})"
        );
    }
    cells
}

#[test]
fn the_blocks_move_with_the_papers_periods() {
    let scenario = common::shipped("grid004.yaml");
    let mut sim = Sim::new(&scenario, 0).expect("sim");
    let names: Vec<_> = sim
        .world()
        .blocks()
        .iter()
        .map(|b| b.name.clone())
        .collect();
    assert_eq!(names, ["top", "bottom"]);
    let mut history: Vec<[BTreeSet<(i64, i64)>; 2]> = vec![[covered(&sim, 0), covered(&sim, 1)]];
    for _ in 0..200 {
        sim.step(&[]).expect("step");
        history.push([covered(&sim, 0), covered(&sim, 1)]);
    }
    // (block, steps per position, positions per cycle, distinct places): the bottom
    // block shuttles over 11 cells and back, 20 positions per cycle.
    for (block, period, positions, places) in [(0, 7, 6, 6), (1, 2, 20, 11)] {
        let cycle = period * positions;
        for k in 1..history.len() {
            let moved = history[k][block] != history[k - 1][block];
            assert_eq!(moved, k % period == 0, "block {block} at step {k}");
            if k >= cycle {
                assert_eq!(
                    history[k][block],
                    history[k - cycle][block],
                    "block {block} repeats"
                );
            }
        }
        for shorter in 1..cycle {
            assert!(
                (shorter..history.len()).any(|k| history[k][block] != history[k - shorter][block]),
                "block {block} would repeat after {shorter} steps already"
            );
        }
        let distinct: BTreeSet<_> = history.iter().map(|h| h[block].clone()).collect();
        assert_eq!(distinct.len(), places, "block {block}: distinct places");
    }
    // The top block's cycle is the paper's 42 steps; the bottom block's is no longer.
    assert_eq!(history[42][0], history[0][0]);
    // The bottom block runs along the bottom wall: its lowest row touches the wall row.
    let wall_row = 0;
    for h in &history {
        assert!(h[1]
            .iter()
            .all(|&(_, y)| y == wall_row + 1 || y == wall_row + 2));
    }
}
