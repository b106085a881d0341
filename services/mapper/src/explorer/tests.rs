use super::*;
use crate::change_map::{MapParams, ObservationWindow};
use roam_proto::map::{GridMeta, Origin};

/// A `w × h` map seen entirely free at t = 0.
fn free_map(w: u32, h: u32) -> ChangeMap {
    let meta = GridMeta {
        width: w,
        height: h,
        resolution: 1.0,
        origin: Origin::default(),
    };
    let mut map = ChangeMap::new(meta, MapParams::default()).expect("map");
    let cells = vec![0i8; (w * h) as usize];
    let window = ObservationWindow {
        x0: 0,
        y0: 0,
        width: w,
        height: h,
        cells: &cells,
    };
    map.observe(&window, 0.0).expect("observe");
    map
}

fn update(flipped: &[(u32, u32)], discovered: &[(u32, u32)]) -> Update {
    Update {
        flipped: flipped.to_vec(),
        discovered: discovered.to_vec(),
        ..Update::default()
    }
}

fn params(max_steps: u32) -> ExplorerParams {
    ExplorerParams {
        max_steps,
        ..ExplorerParams::default()
    }
}

#[test]
fn an_episode_is_max_steps_updates_and_its_reward_is_changes_per_update() {
    let mut map = free_map(5, 5);
    let mut ex = Explorer::new(params(4), Mode::PoissonOnly, 1).expect("explorer");
    let mut robot = (2, 2);
    // Update 1 starts the episode (it belongs to no episode); updates 2–5 are the
    // results of its four steps: 1, 0, 2 + 2 discoveries, 3 changes.
    let updates = [
        update(&[(0, 0)], &[]),
        update(&[(0, 0)], &[]),
        update(&[], &[]),
        update(&[(1, 1), (1, 2)], &[(3, 3), (3, 4)]),
        update(&[(0, 0), (0, 1), (0, 2)], &[]),
    ];
    let mut ends = Vec::new();
    for (k, u) in updates.iter().enumerate() {
        // Time stands still, so every (p, r) of the trajectory is the same point.
        let step = ex.on_update(&mut map, u, robot, 0.0).expect("step");
        assert_eq!(step.strategy, Strategy::Poisson);
        let expected_steps = if k == 4 { 1 } else { k as u32 + 1 };
        assert_eq!(step.episode_steps, expected_steps, "update {k}");
        robot = step.next_cell;
        ends.extend(step.episode);
    }
    assert_eq!(ends.len(), 1);
    let end = ends[0];
    assert_eq!((end.length, end.map_changes), (4, 8));
    assert!((end.reward - 2.0).abs() < 1e-12);
    assert_eq!(ex.episodes_ended(), 1);
    // Four updates at the same tiles: w = 2·(1 − 0.1⁴) = 1.9998.
    let v = ex.learner().value(Strategy::Poisson, map.features(0.0));
    assert!((v - 1.9998).abs() < 1e-12, "{v}");
    assert_eq!(
        ex.learner().value(Strategy::Recency, map.features(0.0)),
        0.0
    );
}

#[test]
fn without_discoveries_only_flips_count() {
    let mut map = free_map(5, 5);
    let p = ExplorerParams {
        count_discoveries: false,
        ..params(2)
    };
    let mut ex = Explorer::new(p, Mode::RecencyOnly, 2).expect("explorer");
    let mut robot = (2, 2);
    let mut end = None;
    for u in [
        update(&[], &[]),
        update(&[(0, 0)], &[(1, 1), (2, 1)]),
        update(&[], &[(4, 4)]),
    ] {
        let step = ex.on_update(&mut map, &u, robot, 0.0).expect("step");
        robot = step.next_cell;
        end = end.or(step.episode);
    }
    let end = end.expect("ended");
    assert_eq!((end.map_changes, end.length), (1, 2));
    assert!((end.reward - 0.5).abs() < 1e-12);
}

/// Drives the explorer (robot obeying, nothing changing) until it explores locally;
/// the robot's cell and the first local action.
fn until_local(
    ex: &mut Explorer,
    map: &mut ChangeMap,
    mut robot: (u32, u32),
) -> ((u32, u32), Action) {
    for _ in 0..20 {
        let step = ex
            .on_update(map, &update(&[], &[]), robot, 0.0)
            .expect("step");
        robot = step.next_cell;
        if step.phase == Phase::Local {
            return (robot, step.action);
        }
    }
    panic!("never reached the goal");
}

