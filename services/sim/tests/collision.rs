//! A robot never enters an occupied cell: a move into a wall, a block or a walker stops
//! short and is reported.

mod common;

use proptest::prelude::*;
use roam_sim::raster::first_blocked;
use roam_sim::{Command, Event, Obstacle, Sim};

fn go(robot: &str, u: [f64; 2]) -> Vec<Command> {
    vec![Command {
        robot: robot.into(),
        u,
    }]
}

#[test]
fn a_robot_driven_into_a_wall_stops_short_and_says_so() {
    let mut sim = Sim::new(&common::inline(common::ROOM), 1).expect("sim");
    // r1 at (2, 5) heads east at 0.2 m per step towards the wall at x = 5.
    let mut collisions = 0;
    for _ in 0..40 {
        let report = sim.step(&go("r1", [1.0, 0.0])).expect("step");
        let r1 = &report.robots[0];
        let [x, y] = r1.readings.truth;
        assert!(x < 5.0, "never inside the wall: x = {x}");
        let cell = sim.world().cell_of([x, y]).expect("on the map");
        assert!(!sim.world().is_blocked(cell));
        for event in &r1.events {
            if let Event::Collision {
                stopped_at,
                cell,
                obstacle,
                target,
            } = event
            {
                collisions += 1;
                assert_eq!(*stopped_at, [x, y]);
                assert_eq!(*obstacle, Obstacle::Wall);
                assert_eq!(cell[0], 10, "the wall's first column");
                assert!(target[0] >= 5.0);
            }
        }
    }
    assert!(collisions >= 20, "it keeps pushing and keeps being stopped");
    let [x, _] = sim.robot("r1").expect("r1").position();
    assert!(x > 4.99, "it got right up to the wall: x = {x}");
}

#[test]
fn the_top_speed_clips_a_long_command() {
    let mut sim = Sim::new(&common::inline(common::ROOM), 1).expect("sim");
    let before = sim.robot("r1").expect("r1").position();
    let report = sim.step(&go("r1", [0.0, 10.0])).expect("step");
    let after = report.robots[0].readings.truth;
    let moved = (after[0] - before[0]).hypot(after[1] - before[1]);
    // 0.2 m plus at most a few σ_tr = 0.01 m of noise.
    assert!((moved - 0.2).abs() < 0.06, "moved {moved} m");
    let Event::SpeedClipped {
        requested_m,
        allowed_m,
    } = report.robots[0].events[0]
    else {
        panic!("{:?}", report.robots[0].events);
    };
    assert!((requested_m - 2.0).abs() < 1e-12, "μ·|u| = 0.2 · 10");
    assert_eq!(allowed_m, 0.2);
}

#[test]
fn blocks_stop_robots_and_push_them_aside() {
    let text = "
name: blocks
map: { grid: { size_m: [10.0, 10.0], resolution: 1.0, border_walls: true } }
motion: { step_mu: 1.0, sigma_tr_m: 0.0, max_speed_m_per_step: 1.0 }
robots:
  - { name: pushed, at: [2.5, 2.5] }
  - { name: blocked, at: [5.5, 7.5] }
blocks:
  - { name: b, size_cells: [1, 1], period_steps: 1, path: [[3.5, 2.5], [2.5, 2.5], [3.5, 2.5]] }
  - { name: wallish, size_cells: [1, 1], period_steps: 100, path: [[7.5, 7.5]] }
";
    let scenario = common::inline(text);
    // The block comes onto `pushed` at step 1.
    let mut sim = Sim::new(&scenario, 0).expect("sim");
    let report = sim
        .step(&[Command {
            robot: "blocked".into(),
            u: [1.0, 0.0],
        }])
        .expect("step");
    let pushed = report
        .robots
        .iter()
        .find(|r| r.name == "pushed")
        .expect("pushed");
    assert_eq!(
        pushed.events.first(),
        Some(&Event::Displaced {
            from: [2.5, 2.5],
            to: [3.5, 2.5],
            by: Obstacle::Block("b".into()),
        }),
        "put on the nearest free cell, east first"
    );
    let cell = sim.world().cell_of(pushed.readings.truth).expect("on map");
    assert!(!sim.world().is_blocked(cell));
    // `blocked` drives east into the block at (7.5, 7.5): one step to x = 6.5, then stop.
    let report = sim
        .step(&[Command {
            robot: "blocked".into(),
            u: [1.0, 0.0],
        }])
        .expect("step");
    let blocked = report
        .robots
        .iter()
        .find(|r| r.name == "blocked")
        .expect("blocked");
    let Some(Event::Collision { obstacle, .. }) = blocked.events.first() else {
        panic!("{:?}", blocked.events);
    };
    assert_eq!(*obstacle, Obstacle::Block("wallish".into()));
    assert!(blocked.readings.truth[0] < 7.0);
}

