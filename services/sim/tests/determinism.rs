//! The same seed and the same commands give the same sensor stream, bit for bit: twice
//! in a row, after a reset, and whatever other robots come and go.

mod common;

use roam_sim::{Command, Sim, StepReport};

/// Drives every robot of `sim` in a slow circle (each with its own phase) for `steps`.
fn drive(sim: &mut Sim, steps: u32) -> Vec<StepReport> {
    let names: Vec<String> = sim.robots().map(|r| r.name().to_owned()).collect();
    (0..steps)
        .map(|k| {
            let commands: Vec<Command> = names
                .iter()
                .enumerate()
                .map(|(i, name)| {
                    let a = f64::from(k) * 0.1 + i as f64;
                    Command {
                        robot: name.clone(),
                        u: [a.cos(), a.sin()],
                    }
                })
                .collect();
            sim.step(&commands).expect("step")
        })
        .collect()
}

/// Every number in the reports, as bits, so "equal" means bit for bit.
fn bits(reports: &[StepReport]) -> Vec<u64> {
    let mut out = Vec::new();
    for r in reports {
        out.push(r.step);
        out.push(r.time_s.to_bits());
        for robot in &r.robots {
            out.extend(robot.readings.truth.map(f64::to_bits));
            for range in &robot.readings.ranges {
                out.push(range.anchor as u64);
                out.push(range.range_m.to_bits());
            }
            if let Some(obs) = &robot.readings.observation {
                out.extend(obs.cells.iter().map(|&c| c as u64));
            }
            out.push(robot.events.len() as u64);
        }
    }
    out
}

#[test]
fn same_seed_same_stream_twice_and_after_reset() {
    let scenario = common::inline(common::ROOM);
    let mut a = Sim::new(&scenario, 42).expect("sim");
    let first = drive(&mut a, 200);
    let mut b = Sim::new(&scenario, 42).expect("sim");
    let second = drive(&mut b, 200);
    assert_eq!(first, second);
    assert_eq!(bits(&first), bits(&second));

    a.reset(42);
    assert_eq!((a.steps(), a.time_s()), (0, 0.0));
    let after_reset = drive(&mut a, 200);
    assert_eq!(bits(&first), bits(&after_reset));

    a.reset(43);
    let other_seed = drive(&mut a, 200);
    assert_ne!(bits(&first), bits(&other_seed));
}

#[test]
fn a_new_robot_does_not_change_another_robots_noise() {
    let scenario = common::inline(common::ROOM);
    let mut alone = Sim::new(&scenario, 7).expect("sim");
    alone.remove_robot("r2").expect("remove");
    let mut crowded = Sim::new(&scenario, 7).expect("sim");
    crowded.add_robot("r3", [3.0, 8.0]).expect("add");
    let r1 = |reports: Vec<StepReport>| -> Vec<_> {
        reports
            .into_iter()
            .map(|r| r.robots.into_iter().find(|x| x.name == "r1").expect("r1"))
            .collect()
    };
    assert_eq!(r1(drive(&mut alone, 100)), r1(drive(&mut crowded, 100)));
}

#[test]
fn the_shipped_scenarios_are_deterministic_with_walkers_and_blocks() {
    let text = "
name: busy
map: { grid: { size_m: [12.0, 12.0], resolution: 0.5, border_walls: true } }
anchors: [ { name: a, at: [0.5, 0.5] } ]
robots: [ { name: r, at: [6.0, 6.0] } ]
blocks:
  - { name: b, size_m: [1.0, 1.0], period_steps: 3, path: [[2.0, 2.0], [4.0, 2.0]] }
walkers:
  - { name: w1, at: [9.0, 9.0], size_m: 0.5, step_m: 0.5, every_steps: 1 }
  - { name: w2, at: [3.0, 9.0], size_m: 1.0, step_m: 0.5, every_steps: 2 }
";
    let scenario = common::inline(text);
    let run = |seed| {
        let mut sim = Sim::new(&scenario, seed).expect("sim");
        let reports = drive(&mut sim, 150);
        let walkers: Vec<[f64; 2]> = sim.world().walkers().iter().map(|w| w.at).collect();
        (bits(&reports), walkers)
    };
    let (first, walkers) = run(5);
    assert_eq!((first.clone(), walkers.clone()), run(5));
    assert_ne!(walkers, run(6).1, "walkers follow the seed");
    for file in ["grid004.yaml", "es3.yaml", "downtime.yaml"] {
        let scenario = common::shipped(file);
        let mut a = Sim::new(&scenario, 1).expect("sim");
        let first = bits(&drive(&mut a, 30));
        a.reset(1);
        assert_eq!(first, bits(&drive(&mut a, 30)), "{file}");
    }
}

#[test]
fn a_resumed_sim_keeps_the_clock_robots_and_blocks_and_repeats_itself() {
    let scenario = common::shipped("grid004.yaml");
    let mut original = Sim::new(&scenario, 3).expect("sim");
    drive(&mut original, 37);
    let snapshot = original.snapshot("grid004");
    assert_eq!(snapshot.step, 37);

    let resume = || {
        let mut sim = Sim::new(&scenario, 3).expect("sim");
        sim.resume(&snapshot).expect("resume");
        sim
    };
    let mut resumed = resume();
    assert_eq!(resumed.steps(), original.steps());
    assert_eq!(resumed.time_s().to_bits(), original.time_s().to_bits());
    for robot in original.robots() {
        let back = resumed.robot(robot.name()).expect("the robot is back");
        assert_eq!(back.position(), robot.position(), "{}", robot.name());
        assert_eq!(back.start(), robot.start(), "{}", robot.name());
    }
    // Scripted blocks are where their script puts them at this step.
    for (a, b) in original
        .world()
        .blocks()
        .iter()
        .zip(resumed.world().blocks())
    {
        assert_eq!(a.centre_at(original.steps()), b.centre_at(resumed.steps()));
    }
    assert_eq!(original.occupancy().cells, resumed.occupancy().cells);
    // The same snapshot resumes to the same run, bit for bit.
    assert_eq!(
        bits(&drive(&mut resumed, 50)),
        bits(&drive(&mut resume(), 50))
    );
}

#[test]
fn a_snapshot_with_a_bad_robot_is_refused_and_changes_nothing() {
    let scenario = common::shipped("downtime.yaml");
    let mut sim = Sim::new(&scenario, 0).expect("sim");
    let mut snapshot = sim.snapshot("downtime");
    snapshot.robots[0].at = [f64::NAN, 0.0];
    assert!(sim.resume(&snapshot).is_err());
    assert_eq!(sim.robots().count(), 1);
    assert!(sim
        .robots()
        .all(|r| r.position().iter().all(|v| v.is_finite())));
}