#[test]
fn local_exploration_follows_changes_and_never_steps_at_random_twice() {
    let mut map = free_map(9, 9);
    let mut ex = Explorer::new(params(1000), Mode::RecencyOnly, 3).expect("explorer");
    let (mut robot, first) = until_local(&mut ex, &mut map, (4, 4));
    // Nothing changes: the first local action is a random step; then a wait and a
    // random step by turns, never two random steps in a row.
    assert_eq!(first, Action::RandomStep);
    let mut previous = first;
    let mut randoms = 0;
    for _ in 0..10 {
        let step = ex
            .on_update(&mut map, &update(&[], &[]), robot, 0.0)
            .expect("step");
        assert_eq!(step.phase, Phase::Local);
        assert!(!(previous == Action::RandomStep && step.action == Action::RandomStep));
        let length = step.u[0].abs() + step.u[1].abs();
        match step.action {
            Action::RandomStep => {
                randoms += 1;
                assert_eq!(length, 1.0);
            }
            Action::Wait => assert_eq!(step.u, [0.0, 0.0]),
            Action::Move => panic!("nothing to move to"),
        }
        previous = step.action;
        robot = step.next_cell;
    }
    assert_eq!(randoms, 5, "random, wait, random, wait, …");
    // A change at the far corner: the local goal is its centroid, one step closer.
    let changes = update(&[(8, 8), (8, 7)], &[]);
    let step = ex.on_update(&mut map, &changes, robot, 0.0).expect("step");
    assert_eq!(step.action, Action::Move);
    assert_eq!(step.goal, (8, 8)); // (8, 7.5) rounds up
    let before = (8 - i64::from(robot.0)).abs() + (8 - i64::from(robot.1)).abs();
    let after = (8 - i64::from(step.next_cell.0)).abs() + (8 - i64::from(step.next_cell.1)).abs();
    assert_eq!(after, before - 1);
}

#[test]
fn ending_the_episode_instead_of_a_second_random_step() {
    let mut map = free_map(9, 9);
    let p = ExplorerParams {
        after_random_step: AfterRandomStep::EndEpisode,
        ..params(1000)
    };
    let mut ex = Explorer::new(p, Mode::RecencyOnly, 4).expect("explorer");
    let (robot, first) = until_local(&mut ex, &mut map, (4, 4));
    assert_eq!(first, Action::RandomStep);
    let second = ex
        .on_update(&mut map, &update(&[], &[]), robot, 0.0)
        .expect("end");
    let end = second.episode.expect("the episode ended");
    assert!(end.length >= 2);
    assert_eq!(second.episode_steps, 1, "a new episode took the step");
}

#[test]
fn commands_scale_and_bad_input_is_refused() {
    let mut map = free_map(5, 5);
    let p = ExplorerParams {
        cell_command: 0.25,
        ..params(42)
    };
    let mut ex = Explorer::new(p, Mode::Curious, 5).expect("explorer");
    let step = ex
        .on_update(&mut map, &update(&[], &[]), (2, 2), 0.0)
        .expect("step");
    let length = step.u[0].abs() + step.u[1].abs();
    assert!(length == 0.25 || length == 0.0, "{:?}", step.u);
    assert!(matches!(
        ex.on_update(&mut map, &update(&[], &[]), (5, 0), 1.0),
        Err(MapperError::CellOffMap { .. })
    ));
    assert!(matches!(
        ex.on_update(&mut map, &update(&[], &[]), (0, 0), f64::INFINITY),
        Err(MapperError::BadTime(_))
    ));
    assert!(Explorer::new(params(0), Mode::Curious, 0).is_err());
}

#[test]
fn the_same_seed_gives_the_same_steps() {
    let run = |seed| {
        let mut map = free_map(9, 9);
        let mut ex = Explorer::new(params(5), Mode::Curious, seed).expect("explorer");
        let mut robot = (4, 4);
        let mut out = Vec::new();
        for k in 0..40 {
            let u = if k % 7 == 3 {
                update(&[(k % 9, 0)], &[])
            } else {
                update(&[], &[])
            };
            let step = ex.on_update(&mut map, &u, robot, 0.0).expect("step");
            robot = step.next_cell;
            out.push((step.next_cell, step.strategy, step.goal));
        }
        out
    };
    assert_eq!(run(11), run(11));
    assert_ne!(run(11), run(12));
}
