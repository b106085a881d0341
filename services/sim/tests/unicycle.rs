//! roam's unicycle: turning costs time, the top speeds hold, it collides and is noisy as
//! the point robot is, and its heading survives a snapshot.

mod common;

use std::f64::consts::{FRAC_PI_2, PI};

use roam_sim::snapshot;
use roam_sim::unicycle::wrap;
use roam_sim::{Command, Event, Sim, SimError, SimParams};
use roam_world::scenario::{MotionModel, UnicycleSpec};

/// Every robot's position and heading after one step.
type Track = (Vec<[f64; 2]>, Vec<Option<f64>>);

const V_MAX: f64 = 0.5;
const W_MAX: f64 = 1.0;
const STEP_S: f64 = 0.1;

/// A 20 x 20 m open room with a wall at x = 15, unicycles without noise, 0.1 s steps.
fn open_room(sigma_tr: f64, robots: &str) -> Sim {
    let text = format!(
        "
name: open
map:
  grid:
    size_m: [20.0, 20.0]
    resolution: 0.5
    border_walls: true
    obstacles: [ {{ rect: [15.0, 0.0, 15.4, 20.0] }} ]
sensing: {{ observation_radius_m: 0.0 }}
motion: {{ sigma_tr_m: {sigma_tr}, model: {{ unicycle: {{ v_max_m_per_s: {V_MAX}, w_max_rad_per_s: {W_MAX} }} }} }}
time: {{ step_s: {STEP_S} }}
robots:
{robots}"
    );
    Sim::new(&common::inline(&text), 1).expect("sim")
}

fn command(robot: &str, u: [f64; 2]) -> Vec<Command> {
    vec![Command {
        robot: robot.into(),
        u,
    }]
}

/// Steps until `robot` is at `goal` (commanding the exact displacement there, which the
/// sim clips to the top speed), and returns the sim seconds it took.
fn drive_to(sim: &mut Sim, robot: &str, goal: [f64; 2]) -> f64 {
    let began = sim.time_s();
    let mu = sim.params().motion.step_mu;
    for _ in 0..10_000 {
        let at = sim.robot(robot).expect("robot").position();
        let (dx, dy) = (goal[0] - at[0], goal[1] - at[1]);
        if dx.hypot(dy) < 1e-9 {
            return sim.time_s() - began;
        }
        sim.step(&command(robot, [dx / mu, dy / mu])).expect("step");
    }
    panic!("{robot} never reached {goal:?}");
}

#[test]
fn a_quarter_turn_before_a_metre_costs_about_a_quarter_turn_of_time() {
    let mut sim = open_room(0.0, "  - { name: r, at: [5.0, 5.0] }\n");
    let straight = drive_to(&mut sim, "r", [6.0, 5.0]);
    // 1 m at 0.5 m/s: 2 s, up to the last step's rounding.
    assert!(
        (straight - 1.0 / V_MAX).abs() <= STEP_S + 1e-9,
        "{straight}"
    );
    sim.reset(1);
    let turned = drive_to(&mut sim, "r", [5.0, 6.0]);
    let turn_s = turned - straight;
    println!("straight {straight:.2} s, quarter turn then straight {turned:.2} s");
    assert!(turned > straight);
    assert!(
        (turn_s - FRAC_PI_2 / W_MAX).abs() <= STEP_S + 1e-9,
        "the turn cost {turn_s} s, (π/2)/w_max is {} s",
        FRAC_PI_2 / W_MAX
    );
    let r = sim.robot("r").expect("r");
    assert!((r.heading_rad() - FRAC_PI_2).abs() < 1e-9, "faces +y");
    // A robot started facing +y pays nothing for the same metre.
    let mut facing = open_room(
        0.0,
        "  - { name: r, at: [5.0, 5.0], heading_rad: 1.5707963267948966 }\n",
    );
    let t = drive_to(&mut facing, "r", [5.0, 6.0]);
    assert!((t - straight).abs() <= STEP_S + 1e-9, "{t} vs {straight}");
}

