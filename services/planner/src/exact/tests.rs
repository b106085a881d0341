use roam_proto::map::{GridMeta, Origin};
use roam_world::grid::Grid;
use roam_world::seed::splitmix64;

use super::*;

/// A `w` × `h` world at 0.2 m with the given walls (cell indices) and scores.
fn world(w: u32, h: u32, walls: &[usize], information: Vec<u8>) -> World {
    let meta = GridMeta {
        width: w,
        height: h,
        resolution: 0.2,
        origin: Origin::default(),
    };
    let mut occupancy = vec![0i8; (w * h) as usize];
    for &i in walls {
        occupancy[i] = 100;
    }
    World::new(
        &Grid {
            meta,
            cells: occupancy,
        },
        &Grid {
            meta,
            cells: information,
        },
        0.25,
    )
    .expect("a world")
}

/// A seeded small world: scores 0–100, about one cell in eight a wall (never the
/// corners, where start and goal go).
fn random_world(seed: u64, w: u32, h: u32) -> World {
    let n = (w * h) as usize;
    let mut state = seed;
    let mut next = || {
        state = splitmix64(state);
        state
    };
    let information = (0..n).map(|_| (next() % 101) as u8).collect();
    let walls: Vec<usize> = (0..n)
        .filter(|&i| i != 0 && i != n - 1 && next() % 8 == 0)
        .collect();
    world(w, h, &walls, information)
}

/// Every walk from `start` that fits `t_exec_s`, the best value of those ending at
/// `goal`: the brute force the search must agree with.
fn brute_force(world: &World, params: &GaParams, start: Cell, goal: Cell, t_exec_s: f64) -> f64 {
    struct Walks<'a> {
        world: &'a World,
        params: &'a GaParams,
        goal: Cell,
        t_exec_s: f64,
        best: f64,
    }
    impl Walks<'_> {
        fn walk(&mut self, path: &mut Vec<Cell>, dir: Option<usize>, time: f64) {
            let here = *path.last().expect("a start");
            if here == self.goal {
                self.best = self.best.max(score(self.world, self.params, path).0);
            }
            for d in 0..8 {
                let Some(next) = self.world.step(here, d) else {
                    continue;
                };
                let t = time + step_time(self.world, self.params, dir, d);
                if t <= self.t_exec_s + EPS_S {
                    path.push(next);
                    self.walk(path, Some(d), t);
                    path.pop();
                }
            }
        }
    }
    let mut walks = Walks {
        world,
        params,
        goal,
        t_exec_s,
        best: -1.0,
    };
    walks.walk(&mut vec![start], None, 0.0);
    walks.best
}

#[test]
fn the_search_finds_what_trying_every_path_finds() {
    let params = GaParams::default();
    let mut checked = 0;
    for seed in 0..30 {
        let world = random_world(seed, 5, 4);
        let (start, goal) = (0, world.cell_count() as Cell - 1);
        // Budgets of a few moves beyond the fastest: brute force stays small.
        let lower = LowerBounds::new(&world, &params);
        let floor = lower.time(start, goal);
        if !floor.is_finite() {
            continue;
        }
        for extra in [0.5, 1.5, 2.5] {
            let t_exec_s = floor + extra;
            let want = brute_force(&world, &params, start, goal, t_exec_s);
            if want < 0.0 {
                continue;
            }
            let got =
                best_path(&world, &params, start, goal, t_exec_s, &[], 10_000_000).expect("a path");
            assert!(got.proven, "seed {seed}, budget {t_exec_s}");
            assert_eq!(
                got.distinct_information, want,
                "seed {seed}, budget {t_exec_s}"
            );
            // The path is what it says: legal, from start to goal, within the budget,
            // worth its value.
            assert_eq!(
                (got.path[0], *got.path.last().expect("cells")),
                (start, goal)
            );
            assert!(got.path.windows(2).all(|m| world.is_legal_move(m[0], m[1])));
            let (value, t) = score(&world, &params, &got.path);
            assert_eq!(value, got.distinct_information);
            assert!(t <= t_exec_s + EPS_S && (t - got.t_eta_s).abs() < 1e-9);
            checked += 1;
        }
    }
    assert!(checked >= 20, "only {checked} instances had a path");
}

#[test]
fn the_objective_is_the_planners_distinct_information_and_eta() {
    let params = GaParams::default();
    let world = random_world(3, 6, 5);
    // A straight row along y = 0, then up: legal on this world.
    let path: Vec<Cell> = (0..world.width() as Cell).collect();
    if path.windows(2).all(|m| world.is_legal_move(m[0], m[1])) {
        let metrics = crate::metrics::path_metrics(&world, &params, &path);
        assert_eq!(
            score(&world, &params, &path).0,
            metrics.distinct_information
        );
        let eta = crate::eta::path_eta(&world, &params, &path);
        assert!(
            (score(&world, &params, &path).1 - eta).abs() < 1e-9,
            "{eta}"
        );
    }
}

#[test]
fn an_incumbent_is_kept_when_nothing_beats_it_and_a_node_limit_says_not_proven() {
    let params = GaParams::default();
    let world = random_world(7, 8, 8);
    let (start, goal) = (0, world.cell_count() as Cell - 1);
    let floor = LowerBounds::new(&world, &params).time(start, goal);
    let t_exec_s = floor * 2.0;
    let full = best_path(&world, &params, start, goal, t_exec_s, &[], 50_000_000).expect("solved");
    assert!(full.proven);
    // Given the optimum as the incumbent, the search proves it in fewer nodes.
    let again = best_path(
        &world,
        &params,
        start,
        goal,
        t_exec_s,
        &[&full.path],
        50_000_000,
    )
    .expect("solved");
    assert!(again.proven && again.nodes <= full.nodes);
    assert_eq!(again.distinct_information, full.distinct_information);
    // Cut short: not proven, and no better than the optimum.
    let cut = best_path(&world, &params, start, goal, t_exec_s, &[], 50).expect("some path");
    assert!(!cut.proven && cut.distinct_information <= full.distinct_information);
    // Cut before any path reached the goal: said so, not "infeasible".
    assert_eq!(
        best_path(&world, &params, start, goal, t_exec_s, &[], 1),
        Err(ExactError::NodeLimit { node_limit: 1 })
    );
}

#[test]
fn instances_it_cannot_search_are_refused_naming_why() {
    let params = GaParams::default();
    let big = random_world(1, 17, 16);
    assert_eq!(
        best_path(&big, &params, 0, 1, 10.0, &[], 10),
        Err(ExactError::TooLarge {
            cells: 272,
            max: MAX_EXACT_CELLS
        })
    );
    let walled = world(3, 1, &[2], vec![10; 3]);
    assert_eq!(
        best_path(&walled, &params, 0, 2, 10.0, &[], 10),
        Err(ExactError::Blocked)
    );
    let open = world(3, 1, &[], vec![10; 3]);
    assert_eq!(
        best_path(&open, &params, 0, 2, 0.1, &[], 10),
        Err(ExactError::Infeasible { t_exec_s: 0.1 })
    );
}