#[test]
fn refused_commands_change_nothing() {
    let mut sim = Sim::new(&common::inline(common::ROOM), 1).expect("sim");
    let before = sim.robot("r1").expect("r1").position();
    for bad in [
        go("nobody", [1.0, 0.0]),
        go("r1", [f64::NAN, 0.0]),
        go("r1", [f64::INFINITY, 0.0]),
        vec![
            Command {
                robot: "r1".into(),
                u: [1.0, 0.0],
            },
            Command {
                robot: "r1".into(),
                u: [0.0, 1.0],
            },
        ],
    ] {
        let err = sim.step(&bad).expect_err("refused");
        assert!(!err.to_string().is_empty());
    }
    assert_eq!(sim.steps(), 0);
    assert_eq!(sim.robot("r1").expect("r1").position(), before);
    // Robots start only on free cells of the map, once per name.
    assert!(sim.add_robot("w", [5.5, 3.0]).is_err(), "in the wall");
    assert!(sim.add_robot("off", [20.0, 3.0]).is_err(), "off the map");
    assert!(
        sim.add_robot("r1", [3.0, 3.0]).is_err(),
        "the name is taken"
    );
    assert!(sim.add_robot("", [3.0, 3.0]).is_err(), "no name");
    assert!(sim.remove_robot("nobody").is_err());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Random commands, large enough to jump a wall in one step: the robot never ends in
    /// an occupied cell, and never passes through one.
    #[test]
    fn no_command_takes_a_robot_into_or_through_a_wall(
        seed in any::<u64>(),
        commands in prop::collection::vec((-3.0f64..3.0, -3.0f64..3.0), 1..60),
    ) {
        let text = format!(
            "{}motion: {{ step_mu: 1.0, sigma_tr_m: 0.05, max_speed_m_per_step: 2.5 }}\n",
            common::ROOM
        );
        let mut sim = Sim::new(&common::inline(&text), seed).expect("sim");
        for (ux, uy) in commands {
            let before = sim.robot("r1").expect("r1").position();
            let report = sim.step(&go("r1", [ux, uy])).expect("step");
            let r1 = report.robots.iter().find(|r| r.name == "r1").expect("r1");
            let after = r1.readings.truth;
            let world = sim.world();
            let cell = world.cell_of(after).expect("on the map");
            prop_assert!(!world.is_blocked(cell), "r1 in an occupied cell {cell:?}");
            let (from, to) = (world.to_cell_units(before), world.to_cell_units(after));
            let crossed = first_blocked(from, to, |c| world.is_blocked(c));
            prop_assert_eq!(crossed, None, "r1 passed through an occupied cell");
            let collided = r1.events.iter().find_map(|e| match e {
                Event::Collision {
                    target,
                    stopped_at,
                    cell,
                    ..
                } => Some((*target, *stopped_at, *cell)),
                _ => None,
            });
            if let Some((target, stopped_at, cell)) = collided {
                prop_assert_eq!(stopped_at, after);
                prop_assert!(world.is_blocked((cell[0], cell[1])));
                let (want, got) = (
                    (target[0] - before[0]).hypot(target[1] - before[1]),
                    (after[0] - before[0]).hypot(after[1] - before[1]),
                );
                prop_assert!(got <= want, "stopped beyond the target");
            }
        }
    }
}