#[test]
fn the_top_speeds_hold_and_a_command_behind_turns_before_it_drives() {
    let mut sim = open_room(0.0, "  - { name: r, at: [5.0, 10.0] }\n");
    let (mut at, mut heading) = ([5.0, 10.0], 0.0);
    let mut clipped = 0;
    for k in 0..400 {
        let a = f64::from(k) * 0.37;
        let gain = if k % 3 == 0 { 50.0 } else { 0.4 };
        let report = sim
            .step(&command("r", [gain * a.cos(), gain * a.sin()]))
            .expect("step");
        let r = &report.robots[0];
        let now = r.readings.truth;
        let now_heading = r
            .readings
            .heading_rad
            .expect("a unicycle reports its heading");
        let moved = (now[0] - at[0]).hypot(now[1] - at[1]);
        assert!(moved <= V_MAX * STEP_S + 1e-12, "step {k}: {moved} m");
        assert!(
            wrap(now_heading - heading).abs() <= W_MAX * STEP_S + 1e-12,
            "step {k}: turned {} rad",
            wrap(now_heading - heading)
        );
        // It only ever drives along its heading.
        if moved > 1e-12 {
            let along = (now[1] - at[1]).atan2(now[0] - at[0]);
            assert!(wrap(along - now_heading).abs() < 1e-9, "step {k}");
        }
        for e in &r.events {
            if let Event::SpeedClipped { allowed_m, .. } = e {
                assert!((allowed_m - V_MAX * STEP_S).abs() < 1e-15);
                clipped += 1;
            }
        }
        (at, heading) = (now, now_heading);
    }
    assert!(
        clipped > 100,
        "long commands are reported clipped ({clipped})"
    );

    // A command straight behind: the first ⌊π / (w_max·dt)⌋ steps only turn.
    let mut sim = open_room(0.0, "  - { name: r, at: [5.0, 10.0] }\n");
    let full_turn_steps = (PI / (W_MAX * STEP_S)).floor() as usize;
    for k in 0..full_turn_steps {
        let report = sim.step(&command("r", [-1.0, 0.0])).expect("step");
        assert_eq!(report.robots[0].readings.truth, [5.0, 10.0], "step {k}");
    }
    let report = sim.step(&command("r", [-1.0, 0.0])).expect("step");
    let x = report.robots[0].readings.truth[0];
    assert!(x < 5.0 && x > 5.0 - V_MAX * STEP_S, "then it drives: {x}");
    // No command: no turn, no move.
    let before = sim.robot("r").expect("r").heading_rad();
    let report = sim.step(&[]).expect("step");
    assert_eq!(report.robots[0].readings.truth[0], x);
    assert_eq!(report.robots[0].readings.heading_rad, Some(before));
}

#[test]
fn a_unicycle_stops_short_of_a_wall_and_noise_is_seeded() {
    let mut sim = open_room(0.0, "  - { name: r, at: [13.0, 10.0] }\n");
    let mut hit = None;
    for _ in 0..100 {
        let report = sim.step(&command("r", [10.0, 0.0])).expect("step");
        if let Some(Event::Collision { stopped_at, .. }) = report.robots[0].events.last() {
            hit = Some(*stopped_at);
        }
    }
    let stopped = hit.expect("it hits the wall at x = 15");
    assert!(stopped[0] < 15.0 && stopped[0] > 14.9, "{stopped:?}");
    let cell = sim.world().cell_of(stopped).expect("on the map");
    assert!(!sim.world().is_blocked(cell));

    // Transition noise as the point robot's: seeded, and only while commanded.
    let noisy = |seed: u64| {
        let mut sim = open_room(0.01, "  - { name: r, at: [5.0, 10.0] }\n");
        sim.reset(seed);
        let mut track = Vec::new();
        for k in 0..200 {
            let u = if k % 50 < 10 { [0.0, 0.0] } else { [1.0, 0.5] };
            let report = sim.step(&command("r", u)).expect("step");
            track.push(report.robots[0].readings.truth);
        }
        track
    };
    let a = noisy(5);
    assert_eq!(a, noisy(5), "same seed, same run");
    assert_ne!(a, noisy(6), "the noise follows the seed");
    assert_eq!(a[0], [5.0, 10.0], "no command, no noise");
    assert_ne!(a[10], a[11], "commanded: noisy");
}

#[test]
fn the_heading_survives_a_snapshot_and_a_reset_restores_the_start_heading() {
    let robots =
        "  - { name: r, at: [5.0, 5.0], heading_rad: 1.0 }\n  - { name: s, at: [8.0, 5.0] }\n";
    let mut original = open_room(0.01, robots);
    assert_eq!(original.robot("r").expect("r").heading_rad(), wrap(1.0));
    for k in 0..37 {
        let a = f64::from(k) * 0.2;
        original
            .step(&[
                Command {
                    robot: "r".into(),
                    u: [a.cos(), a.sin()],
                },
                Command {
                    robot: "s".into(),
                    u: [-1.0, 1.0],
                },
            ])
            .expect("step");
    }
    let snap = original.snapshot("open");
    let r = snap.robots.iter().find(|r| r.name == "r").expect("r");
    assert_eq!(r.start_heading_rad, Some(wrap(1.0)));
    assert_eq!(
        r.heading_rad,
        Some(original.robot("r").expect("r").heading_rad())
    );

    let dir = std::env::temp_dir().join(format!("roam-unicycle-snap-{}", std::process::id()));
    let path = dir.join("sim.json");
    snapshot::save(&path, &snap).expect("save");
    let read = snapshot::load(&path).expect("load").expect("a file");
    assert_eq!(read, snap);
    let _ = std::fs::remove_dir_all(&dir);

    let resume = || {
        let mut sim = open_room(0.01, robots);
        sim.resume(&read).expect("resume");
        sim
    };
    let mut resumed = resume();
    for robot in original.robots() {
        let back = resumed.robot(robot.name()).expect("back");
        assert_eq!(back.position(), robot.position());
        assert_eq!(back.heading_rad().to_bits(), robot.heading_rad().to_bits());
    }
    let drive = |sim: &mut Sim| -> Vec<Track> {
        (0..30)
            .map(|_| {
                let report = sim.step(&command("r", [0.0, -1.0])).expect("step");
                (
                    report.robots.iter().map(|r| r.readings.truth).collect(),
                    report
                        .robots
                        .iter()
                        .map(|r| r.readings.heading_rad)
                        .collect(),
                )
            })
            .collect()
    };
    assert_eq!(
        drive(&mut resumed),
        drive(&mut resume()),
        "a resumed run repeats itself"
    );
    resumed.reset(1);
    assert_eq!(resumed.robot("r").expect("r").heading_rad(), wrap(1.0));
    assert_eq!(resumed.robot("s").expect("s").heading_rad(), 0.0);

    // A snapshot without headings (written for a point robot) starts each robot at the
    // scenario's heading; a non-finite heading is refused.
    let mut old = read.clone();
    for r in &mut old.robots {
        (r.start_heading_rad, r.heading_rad) = (None, None);
    }
    let mut sim = open_room(0.01, robots);
    sim.resume(&old).expect("resume");
    assert_eq!(sim.robot("r").expect("r").heading_rad(), wrap(1.0));
    let mut bad = read;
    bad.robots[0].heading_rad = Some(f64::NAN);
    let err = sim.resume(&bad).expect_err("NaN heading");
    assert!(err.to_string().contains("heading"), "{err}");
}

#[test]
fn a_point_robot_reports_no_heading_and_bad_unicycle_parameters_are_refused() {
    let scenario = common::inline(common::ROOM);
    let mut point = Sim::new(&scenario, 1).expect("sim");
    let report = point.step(&[]).expect("step");
    assert!(report
        .robots
        .iter()
        .all(|r| r.readings.heading_rad.is_none()));
    assert!(point.add_robot_facing("h", [3.0, 8.0], f64::NAN).is_err());

    let mut params = SimParams::from_file(&scenario.file);
    for (v, w, field) in [
        (0.0, 1.0, "motion.model.unicycle.v_max_m_per_s"),
        (-1.0, 1.0, "motion.model.unicycle.v_max_m_per_s"),
        (f64::NAN, 1.0, "motion.model.unicycle.v_max_m_per_s"),
        (0.5, 0.0, "motion.model.unicycle.w_max_rad_per_s"),
        (0.5, -2.0, "motion.model.unicycle.w_max_rad_per_s"),
        (0.5, f64::NAN, "motion.model.unicycle.w_max_rad_per_s"),
        (0.5, 45.0, "motion.model.unicycle.w_max_rad_per_s"),
    ] {
        params.motion.model = MotionModel::Unicycle(UnicycleSpec {
            v_max_m_per_s: v,
            w_max_rad_per_s: w,
        });
        match Sim::with_params(&scenario, params, 1) {
            Err(SimError::Param { field: f, reason }) => {
                assert_eq!(f, field);
                assert!(reason.contains("greater than 0 and at most 20"), "{reason}");
            }
            other => panic!("({v}, {w}): {other:?}"),
        }
    }
}
